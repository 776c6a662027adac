//! The node: a robot's composed behavior on the threaded runtime, its hardware as ROS 2
//! topics ([`super::devices`]), and its missions as Nav2's two docking actions.
//!
//! * **Topics.** It subscribes to one image topic per camera of the profile, to
//!   `nav_msgs/msg/Odometry` and, when the profile declares a `dock_contact` sensor, to
//!   the dock contact switch (`std_msgs/msg/Bool`); it publishes
//!   `geometry_msgs/msg/Twist` on `cmd_vel` and, for the actuators the profile declares,
//!   `posture` and `dock_guides` (`std_msgs/msg/String`: `raised`/`lowered`,
//!   `open`/`closed`) and `lights` (`std_msgs/msg/Bool`) ([`super::aux_devices`]).
//! * **Actions.** `dock_robot` (`nav2_msgs/action/DockRobot`) starts a docking mission
//!   and `undock_robot` (`nav2_msgs/action/UndockRobot`) a departure, with the ROS 2
//!   action protocol's `send_goal`, `get_result` and `cancel_goal` services and
//!   `feedback` and `status` topics under `<action>/_action/` ([`super::goals`]); and
//!   `<node>/reload_database` (`nav2_msgs/srv/ReloadDockDatabase`, [`super::dock_db`]).
//!   With the node named `docking_server` (the default) these are Nav2's own names.
//! * **The run.** Each goal is [`crate::arbiter::runtime::run_missions_observed`] on the
//!   robot those topics make, so staleness limits, safe stops, the watchdog and the typed
//!   outcomes are the threaded runtime's own. The behavior persists between goals: a
//!   docking after an undocking uses the colours imprinted on the way out.
//! * **Discovery.** Every entity has its liveliness token with its real QoS
//!   ([`super::qos`]) and the GID `rmw_zenoh` would give it; each action's `status` is
//!   transient-local, depth 1 ([`super::latched`]).

use super::aux_devices::{AuxTopic, Encode, TopicSwitch, Unbridged, guides_message, lights_message, posture_message};
pub use super::aux_devices::{encode_bool, encode_string};
use super::config::zerr;
pub use super::config::{BridgeConfig, BridgeError, CameraTopic, zenoh_config};
use super::devices::{ImageKind, TopicCamera, TopicOdometer, TwistDrive, subscribe};
use super::dock_db::DockDatabase;
use super::goals::{Shared, Which, on_cancel, on_get_result, on_reload, on_send_goal, run_goals};
use super::interfaces::{self, Interface};
use super::keys::{RmwPublisher, gid, zid_string};
use super::latched::LatchedPublisher;
use super::qos::Qos;
use crate::arbiter::ReactiveLoop;
use crate::profile::Profile;
use crate::robot::{Actuator, Robot, Sensor};
use crate::schemas::{Agent, DOCK_CONTACT_KIND, GUIDES_KIND, LIGHTS_KIND, POSTURE_KIND};
use crossbeam::channel::unbounded;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::thread::JoinHandle;
use std::time::Duration;
use zenoh::Wait;

/// The running node. Dropping it (or [`Ros2Node::shutdown`]) cancels the running goal,
/// waits for the robot to stop and closes the session.
pub struct Ros2Node {
    session: zenoh::Session,
    shared: Arc<Shared>,
    worker: Option<JoinHandle<()>>,
    /// Queryables, subscribers and liveliness tokens, kept alive with the node.
    _declared: Vec<Box<dyn std::any::Any + Send + Sync>>,
}

impl Ros2Node {
    /// Opens the session, declares every topic, service and token, and starts the worker
    /// that runs goals.
    ///
    /// # Errors
    /// [`BridgeError`] when the behavior cannot be built, the topics do not match the
    /// profile's cameras, or Zenoh refuses a declaration.
    pub fn start(profile: &Profile, config: BridgeConfig) -> Result<Self, BridgeError> {
        Self::start_with(profile, crate::behaviors::catalog::shipped(), config)
    }

    /// [`Ros2Node::start`], the agent built from `catalog` (a crate's own robot kinds).
    ///
    /// # Errors
    /// As [`Ros2Node::start`].
    pub fn start_with(
        profile: &Profile,
        catalog: &crate::behaviors::Catalog,
        config: BridgeConfig,
    ) -> Result<Self, BridgeError> {
        if config.cameras.len() != profile.cameras.len() {
            return Err(BridgeError::Config(format!(
                "the profile has {} camera(s) but {} image topic(s) were given",
                profile.cameras.len(),
                config.cameras.len()
            )));
        }
        let agent = catalog
            .agent(profile)
            .map_err(|e| BridgeError::Behavior(e.to_string()))?;
        let lp: ReactiveLoop<dyn Agent> = ReactiveLoop::new(agent, profile.loop_config());
        let session = zenoh::open(zenoh_config(&config.listen, &config.connect)?)
            .wait()
            .map_err(zerr)?;
        let mut docks = DockDatabase::for_profile(profile, &config.odom_frame);
        if let Some(path) = &config.dock_database {
            docks = docks
                .reloaded(path, &profile.name)
                .map_err(|e| BridgeError::Config(e.to_string()))?;
        }
        let zid = zid_string(session.zid().to_le_bytes());
        let node = &config.node;
        let mut declared: Vec<Box<dyn std::any::Any + Send + Sync>> = Vec::new();
        let mut entity = 0u32;
        let mut token = |declared: &mut Vec<Box<dyn std::any::Any + Send + Sync>>,
                         kind: &str,
                         name: &str,
                         ty: &Interface,
                         qos: &Qos|
         -> Result<[u8; 16], BridgeError> {
            entity += 1;
            let t = node.entity_token(&zid, entity, kind, name, ty, qos);
            let g = gid(&t);
            declared.push(Box::new(session.liveliness().declare_token(t).wait().map_err(zerr)?));
            Ok(g)
        };
        declared.push(Box::new(
            session
                .liveliness()
                .declare_token(node.node_token(&zid))
                .wait()
                .map_err(zerr)?,
        ));

        // The robot's devices.
        let wait = Duration::from_secs_f64((2.0 / profile.loop_.rate_hz.max(1.0)).min(0.5));
        let mut cameras: Vec<Box<dyn crate::robot::Camera>> = Vec::new();
        for (cam, spec) in config.cameras.iter().zip(&profile.cameras) {
            let ty = match cam.kind {
                ImageKind::Raw => interfaces::image(),
                ImageKind::Compressed => interfaces::compressed_image(),
            };
            token(&mut declared, "MS", &cam.topic, &ty, &Qos::DEFAULT)?;
            let sub = subscribe(&session, &node.key(&cam.topic, &ty)).map_err(BridgeError::Zenoh)?;
            cameras.push(Box::new(TopicCamera::new(
                node.qualify(&cam.topic),
                cam.kind,
                (spec.width_px, spec.height_px),
                sub,
                wait,
                config.trust_stamps,
            )));
        }
        let twist = interfaces::twist();
        let drive_gid = token(&mut declared, "MP", &config.cmd_vel, &twist, &Qos::DEFAULT)?;
        let cmd = session
            .declare_publisher(node.key(&config.cmd_vel, &twist))
            .wait()
            .map_err(zerr)?;
        let mut robot = Robot::new(cameras, Box::new(TwistDrive::new(RmwPublisher::new(cmd, drive_gid))));
        if let Some(topic) = &config.odometry {
            let ty = interfaces::odometry();
            token(&mut declared, "MS", topic, &ty, &Qos::DEFAULT)?;
            let sub = subscribe(&session, &node.key(topic, &ty)).map_err(BridgeError::Zenoh)?;
            robot.odometer = Some(Box::new(TopicOdometer::new(node.qualify(topic), sub)));
        }
        let boolean = interfaces::message("std_msgs/msg/Bool");
        let string = interfaces::message("std_msgs/msg/String");
        for spec in &profile.sensors {
            let device: Box<dyn Sensor> = match (spec.kind.as_str(), &config.dock_contact) {
                (DOCK_CONTACT_KIND, Some(topic)) => {
                    token(&mut declared, "MS", topic, &boolean, &Qos::DEFAULT)?;
                    let (latest, sub) = subscribe(&session, &node.key(topic, &boolean)).map_err(BridgeError::Zenoh)?;
                    Box::new(TopicSwitch {
                        topic: node.qualify(topic),
                        latest,
                        _sub: sub,
                    })
                }
                _ => Box::new(Unbridged),
            };
            robot.sensors.push(device);
        }
        for spec in &profile.actuators {
            let topic: Option<(&str, &Interface, Encode)> = match spec.kind.as_str() {
                POSTURE_KIND => Some(("posture", &string, posture_message)),
                GUIDES_KIND => Some(("dock_guides", &string, guides_message)),
                LIGHTS_KIND => Some(("lights", &boolean, lights_message)),
                _ => None,
            };
            let device: Box<dyn Actuator> = match topic {
                Some((name, ty, encode)) => {
                    let g = token(&mut declared, "MP", name, ty, &Qos::DEFAULT)?;
                    let p = session.declare_publisher(node.key(name, ty)).wait().map_err(zerr)?;
                    Box::new(AuxTopic {
                        publisher: RmwPublisher::new(p, g),
                        encode,
                    })
                }
                None => Box::new(Unbridged),
            };
            robot.actuators.push(device);
        }

        // The two actions and the dock database service.
        let cancel = interfaces::cancel_goal();
        let status_ty = interfaces::goal_status_array();
        let publisher = |name: &str, ty: &Interface| session.declare_publisher(node.key(name, ty)).wait().map_err(zerr);
        let mut status = Vec::new();
        let mut feedback = None;
        for which in [Which::Dock, Which::Undock] {
            let a = interfaces::action(which.interface());
            let base = format!("{}/_action", which.action());
            let (fb_name, st_name) = (format!("{base}/feedback"), format!("{base}/status"));
            let fb_gid = token(&mut declared, "MP", &fb_name, &a.feedback, &Qos::DEFAULT)?;
            let st_gid = token(&mut declared, "MP", &st_name, &status_ty, &Qos::ACTION_STATUS)?;
            let fb = RmwPublisher::new(publisher(&fb_name, &a.feedback)?, fb_gid);
            // UndockRobot's feedback is empty and never sent; its publisher is declared, as
            // every action server declares one.
            match which {
                Which::Dock => feedback = Some(fb),
                Which::Undock => declared.push(Box::new(fb)),
            }
            let st = RmwPublisher::new(publisher(&st_name, &status_ty)?, st_gid);
            status.push(LatchedPublisher::new(&session, st, &zid).map_err(BridgeError::Zenoh)?);
        }
        let (Some(feedback), Ok(status)) = (feedback, <[LatchedPublisher; 2]>::try_from(status)) else {
            return Err(BridgeError::Config("the two actions' topics".to_owned()));
        };
        let (jobs_tx, jobs_rx) = unbounded();
        let shared = Arc::new(Shared::new(
            jobs_tx,
            status,
            feedback,
            docks,
            &profile.name,
            &config.odom_frame,
        ));
        for which in [Which::Dock, Which::Undock] {
            let a = interfaces::action(which.interface());
            let base = format!("{}/_action", which.action());
            for (service, ty) in [
                ("send_goal", &a.send_goal),
                ("get_result", &a.get_result),
                ("cancel_goal", &cancel),
            ] {
                let name = format!("{base}/{service}");
                token(&mut declared, "SS", &name, ty, &Qos::SERVICES)?;
                let sh = shared.clone();
                let q = session
                    .declare_queryable(node.key(&name, ty))
                    .complete(true)
                    .callback(move |query| match service {
                        "send_goal" => on_send_goal(&sh, which, &query),
                        "get_result" => on_get_result(&sh, which, query),
                        _ => on_cancel(&sh, which, &query),
                    })
                    .wait()
                    .map_err(zerr)?;
                declared.push(Box::new(q));
            }
        }
        let reload = interfaces::reload_dock_database();
        let reload_name = format!("{}/reload_database", node.name);
        token(&mut declared, "SS", &reload_name, &reload, &Qos::SERVICES)?;
        let sh = shared.clone();
        let q = session
            .declare_queryable(node.key(&reload_name, &reload))
            .complete(true)
            .callback(move |query| on_reload(&sh, &query))
            .wait()
            .map_err(zerr)?;
        declared.push(Box::new(q));

        let sh = shared.clone();
        let runtime = config.runtime.clone();
        let worker = std::thread::Builder::new()
            .name("marsupial-ros2-goals".to_owned())
            .spawn(move || run_goals(robot, lp, &jobs_rx, &sh, &runtime))
            .map_err(|e| BridgeError::Config(format!("could not start the goal thread: {e}")))?;
        Ok(Self {
            session,
            shared,
            worker: Some(worker),
            _declared: declared,
        })
    }

    /// The endpoints the session listens on, as Zenoh resolved them (with the port the OS
    /// chose for `tcp/127.0.0.1:0`), for a peer to connect to.
    pub fn locators(&self) -> Vec<String> {
        self.session
            .info()
            .locators()
            .wait()
            .into_iter()
            .map(|l| l.to_string())
            .collect()
    }

    /// Cancels the running goal, waits until the robot has stopped, and closes the
    /// session.
    pub fn shutdown(mut self) {
        self.stop_worker();
    }

    fn stop_worker(&mut self) {
        self.shared.closing.store(true, Ordering::SeqCst);
        self.shared.stop_active();
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
        let _ = self.session.close().wait();
    }
}

impl Drop for Ros2Node {
    fn drop(&mut self) {
        if self.worker.is_some() {
            self.stop_worker();
        }
    }
}

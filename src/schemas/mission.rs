//! Missions: what a robot's composed behavior is asked to do, and the [`Agent`] trait that
//! starts them.
//!
//! A robot's behavior tree (declared in its profile's `[behavior.tree]`) holds every
//! phase it knows; a mission says where to start. Departure (leave the dock, imprint the
//! fiducial on the way) and docking are the two every docking robot has, after Nav2's
//! `UndockRobot` and `DockRobot` requests: each is started on its own and ends the run
//! with a typed [`Outcome`](super::Outcome), so a round trip is a departure followed by a
//! docking. The same call starts them on the threaded runtime
//! ([`ReactiveLoop::begin`](crate::arbiter::ReactiveLoop::begin)) and in the simulator.

use super::behavior::Behavior;
use crate::geometry::Pose2;
use thiserror::Error;

/// What the robot is asked to do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mission {
    /// Leave the dock, imprinting the fiducial's colours on the way out (when the robot
    /// imprints).
    Departure,
    /// Dock.
    Docking {
        /// An a-priori estimate of the dock's pose (entrance, +x out along its axis) in
        /// the odometry frame this docking starts in: from GPS, or remembered from the
        /// departure. With one, robots that declare a ballistic entry drive to the dock's
        /// approach zone by odometry first; without, the robot is taken to be within
        /// sight of the dock.
        dock_hint: Option<Pose2>,
        /// Drive to the approach zone first when there is a hint and the tree declares a
        /// ballistic entry (Nav2's `navigate_to_staging_pose`); `false`: the robot is
        /// already staged and starts at the tree's docking entry, the hint kept for the
        /// phases that use it (a repositioning toward the dock).
        stage: bool,
    },
}

impl Mission {
    /// Docking from within sight of the dock (no a-priori pose).
    pub fn docking() -> Self {
        Mission::Docking {
            dock_hint: None,
            stage: true,
        }
    }

    /// Docking at the dock `hint` says, driving to its approach zone first (where the
    /// robot's tree declares a ballistic entry).
    pub fn docking_at(hint: Pose2) -> Self {
        Mission::Docking {
            dock_hint: Some(hint),
            stage: true,
        }
    }

    /// Short name, as in logs: `departure` or `docking`.
    pub fn name(&self) -> &'static str {
        match self {
            Mission::Departure => "departure",
            Mission::Docking { .. } => "docking",
        }
    }
}

/// Why a mission could not start.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum MissionError {
    /// The behavior has no missions (a plain arbiter, not a robot's composed behavior).
    #[error("`{behavior}` takes no missions")]
    NoMissions {
        /// The behavior's name.
        behavior: String,
    },
    /// The robot cannot do this mission as configured (no departure declared in its
    /// tree, or nothing to imprint in its segmentation mode).
    #[error("`{robot}` cannot start a {mission}: {why}")]
    Unavailable {
        /// The robot's behavior.
        robot: String,
        /// The mission asked for.
        mission: &'static str,
        /// Why not.
        why: String,
    },
}

/// Counters a robot keeps per mission (for campaign records).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AgentStats {
    /// Alignment manoeuvres started (RAPOSA's region-II iterations).
    pub manoeuvres: u32,
}

/// A robot's whole behavior: a [`Behavior`] that can be given missions.
///
/// Between missions it is inactive (`tick` returns `None`, the loop holds the robot
/// still) while its perceptual schemas keep running, so colour adaptation follows the
/// light even while the robot waits.
pub trait Agent: Behavior {
    /// Starts `mission` at the next tick, abandoning whatever ran before.
    ///
    /// # Errors
    /// [`MissionError`] when this robot cannot do the mission; it is then left as it was.
    fn begin(&mut self, mission: &Mission) -> Result<(), MissionError>;

    /// Counters of the current mission.
    fn stats(&self) -> AgentStats {
        AgentStats::default()
    }

    /// This tick's percept and colour ranges, for recorders and displays
    /// ([`Observation`](super::Observation)); `None` (the default) for a robot without
    /// perception.
    fn observe(&self) -> Option<super::Observation> {
        None
    }
}

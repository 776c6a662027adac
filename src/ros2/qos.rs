//! The QoS each entity really has, written into its liveliness token as `rmw_zenoh`
//! writes it, so `ros2 topic info --verbose` and a QoS-matching peer see the truth.
//!
//! `rmw_zenoh` (`liveliness_utils.cpp`, `qos_to_keyexpr`) writes six `:`-separated parts,
//! reliability, durability, `history,depth`, `deadline sec,nsec`, `lifespan sec,nsec` and
//! `liveliness,lease sec,lease nsec`, each value left empty when it equals *its own*
//! default (`qos.cpp`): reliable, **transient-local**, keep-last, **depth 42**, infinite
//! deadline, lifespan and lease, automatic liveliness. Numbers are `rmw`'s enums
//! (reliability 1 reliable, 2 best effort; durability 1 transient-local, 2 volatile;
//! history 1 keep-last, 2 keep-all). A ROS 2 default publisher (reliable, volatile,
//! keep-last 10) is therefore `:2:,10:,:,:,,`, not the empty `::,:,:,:,,`.

/// `rmw_qos_durability_policy_e`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Durability {
    /// Late joiners get the last `depth` samples (`RMW_QOS_POLICY_DURABILITY_TRANSIENT_LOCAL`, 1).
    TransientLocal = 1,
    /// Only samples published after a subscriber joined (`…_VOLATILE`, 2).
    Volatile = 2,
}

/// The QoS policies the bridge sets; the others (deadline, lifespan, liveliness) are
/// `rmw`'s defaults for every entity it declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    /// Reliable (1) or best effort (2).
    pub reliable: bool,
    /// Volatile or transient-local.
    pub durability: Durability,
    /// Keep-last depth.
    pub depth: u32,
}

impl Qos {
    /// `rmw_qos_profile_default`: reliable, volatile, keep-last 10. ROS 2's default for
    /// topics, and what the node's publishers, subscriptions and action feedback use.
    pub const DEFAULT: Qos = Qos {
        reliable: true,
        durability: Durability::Volatile,
        depth: 10,
    };

    /// `rmw_qos_profile_services_default`: the same policies, for services (and the
    /// action protocol's `send_goal`, `get_result` and `cancel_goal`).
    pub const SERVICES: Qos = Qos::DEFAULT;

    /// `rcl_action_qos_profile_status_default`: reliable, transient-local, keep-last 1,
    /// so a client that joins late still reads each goal's status.
    pub const ACTION_STATUS: Qos = Qos {
        reliable: true,
        durability: Durability::TransientLocal,
        depth: 1,
    };

    /// The token's QoS part, each value empty where it equals `rmw_zenoh`'s default.
    pub fn keyexpr(&self) -> String {
        let reliability = if self.reliable { "" } else { "2" };
        let durability = match self.durability {
            Durability::TransientLocal => String::new(),
            d => (d as u8).to_string(),
        };
        let depth = if self.depth == 42 {
            String::new()
        } else {
            self.depth.to_string()
        };
        format!("{reliability}:{durability}:,{depth}:,:,:,,")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_write_what_differs_from_rmw_zenohs_defaults() {
        assert_eq!(Qos::DEFAULT.keyexpr(), ":2:,10:,:,:,,");
        assert_eq!(Qos::SERVICES.keyexpr(), ":2:,10:,:,:,,");
        assert_eq!(Qos::ACTION_STATUS.keyexpr(), "::,1:,:,:,,");
        let rmw_zenoh_default = Qos {
            reliable: true,
            durability: Durability::TransientLocal,
            depth: 42,
        };
        assert_eq!(rmw_zenoh_default.keyexpr(), "::,:,:,:,,");
        let sensor = Qos {
            reliable: false,
            durability: Durability::Volatile,
            depth: 5,
        };
        assert_eq!(sensor.keyexpr(), "2:2:,5:,:,:,,");
    }
}

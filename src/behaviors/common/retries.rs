//! The retries of one docking, written once for every robot: how many a docking may use
//! (the profile's `behavior.max_retries`) and how many it has. A robot's memory holds one
//! [`Retries`]; the leaf that decides to try again spends one and, past the last, fails
//! the docking with `retries_exhausted`; feedback reports how many were used.

/// The retries of one docking (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Retries {
    used: u32,
    max: u32,
}

impl Retries {
    /// None used of `max` (`behavior.max_retries`).
    pub fn new(max: u32) -> Self {
        Self { used: 0, max }
    }

    /// How many this docking has used.
    pub fn used(&self) -> u32 {
        self.used
    }

    /// Spends one: true while it was within the allowance (the robot tries again), false
    /// once the docking has used more than `max` (it gives up).
    pub fn spend(&mut self) -> bool {
        self.used += 1;
        self.used <= self.max
    }

    /// True while another retry may be spent (fewer than `max` used): a leaf that may
    /// choose to retry, as Bujold's approach repositions, asks this first.
    pub fn left(&self) -> bool {
        self.used < self.max
    }

    /// Starts a docking's count over.
    pub fn reset(&mut self) {
        self.used = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::Retries;

    #[test]
    fn spends_up_to_the_allowance_then_refuses() {
        let mut r = Retries::new(2);
        assert!(r.left() && r.spend());
        assert!(r.left() && r.spend());
        assert!(!r.left(), "both used");
        assert!(!r.spend(), "a third is past the allowance");
        assert_eq!(r.used(), 3);
        r.reset();
        assert_eq!((r.used(), r.left()), (0, true));
        assert!(!Retries::new(0).spend(), "no retries allowed");
    }
}

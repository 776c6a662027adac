//! A fixed ring of the last samples and their median: the robust summary of the viewing
//! angle that Bujold's repositioning decision and RAPOSA's two-block cues both read.

/// Largest median window a viewing-angle estimate may look back over, frames.
pub const MAX_ALPHA_WINDOW: usize = 64;

/// The last `capacity` samples in a fixed ring, with their median: a robust summary that
/// ignores the minority of frames a flash, a shadow edge or a glare notch biases, where a
/// low-pass filter would follow them part of the way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MedianWindow {
    values: [f64; MAX_ALPHA_WINDOW],
    capacity: usize,
    len: usize,
    next: usize,
}

impl MedianWindow {
    /// An empty window of `capacity` samples (clamped to 1..=[`MAX_ALPHA_WINDOW`]).
    pub fn new(capacity: usize) -> Self {
        Self {
            values: [0.0; MAX_ALPHA_WINDOW],
            capacity: capacity.clamp(1, MAX_ALPHA_WINDOW),
            len: 0,
            next: 0,
        }
    }

    /// Forgets every sample.
    pub fn clear(&mut self) {
        self.len = 0;
        self.next = 0;
    }

    /// Adds a sample, dropping the oldest when full.
    pub fn push(&mut self, v: f64) {
        self.values[self.next] = v;
        self.next = (self.next + 1) % self.capacity;
        self.len = (self.len + 1).min(self.capacity);
    }

    /// True when the window holds `capacity` samples.
    pub fn is_full(&self) -> bool {
        self.len == self.capacity
    }

    /// Median of a full window (`None` until `capacity` samples are held): the estimate
    /// a decision may act on.
    pub fn full_median(&self) -> Option<f64> {
        if self.is_full() { self.median() } else { None }
    }

    /// Median of the samples held (`None` when empty); an even count averages the middle two.
    pub fn median(&self) -> Option<f64> {
        if self.len == 0 {
            return None;
        }
        let mut v = self.values;
        let v = &mut v[..self.len];
        v.sort_by(f64::total_cmp);
        let m = self.len / 2;
        Some(if self.len % 2 == 1 {
            v[m]
        } else {
            0.5 * (v[m - 1] + v[m])
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_window_ignores_a_minority_of_outliers_and_forgets_the_oldest() {
        let mut w = MedianWindow::new(16);
        assert_eq!(w.median(), None);
        w.push(3.0);
        w.push(1.0);
        assert_eq!(w.median(), Some(2.0));
        assert_eq!(w.full_median(), None, "not full yet");
        // A steady 0.1 rad with a third of the frames pushed to 0.5 by a flash.
        w.clear();
        for k in 0..16 {
            w.push(if k % 3 == 0 { 0.5 } else { 0.1 });
        }
        assert!(w.is_full());
        assert_eq!(w.median(), Some(0.1));
        assert_eq!(w.full_median(), Some(0.1));
        // A full window of new values replaces the old ones entirely.
        for _ in 0..16 {
            w.push(-0.2);
        }
        assert_eq!(w.median(), Some(-0.2));
        assert_eq!(w.len, 16);
    }
}

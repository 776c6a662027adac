//! Frozen drivers: a camera or odometer that keeps re-sending its last reading, stamped
//! as new.
//!
//! A driver that hangs inside its capture loop often goes on publishing the buffer it
//! holds, with a fresh timestamp each time. Staleness alone cannot see it: every reading
//! looks new. The content can:
//! * **Frames.** An image sensor's shot and read noise make two real exposures differ in
//!   some pixel, even of a still scene (the simulator's sensor model adds read noise, and
//!   `tests/sim_faults.rs` checks that whole docking runs without an input fault spend
//!   under 0.2 s in safe stop with this check on). A frame bit-identical
//!   to the one before is the same exposure again. The loop dates it from when that
//!   content first arrived, so it ages, and the camera's staleness limit stops the robot
//!   as it would for a silent camera. A noiseless synthetic camera (a test double, a
//!   rendered toy world) legitimately repeats frames when nothing moves: turn the check
//!   off there ([`Staleness::camera_repeats_stale`](super::Staleness)).
//! * **Odometry.** A still base reports the same pose every time, so a repeated pose
//!   alone proves nothing. A reading that says the base moves (its twist is not zero)
//!   while its pose stays bit-identical to the last reading's cannot come from a working
//!   odometer: it is dated from its first arrival too. An odometer that froze while the
//!   base stood still reports no motion, which no check on its data alone can tell from a
//!   stall; the behaviors' own progress checks have to catch that one.
//!
//! Readings whose stamp did not change are the same reading seen again (the threaded
//! runtime hands the loop the latest frame each tick, new or not) and are not repeats.
//! A frame is compared by a 64-bit fingerprint of its bytes, so nothing is copied and
//! nothing allocated per frame; two different frames share a fingerprint with
//! probability 2⁻⁶⁴.

use crate::schemas::{Inputs, OdometryReading};

/// The twist below which a base counts as still (m/s and rad/s): far under any speed a
/// drive can hold, far over floating-point residue.
const STILL: f64 = 1e-6;

/// One input's last content, and when that content first arrived.
#[derive(Debug, Clone, Copy)]
struct Seen<T> {
    /// The last reading's stamp (to tell a new reading from the same one seen again).
    stamp: f64,
    /// Its content (a fingerprint for frames, the reading for odometry).
    content: T,
    /// The stamp of the first reading with this content.
    since: f64,
}

impl<T: PartialEq + Copy> Seen<T> {
    /// Updates `slot` with a reading of `content` stamped `stamp`; `repeat` says whether
    /// equal content counts as the same reading.
    fn update(slot: &mut Option<Seen<T>>, stamp: f64, content: T, repeat: bool) {
        match slot {
            Some(s) if s.stamp == stamp => {}
            Some(s) if repeat && s.content == content => {
                s.stamp = stamp;
            }
            _ => {
                *slot = Some(Seen {
                    stamp,
                    content,
                    since: stamp,
                })
            }
        }
    }
}

/// The repeat tracker of one loop: per camera and for odometry, when the current content
/// first arrived.
#[derive(Debug, Clone, Default)]
pub(crate) struct Repeats {
    cameras: Vec<Option<Seen<u64>>>,
    odometry: Option<Seen<OdometryReading>>,
}

impl Repeats {
    /// A tracker for `cameras` cameras (sized once).
    pub(crate) fn new(cameras: usize) -> Self {
        Self {
            cameras: vec![None; cameras],
            odometry: None,
        }
    }

    /// Notes this tick's readings. Frames are fingerprinted only when `frames` is set and
    /// their stamp is new.
    pub(crate) fn observe(&mut self, inputs: &Inputs<'_>, frames: bool) {
        if frames {
            for (i, slot) in self.cameras.iter_mut().enumerate() {
                let Some(c) = inputs.camera(i) else { continue };
                if slot.is_some_and(|s| s.stamp == c.stamp) {
                    continue;
                }
                Seen::update(slot, c.stamp, fingerprint(c.image.as_bytes()), true);
            }
        }
        if let Some(o) = inputs.odometry {
            let moving = o.value.twist.v.abs() > STILL || o.value.twist.omega.abs() > STILL;
            Seen::update(&mut self.odometry, o.stamp, o.value, moving);
        }
    }

    /// The stamp to judge camera `i`'s age by: when its current content first arrived
    /// (`None` before its first frame, or when frames are not tracked).
    pub(crate) fn camera_since(&self, i: usize) -> Option<f64> {
        self.cameras.get(i).copied().flatten().map(|s| s.since)
    }

    /// The stamp to judge odometry's age by (see [`Repeats::camera_since`]).
    pub(crate) fn odometry_since(&self) -> Option<f64> {
        self.odometry.map(|s| s.since)
    }

    /// Forgets everything (a new mission's inputs are judged afresh).
    pub(crate) fn clear(&mut self) {
        self.cameras.iter_mut().for_each(|s| *s = None);
        self.odometry = None;
    }
}

/// A 64-bit fingerprint of `bytes`: four independent lanes, each taking every fourth
/// eight-byte word and mixing it in by a multiply and rotate (the FxHash step), so the four
/// multiplies of a 32-byte step run in parallel instead of one long dependency chain (a
/// single lane was 2–3 % of a simulated tick). The lanes and the length are then folded
/// together and avalanched, so frames of different sizes differ. Not cryptographic: it
/// only has to tell consecutive frames apart.
pub(crate) fn fingerprint(bytes: &[u8]) -> u64 {
    const K: u64 = 0x51_7c_c1_b7_27_22_0a_95;
    let mix = |h: u64, w: u64| (h.rotate_left(5) ^ w).wrapping_mul(K);
    let word = |c: &[u8]| u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
    let mut lanes = [bytes.len() as u64, 1, 2, 3];
    let mut blocks = bytes.chunks_exact(32);
    for b in &mut blocks {
        for (i, lane) in lanes.iter_mut().enumerate() {
            *lane = mix(*lane, word(&b[8 * i..8 * i + 8]));
        }
    }
    let mut h = lanes.into_iter().fold(0, mix);
    let mut words = blocks.remainder().chunks_exact(8);
    for c in &mut words {
        h = mix(h, word(c));
    }
    let mut tail = [0u8; 8];
    tail[..words.remainder().len()].copy_from_slice(words.remainder());
    h = mix(h, u64::from_le_bytes(tail));
    // The murmur3 finaliser: every input bit reaches every output bit.
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^ (h >> 33)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_flipped_bit_changes_the_fingerprint() {
        let mut bytes = vec![7u8; 320 * 240 * 3];
        let base = fingerprint(&bytes);
        for i in [0, 1, 7, 8, 15, 16, 24, 31, 32, 1000, bytes.len() - 1] {
            for bit in [0, 3, 7] {
                bytes[i] ^= 1 << bit;
                assert_ne!(fingerprint(&bytes), base, "byte {i} bit {bit}");
                bytes[i] ^= 1 << bit;
            }
        }
        assert_eq!(fingerprint(&bytes), base);
        assert_ne!(fingerprint(&bytes[..bytes.len() - 3]), base, "length counts");
    }

    #[test]
    fn the_tail_past_the_last_whole_block_counts() {
        // 1003 bytes: 31 blocks of 32, then three whole words and a three-byte tail.
        let mut bytes: Vec<u8> = (0..1003u32).map(|i| (i * 37 % 251) as u8).collect();
        let base = fingerprint(&bytes);
        for i in [991, 992, 999, 1000, 1002] {
            bytes[i] ^= 0x10;
            assert_ne!(fingerprint(&bytes), base, "byte {i}");
            bytes[i] ^= 0x10;
        }
        // Two words swapped between lanes, and within one lane, are different frames.
        let mut swapped = bytes.clone();
        swapped.swap(0, 8);
        assert_ne!(fingerprint(&swapped), base);
        let mut swapped = bytes.clone();
        swapped.swap(0, 32);
        assert_ne!(fingerprint(&swapped), base);
    }

    #[test]
    fn repeated_content_keeps_its_first_stamp() {
        let mut slot = None;
        Seen::update(&mut slot, 1.0, 42u64, true);
        Seen::update(&mut slot, 1.1, 42, true);
        Seen::update(&mut slot, 1.2, 42, true);
        assert_eq!(slot.map(|s| s.since), Some(1.0));
        Seen::update(&mut slot, 1.3, 43, true);
        assert_eq!(slot.map(|s| s.since), Some(1.3));
        // Repeats that do not count (a still odometer) are new readings.
        Seen::update(&mut slot, 1.4, 43, false);
        assert_eq!(slot.map(|s| s.since), Some(1.4));
    }
}

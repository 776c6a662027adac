//! Deterministic randomness owned by the caller: same seed, same stream, on every
//! platform and every version of this crate (no dependency whose output may change).

/// SplitMix64: seeds other generators and derives per-run seeds from (seed, index).
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// xoshiro256++ (Blackman & Vigna): fast, small, good statistical quality.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rng {
    s: [u64; 4],
}

impl Rng {
    /// A generator seeded from one number.
    pub fn new(seed: u64) -> Self {
        let mut x = seed;
        let mut s = [0u64; 4];
        for v in s.iter_mut() {
            x = splitmix64(x);
            *v = x;
        }
        if s == [0; 4] {
            s[0] = 1;
        }
        Self { s }
    }

    /// A generator for stream `index` of `seed` (e.g. one per run of a campaign).
    pub fn derive(seed: u64, index: u64) -> Self {
        Self::new(splitmix64(seed ^ splitmix64(index.wrapping_add(0x5EED))))
    }

    /// A generator of its own for the device (or draw) called `name` in a run seeded
    /// `seed`: adding a device to a run changes none of the run's other streams. (The
    /// name is hashed with 64-bit FNV-1a.)
    pub fn named(seed: u64, name: &str) -> Self {
        let hash = name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        Self::new(seed ^ hash)
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        let r = (self.s[0].wrapping_add(self.s[3]))
            .rotate_left(23)
            .wrapping_add(self.s[0]);
        let t = self.s[1] << 17;
        self.s[2] ^= self.s[0];
        self.s[3] ^= self.s[1];
        self.s[1] ^= self.s[2];
        self.s[0] ^= self.s[3];
        self.s[2] ^= t;
        self.s[3] = self.s[3].rotate_left(45);
        r
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Standard normal (Box–Muller; one value per call, the pair's second is discarded
    /// so the stream position does not depend on call history).
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// A table of standard-normal values (i16, in units of 1/256) for per-pixel sensor noise:
/// one lookup per pixel instead of a logarithm and a cosine.
#[derive(Debug, Clone)]
pub struct NoiseTable {
    values: Vec<i16>,
}

impl NoiseTable {
    /// Size of the table (a power of two).
    pub const LEN: usize = 1 << 16;

    /// Fills the table from `seed`.
    pub fn new(seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        Self {
            values: (0..Self::LEN)
                .map(|_| (rng.normal().clamp(-5.0, 5.0) * 256.0).round() as i16)
                .collect(),
        }
    }

    /// Value `i` (wrapped), × 256.
    #[inline]
    pub fn get(&self, i: usize) -> i16 {
        self.values[i & (Self::LEN - 1)]
    }

    /// `len` consecutive values starting near `start` (wrapped so the window fits;
    /// `len` must not exceed [`NoiseTable::LEN`]).
    pub fn window(&self, start: usize, len: usize) -> &[i16] {
        let len = len.min(Self::LEN);
        let s = start % (Self::LEN - len + 1);
        &self.values[s..s + len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_streams_depend_on_the_name_and_the_seed_only() {
        let draw = |seed, name| Rng::named(seed, name).next_u64();
        assert_eq!(draw(7, "rear_ranges"), draw(7, "rear_ranges"));
        assert_ne!(draw(7, "rear_ranges"), draw(7, "front_ranges"));
        assert_ne!(draw(7, "rear_ranges"), draw(8, "rear_ranges"));
        // The empty name is the seed's own FNV offset: still a valid, distinct stream.
        assert_ne!(draw(7, ""), Rng::new(7).next_u64());
    }

    #[test]
    fn reproducible_and_distinct_streams() {
        let a: Vec<u64> = (0..5)
            .map({
                let mut r = Rng::new(42);
                move |_| r.next_u64()
            })
            .collect();
        let b: Vec<u64> = (0..5)
            .map({
                let mut r = Rng::new(42);
                move |_| r.next_u64()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(Rng::derive(1, 0).next_u64(), Rng::derive(1, 1).next_u64());
    }

    #[test]
    fn normal_moments() {
        let mut r = Rng::new(7);
        let xs: Vec<f64> = (0..200_000).map(|_| r.normal()).collect();
        let m = xs.iter().sum::<f64>() / xs.len() as f64;
        let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / xs.len() as f64;
        assert!(m.abs() < 0.01 && (v - 1.0).abs() < 0.02, "{m} {v}");
        let t = NoiseTable::new(3);
        let tm = (0..NoiseTable::LEN).map(|i| t.get(i) as f64 / 256.0).sum::<f64>() / NoiseTable::LEN as f64;
        assert!(tm.abs() < 0.02);
    }
}

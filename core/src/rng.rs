//! Counter-derived random streams: one per (seed, test bed, estimator, budget, repetition,
//! integral), so results do not depend on the thread count (book: contract.md).
//!
//! Every (experiment seed, test bed, estimator, budget, repetition, integral) gets its own
//! `rand_pcg` stream: the key is hashed with a fixed, versioned mixing function (FNV-1a over the
//! names, SplitMix64 finalisers over the numbers) into the 128-bit state and the 127-bit stream
//! selector of a [`Pcg64`]. Nothing depends on the thread that runs the work, so results are
//! bit-identical for a seed whatever the thread count.

pub use rand_pcg::Pcg64;

/// The RNG every estimator receives.
pub type StreamRng = Pcg64;

/// The coordinates of one estimate in a sweep; each field changes the stream.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct StreamKey<'a> {
    /// The experiment seed (`--seed`).
    pub seed: u64,
    /// Test bed id and variant, e.g. `gradient-plane/default`.
    pub testbed: &'a str,
    /// Estimator id.
    pub estimator: &'a str,
    /// Budget value (samples, fetches, or microseconds).
    pub budget: u64,
    /// Repetition index.
    pub rep: u64,
    /// Integral (pixel) index.
    pub integral: u64,
}

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// FNV-1a 64-bit hash of a string (stable across platforms and compiler versions).
pub fn fnv1a(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01B3))
}

impl StreamKey<'_> {
    /// Two independent 64-bit digests of the key.
    fn digest(&self) -> (u64, u64) {
        let parts = [self.seed, fnv1a(self.testbed), fnv1a(self.estimator), self.budget, self.rep, self.integral];
        let mut a = 0x243F_6A88_85A3_08D3u64;
        let mut b = 0x1319_8A2E_0370_7344u64;
        for p in parts {
            a = splitmix64(a ^ p);
            b = splitmix64(b.rotate_left(17) ^ splitmix64(p));
        }
        (a, b)
    }

    /// The stream for this key.
    pub fn rng(&self) -> StreamRng {
        let (a, b) = self.digest();
        let state = (u128::from(a) << 64) | u128::from(splitmix64(a ^ b));
        let stream = (u128::from(b) << 64) | u128::from(splitmix64(b));
        Pcg64::new(state, stream)
    }
}

/// A stream for a test or a bench: the key with only a seed and a label.
pub fn stream(seed: u64, label: &str) -> StreamRng {
    StreamKey { seed, testbed: label, estimator: "", budget: 0, rep: 0, integral: 0 }.rng()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngCore;

    const PINNED_FIRST_OUTPUT: u64 = 18_080_718_928_167_697_004;

    fn key(rep: u64) -> StreamKey<'static> {
        StreamKey { seed: 7, testbed: "gradient-plane/default", estimator: "is0_cv0", budget: 16, rep, integral: 3 }
    }

    #[test]
    fn same_key_same_stream_and_value_stability() {
        let a: Vec<u64> = (0..4).map(|_| 0).scan(key(0).rng(), |r, _: u64| Some(r.next_u64())).collect();
        let b: Vec<u64> = (0..4).map(|_| 0).scan(key(0).rng(), |r, _: u64| Some(r.next_u64())).collect();
        assert_eq!(a, b);
        // Pinned value: a change of the mixing function changes every stored result; bump the
        // crate version and say so if this ever has to change.
        assert_eq!(a[0], PINNED_FIRST_OUTPUT);
    }

    #[test]
    fn neighbouring_keys_give_unrelated_streams() {
        let mut seen = std::collections::HashSet::new();
        for rep in 0..1000 {
            assert!(seen.insert(key(rep).rng().next_u64()));
        }
        // Changing any single field changes the first output.
        let base = key(0).rng().next_u64();
        let mut k = key(0);
        k.seed = 8;
        assert_ne!(k.rng().next_u64(), base);
        let mut k = key(0);
        k.estimator = "is0_cv1";
        assert_ne!(k.rng().next_u64(), base);
        let mut k = key(0);
        k.integral = 4;
        assert_ne!(k.rng().next_u64(), base);
    }
}

//! Running, exactly mergeable sample statistics.
//!
//! [`NeumaierSum`] is a compensated (Kahan–Babuška–Neumaier) sum; [`Moments`] keeps the count,
//! mean and sum of squared deviations of a sample (Welford's update) and merges two partial
//! results with Chan et al.'s parallel formula. Both are plain floating-point state machines with no
//! hidden randomness or parallelism: the same sequence of `add`/`push`/`merge` calls always gives
//! bit-identical results, which keeps parallel reductions reproducible as long as the merge order is
//! fixed.

use serde::{Deserialize, Serialize};

/// Compensated summation (Neumaier's variant of Kahan summation).
///
/// The running error of every addition is accumulated in a separate compensation term, so the
/// result is accurate to about one rounding of the exact sum regardless of the number of terms
/// (unlike naive summation, whose error grows with the count).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NeumaierSum {
    sum: f64,
    comp: f64,
}

impl NeumaierSum {
    /// An empty sum (value `0.0`).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one term.
    #[inline]
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.comp += (self.sum - t) + x;
        } else {
            self.comp += (x - t) + self.sum;
        }
        self.sum = t;
    }

    /// The compensated value of the sum.
    ///
    /// Non-finite sums (an infinite or NaN term) are returned as the plain running sum, so an
    /// infinite term gives an infinite result rather than NaN.
    pub fn value(&self) -> f64 {
        if self.sum.is_finite() {
            self.sum + self.comp
        } else {
            self.sum
        }
    }

    /// Adds another partial sum into this one (deterministic for a fixed merge order).
    pub fn merge(&mut self, other: &NeumaierSum) {
        self.add(other.sum);
        self.comp += other.comp;
    }
}

impl Extend<f64> for NeumaierSum {
    fn extend<I: IntoIterator<Item = f64>>(&mut self, iter: I) {
        for x in iter {
            self.add(x);
        }
    }
}

impl FromIterator<f64> for NeumaierSum {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> Self {
        let mut s = Self::new();
        s.extend(iter);
        s
    }
}

/// Running count, mean and sums of squared and cubed deviations of a sample.
///
/// The running mean is compensated: it is kept as an unevaluated sum `mean + mean_comp` and every
/// update adds its increment with an error-free two-sum, so 1e8 pushes of a slowly drifting
/// sequence stay within a few ulps of the exact mean (plain Welford drifts by 1.6e-9 relative
/// there; the `stability` experiment's `running-mean` cases measure both).
///
/// Updated one value at a time with Welford's algorithm ([`Moments::push`]) and combined with
/// Chan, Golub and LeVeque's pairwise formula ([`Moments::merge`]), both numerically stable when the
/// mean is large compared with the spread; the third moment follows Terriberry's online update and
/// Pébay's pairwise formula (it feeds [`Moments::skewness`], which says whether a t-test is valid).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Moments {
    n: u64,
    mean: f64,
    /// Sums of powers of deviations can overflow for estimates near 1e103 (an exploding weight):
    /// JSON writes infinity as `null`, which reads back as infinity (for `m3` without its sign:
    /// only its size matters to a skewness gate).
    #[serde(deserialize_with = "overflowed")]
    m2: f64,
    #[serde(default, deserialize_with = "overflowed")]
    m3: f64,
    /// The low part of the compensated mean (`mean + mean_comp`; 0 in files written before it).
    #[serde(default)]
    mean_comp: f64,
}

fn overflowed<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
}

/// Knuth's error-free two-sum: `(s, e)` with `s = fl(a + b)` and `a + b = s + e` exactly.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

impl Moments {
    /// An empty sample.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one observation.
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let nf = self.n as f64;
        let delta = (x - self.mean) - self.mean_comp;
        let delta_n = delta / nf;
        self.m3 += delta * delta_n * delta_n * (nf - 1.0) * (nf - 2.0) - 3.0 * delta_n * self.m2;
        self.add_to_mean(delta_n);
        self.m2 += delta * ((x - self.mean) - self.mean_comp);
    }

    /// Adds `inc` to the compensated mean `mean + mean_comp` (renormalised so `mean` carries it).
    fn add_to_mean(&mut self, inc: f64) {
        let (s, e) = two_sum(self.mean, inc);
        let (hi, lo) = two_sum(s, self.mean_comp + e);
        if hi.is_finite() {
            (self.mean, self.mean_comp) = (hi, lo);
        } else {
            // An infinite or NaN observation: keep the plain running value (no NaN from inf - inf).
            (self.mean, self.mean_comp) = (self.mean + inc, 0.0);
        }
    }

    /// Merges the statistics of another, disjoint sample into this one.
    ///
    /// Deterministic: the same sequence of merges always gives bit-identical results. Merging an
    /// empty sample is a no-op, and merging into an empty sample copies `other`.
    pub fn merge(&mut self, other: &Moments) {
        if other.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = other.clone();
            return;
        }
        let na = self.n as f64;
        let nb = other.n as f64;
        let n = self.n + other.n;
        let nf = n as f64;
        let delta = (other.mean - self.mean) + (other.mean_comp - self.mean_comp);
        self.m3 += other.m3
            + delta * delta * delta * (na * nb * (na - nb) / (nf * nf))
            + 3.0 * delta * (na * other.m2 - nb * self.m2) / nf;
        self.add_to_mean(delta * (nb / nf));
        self.m2 += other.m2 + delta * delta * (na * nb / nf);
        self.n = n;
    }

    /// Number of observations.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// The whole state, `(n, [mean, m2, m3, mean_comp])`, for compact storage:
    /// [`Moments::from_raw`] restores it bit for bit (non-finite sums included).
    pub fn raw(&self) -> (u64, [f64; 4]) {
        (self.n, [self.mean, self.m2, self.m3, self.mean_comp])
    }

    /// The state [`Moments::raw`] returned. Nothing is checked: call [`Moments::check`] on state
    /// read back from files.
    pub fn from_raw(n: u64, [mean, m2, m3, mean_comp]: [f64; 4]) -> Self {
        Moments { n, mean, m2, m3, mean_comp }
    }

    /// Whether the state could have come from pushes and merges of finite values: finite mean and
    /// moments, a non-negative sum of squares (to rounding), and nothing but zeros when empty.
    /// For state read back from files.
    pub fn check(&self) -> Result<(), String> {
        let parts = [self.mean, self.m2, self.m3, self.mean_comp];
        if !self.mean.is_finite() || !self.mean_comp.is_finite() || self.m2.is_nan() || self.m3.is_nan() {
            return Err("non-finite moments".into());
        }
        if self.m2 == f64::NEG_INFINITY {
            return Err("negative sum of squares".into());
        }
        if self.n == 0 && parts.iter().any(|&x| x != 0.0) {
            return Err("moments of an empty sample".into());
        }
        if self.m2 < -1e-9 * (1.0 + self.mean * self.mean) * self.n as f64 {
            return Err(format!("negative sum of squares {}", self.m2));
        }
        Ok(())
    }

    /// Sample mean; `NaN` for an empty sample.
    pub fn mean(&self) -> f64 {
        if self.n == 0 {
            f64::NAN
        } else {
            self.mean + self.mean_comp
        }
    }

    /// Unbiased sample variance (divisor `n - 1`); `NaN` when fewer than 2 observations.
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            f64::NAN
        } else {
            (self.m2 / (self.n - 1) as f64).max(0.0)
        }
    }

    /// Standard error of the mean, `sqrt(variance / n)`; `NaN` when fewer than 2 observations.
    pub fn std_err(&self) -> f64 {
        (self.variance() / self.n as f64).sqrt()
    }

    /// Adjusted Fisher-Pearson sample skewness `G1 = sqrt(n (n - 1)) / (n - 2) * g1` with
    /// `g1 = sqrt(n) m3 / m2^1.5`; `NaN` with fewer than 3 observations or no spread.
    pub fn skewness(&self) -> f64 {
        if self.n < 3 || self.m2 <= 0.0 {
            return f64::NAN;
        }
        let n = self.n as f64;
        let g1 = n.sqrt() * self.m3 / self.m2.powf(1.5);
        g1 * (n * (n - 1.0)).sqrt() / (n - 2.0)
    }
}

impl Extend<f64> for Moments {
    fn extend<I: IntoIterator<Item = f64>>(&mut self, iter: I) {
        for x in iter {
            self.push(x);
        }
    }
}

impl FromIterator<f64> for Moments {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> Self {
        let mut m = Self::new();
        m.extend(iter);
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
    }

    /// Estimates near 1e103 overflow the third (and then the second) power sums; the file keeps
    /// them as `null`, which reads back as infinity and passes the read-back check, so the skewness
    /// gate sees an infinitely skewed cell instead of refusing the folder.
    #[test]
    fn overflowed_power_sums_round_trip_as_infinity() {
        let mut m = Moments::default();
        for x in [0.0, 0.0, 1e104] {
            m.push(x);
        }
        assert!(m.m3.is_infinite() && m.mean().is_finite());
        let text = serde_json::to_string(&m).expect("serialise");
        assert!(text.contains("null"), "{text}");
        let back: Moments = serde_json::from_str(&text).expect("reads back");
        assert!(back.m3 == f64::INFINITY && back.check().is_ok());
        assert!(back.skewness().is_infinite() || back.skewness().is_nan());
    }

    #[test]
    fn neumaier_beats_naive_on_many_tenths() {
        let mut naive = 0.0f64;
        let mut s = NeumaierSum::new();
        for _ in 0..10_000_000 {
            naive += 0.1;
            s.add(0.1);
        }
        // The exact sum of 1e7 copies of fl(0.1) rounds to 1e6.
        assert_eq!(s.value(), 1.0e6);
        assert!((naive - 1.0e6).abs() > 1e-4, "naive = {naive}");
    }

    #[test]
    fn neumaier_handles_classic_cancellation() {
        let xs = [1.0, 1e100, 1.0, -1e100];
        let naive: f64 = xs.iter().sum();
        let s: NeumaierSum = xs.iter().copied().collect();
        assert_eq!(naive, 0.0);
        assert_eq!(s.value(), 2.0);
    }

    #[test]
    fn neumaier_merge_and_non_finite() {
        let mut a: NeumaierSum = [1.0, 1e100].into_iter().collect();
        let b: NeumaierSum = [1.0, -1e100].into_iter().collect();
        a.merge(&b);
        assert_eq!(a.value(), 2.0);
        let inf: NeumaierSum = [1.0, f64::INFINITY, 2.0].into_iter().collect();
        assert_eq!(inf.value(), f64::INFINITY);
        assert_eq!(NeumaierSum::new().value(), 0.0);
    }

    #[test]
    fn moments_basic_values() {
        let m: Moments = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0].into_iter().collect();
        assert_eq!(m.count(), 8);
        assert_eq!(m.mean(), 5.0);
        assert!(rel(m.variance(), 32.0 / 7.0) < 1e-15);
        assert!(rel(m.std_err(), (32.0f64 / 7.0 / 8.0).sqrt()) < 1e-15);
    }

    #[test]
    fn compensated_mean_does_not_drift_on_a_trend() {
        // x_k = 1 + k 1e-6 over 1e7 pushes: plain Welford (the control) drifts by ~1e-10 relative.
        let n = 10_000_000u64;
        let (mut m, mut plain, mut exact) = (Moments::new(), 0.0f64, NeumaierSum::new());
        for k in 0..n {
            let x = 1.0 + k as f64 * 1e-6;
            m.push(x);
            plain += (x - plain) / (k + 1) as f64;
            exact.add(x);
        }
        let want = exact.value() / n as f64;
        assert!(rel(m.mean(), want) < 1e-14, "compensated {:e}", rel(m.mean(), want));
        assert!(rel(plain, want) > 1e-12, "the control should drift: {:e}", rel(plain, want));
        let inf: Moments = [1.0, f64::INFINITY].into_iter().collect();
        assert_eq!(inf.mean(), f64::INFINITY);
    }

    #[test]
    fn moments_small_samples_are_nan() {
        let empty = Moments::new();
        assert!(empty.mean().is_nan() && empty.variance().is_nan() && empty.std_err().is_nan());
        let mut one = Moments::new();
        one.push(3.0);
        assert_eq!(one.mean(), 3.0);
        assert!(one.variance().is_nan() && one.std_err().is_nan());
    }

    #[test]
    fn moments_stable_with_large_offset() {
        // Naive sum-of-squares would lose every digit here.
        let m: Moments = [1e9 + 4.0, 1e9 + 7.0, 1e9 + 13.0, 1e9 + 16.0].into_iter().collect();
        assert!(rel(m.variance(), 30.0) < 1e-9, "{}", m.variance());
    }

    #[test]
    fn merge_equals_sequential_push() {
        let mut rng = Pcg64::seed_from_u64(0x5eed_0001);
        let xs: Vec<f64> = (0..10_007).map(|_| 3.0 + rng.gen::<f64>().powi(3)).collect();
        let seq: Moments = xs.iter().copied().collect();
        let mut merged = Moments::new();
        for chunk in xs.chunks(997) {
            let part: Moments = chunk.iter().copied().collect();
            merged.merge(&part);
        }
        assert_eq!(merged.count(), seq.count());
        assert!(rel(merged.mean(), seq.mean()) < 1e-12);
        assert!(rel(merged.variance(), seq.variance()) < 1e-12);
        assert!(rel(merged.skewness(), seq.skewness()) < 1e-9);
        // Merging is deterministic and empty samples are neutral.
        let mut again = Moments::new();
        for chunk in xs.chunks(997) {
            again.merge(&Moments::new());
            again.merge(&chunk.iter().copied().collect());
        }
        assert_eq!(again, merged);
        let mut into_empty = Moments::new();
        into_empty.merge(&seq);
        assert_eq!(into_empty, seq);
    }

    #[test]
    fn skewness_matches_the_two_pass_formula() {
        let xs = [0.0, 0.0, 0.0, 1.0, 0.0, 3.0, 0.5, 0.0, 0.0, 10.0];
        let m: Moments = xs.iter().copied().collect();
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let (m2, m3) = xs.iter().fold((0.0, 0.0), |(a, b), x| (a + (x - mean).powi(2), b + (x - mean).powi(3)));
        let g1 = n.sqrt() * m3 / m2.powf(1.5);
        let want = g1 * (n * (n - 1.0)).sqrt() / (n - 2.0);
        assert!(rel(m.skewness(), want) < 1e-12, "{} vs {want}", m.skewness());
        let sym: Moments = [1.0, 2.0, 3.0, 4.0, 5.0].into_iter().collect();
        assert!(sym.skewness().abs() < 1e-12);
        let flat: Moments = [2.0; 5].into_iter().collect();
        assert!(flat.skewness().is_nan());
    }
}

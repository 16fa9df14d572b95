//! Two estimators against each other without a reference: whether two sets of independent
//! repetitions estimate the same means.
//!
//! - [`welch_test`]: per integral (and channel), Welch's t-test of the two means from each side's
//!   mean, variance of one repetition and number of repetitions;
//! - [`pooled`]: one test over all integrals, a weighted Bonferroni of two tests that stay valid
//!   however the integrals of one repetition depend on each other (see its doc);
//! - [`p_value_histogram`]: counts of p-values in equal bins of `[0, 1]` (flat under the null).

use super::hypothesis::{holm_bonferroni_finite, welch};
use serde::{Deserialize, Serialize};

/// The share of the pooled test's level given to the test of the sums (the rest goes to the
/// per-integral Holm test), fixed before any outcome is seen.
pub const SUM_SHARE: f64 = 0.8;

/// One Welch test.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WelchResult {
    /// `(mean_a - mean_b) / sqrt(var_a / n_a + var_b / n_b)`.
    pub t: f64,
    /// Welch–Satterthwaite degrees of freedom.
    pub df: f64,
    /// Two-sided p-value (`NaN` when either side has fewer than 2 repetitions).
    pub p: f64,
}

/// Welch's two-sided test of `mean_a = mean_b` from each side's mean, sample variance of one
/// observation and number of observations (independent within and across the sides).
pub fn welch_test(mean_a: f64, var_a: f64, n_a: u64, mean_b: f64, var_b: f64, n_b: u64) -> WelchResult {
    let se = |var: f64, n: u64| if n == 0 || var < 0.0 { f64::NAN } else { (var / n as f64).sqrt() };
    let o = welch(mean_a, se(var_a, n_a), n_a, mean_b, se(var_b, n_b), n_b);
    WelchResult { t: o.statistic, df: o.dof, p: o.p_value }
}

/// The pooled test over all integrals ([`pooled`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pooled {
    /// The pooled p-value: `min(1, p_sum / SUM_SHARE, p_holm / (1 - SUM_SHARE))`, or the one of
    /// the two that exists; `NaN` when neither does.
    pub p: f64,
    /// The test of the per-repetition sums (`NaN` when not given).
    pub p_sum: f64,
    /// The smallest Holm-adjusted per-integral p-value (`NaN` when none is finite).
    pub p_holm: f64,
    /// Per-integral tests with a finite p-value.
    pub tested: usize,
}

/// One test of "the two estimators have the same mean in every integral" over many integrals.
///
/// The integrals of one repetition need not be independent (one adaptive structure per image,
/// the frames of one pixel, correlated colour channels), so Fisher's or Stouffer's combination, or a
/// chi-square of the per-integral z's, which all assume independent integrals, can be far from
/// their nominal size. Two tests that hold under any dependence are combined instead:
/// - `sum`: each repetition's sum over all integrals is one observation, independent across
///   repetitions whatever the integrals share; a Welch test of the two sides' sums sees a
///   difference spread over many integrals, each too small to see alone (it misses differences
///   of opposite signs that cancel);
/// - `holm`: Holm–Bonferroni over the per-integral p-values, valid under any dependence: sees a
///   difference in a few integrals.
///
/// Combined by a weighted Bonferroni ([`SUM_SHARE`] to the sum test), so the family-wise level of
/// the pair is at most the level the pooled p is compared with.
pub fn pooled(per_integral_p: &[f64], sum: Option<&WelchResult>) -> Pooled {
    let adjusted = holm_bonferroni_finite(per_integral_p);
    let tested = adjusted.iter().filter(|p| !p.is_nan()).count();
    let p_holm = adjusted.iter().copied().filter(|p| !p.is_nan()).fold(f64::NAN, f64::min);
    let p_sum = sum.map_or(f64::NAN, |s| s.p);
    let p = match (p_sum.is_nan(), p_holm.is_nan()) {
        (false, false) => (p_sum / SUM_SHARE).min(p_holm / (1.0 - SUM_SHARE)).min(1.0),
        (false, true) => p_sum,
        (true, false) => p_holm,
        (true, true) => f64::NAN,
    };
    Pooled { p, p_sum, p_holm, tested }
}

/// Counts of the finite p-values in `bins` equal bins of `[0, 1]` (a p of exactly 1 in the last);
/// under the null the counts are uniform. `NaN` and values outside `[0, 1]` are not counted.
pub fn p_value_histogram(p_values: &[f64], bins: usize) -> Vec<u64> {
    let mut counts = vec![0u64; bins];
    if bins == 0 {
        return counts;
    }
    for &p in p_values.iter().filter(|p| (0.0..=1.0).contains(*p)) {
        counts[((p * bins as f64) as usize).min(bins - 1)] += 1;
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::Moments;
    use rand::Rng;

    fn normal(rng: &mut impl Rng) -> f64 {
        let (u, v): (f64, f64) = (1.0 - rng.gen::<f64>(), rng.gen::<f64>());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    fn sample(rng: &mut impl Rng, n: usize, mean: f64, sd: f64) -> Moments {
        let mut m = Moments::new();
        for _ in 0..n {
            m.push(mean + sd * normal(rng));
        }
        m
    }

    fn test(a: &Moments, b: &Moments) -> WelchResult {
        welch_test(a.mean(), a.variance(), a.count(), b.mean(), b.variance(), b.count())
    }

    /// Whether `k` rejections in `n` trials are within the 99.9% binomial interval around `alpha`
    /// (normal approximation).
    fn within(k: usize, n: usize, alpha: f64) -> bool {
        let sd = (n as f64 * alpha * (1.0 - alpha)).sqrt();
        (k as f64 - n as f64 * alpha).abs() <= 3.29 * sd
    }

    #[test]
    fn welch_known_value_and_guards() {
        // se^2 = 4/10 + 9/20 = 0.85; t = 1 / sqrt(0.85).
        let r = welch_test(2.0, 4.0, 10, 1.0, 9.0, 20);
        assert!((r.t - 1.0 / 0.85f64.sqrt()).abs() < 1e-12);
        let df = 0.85f64.powi(2) / (0.4f64.powi(2) / 9.0 + 0.45f64.powi(2) / 19.0);
        assert!((r.df - df).abs() < 1e-9 && r.p > 0.2 && r.p < 0.4, "{r:?}");
        assert!(welch_test(1.0, 1.0, 1, 1.0, 1.0, 10).p.is_nan());
        assert_eq!(welch_test(1.0, 0.0, 5, 1.0, 0.0, 5).p, 1.0);
    }

    /// Size by simulation: 2,000 pairs of samples of one distribution (sizes 12 and 30, unequal
    /// spreads are Welch's case, here one normal); the rejection rate at 5% is within the 99.9%
    /// binomial interval (measured: 101 of 2,000, 5.05%).
    #[test]
    fn welch_keeps_its_size() {
        let mut rng = crate::rng::stream(11, "two-sample size");
        let trials = 2000;
        let rejected = (0..trials)
            .filter(|_| test(&sample(&mut rng, 12, 1.0, 0.3), &sample(&mut rng, 30, 1.0, 0.3)).p < 0.05)
            .count();
        eprintln!("welch size: {rejected} of {trials} rejected at 5%");
        assert!(within(rejected, trials, 0.05), "{rejected} of {trials}");
    }

    /// Power: a planted 2% shift (relative spread 5% per repetition, 200 repetitions a side) is
    /// detected at 1e-3 in most trials (measured: 200 of 200).
    #[test]
    fn welch_detects_a_two_percent_shift() {
        let mut rng = crate::rng::stream(12, "two-sample power");
        let trials = 200;
        let found = (0..trials)
            .filter(|_| test(&sample(&mut rng, 400, 1.0, 0.05), &sample(&mut rng, 400, 1.02, 0.05)).p < 1e-3)
            .count();
        eprintln!("welch power: {found} of {trials} found at 1e-3");
        assert!(found >= 190, "{found} of {trials}");
    }

    /// The pooled test over 64 integrals whose repetitions share a common term (correlated
    /// integrals, the case where Fisher or Stouffer would be wrong): size within the binomial
    /// interval at 5% over 1,000 trials or below it (Holm and the Bonferroni split are
    /// conservative; measured: 44 of 1,000), and a 2% shift in every integral found at 1e-3.
    #[test]
    fn pooled_test_size_and_power_with_correlated_integrals() {
        let mut rng = crate::rng::stream(13, "two-sample pooled");
        let side = |rng: &mut crate::rng::StreamRng, shift: f64| {
            let (mut per, mut sum) = (vec![Moments::new(); 64], Moments::new());
            for _ in 0..16 {
                let common = 0.01 * normal(rng);
                let mut s = 0.0;
                for m in per.iter_mut() {
                    let x = (1.0 + shift) * (1.0 + common + 0.02 * normal(rng));
                    m.push(x);
                    s += x;
                }
                sum.push(s);
            }
            (per, sum)
        };
        let run = |rng: &mut crate::rng::StreamRng, shift: f64| {
            let ((pa, sa), (pb, sb)) = (side(rng, 0.0), side(rng, shift));
            let p: Vec<f64> = pa.iter().zip(&pb).map(|(a, b)| test(a, b).p).collect();
            pooled(&p, Some(&test(&sa, &sb))).p
        };
        let trials = 1000;
        let rejected = (0..trials).filter(|_| run(&mut rng, 0.0) < 0.05).count();
        eprintln!("pooled size: {rejected} of {trials} rejected at 5%");
        assert!(rejected as f64 <= 50.0 + 3.29 * (trials as f64 * 0.05 * 0.95).sqrt(), "{rejected}");
        assert!(rejected >= 20, "{rejected} of {trials}: far below the nominal 5%");
        let found = (0..100).filter(|_| run(&mut rng, 0.02) < 1e-3).count();
        eprintln!("pooled power: {found} of 100 found at 1e-3");
        assert!(found >= 85, "{found} of 100");
    }

    #[test]
    fn pooled_combines_the_two_tests_by_weighted_bonferroni() {
        let sum = WelchResult { t: 3.0, df: 10.0, p: 0.008 };
        let p = pooled(&[0.5, 0.002, f64::NAN], Some(&sum));
        assert_eq!(p.tested, 2);
        assert!((p.p_holm - 0.004).abs() < 1e-15);
        assert!((p.p - 0.01).abs() < 1e-15, "{p:?}");
        assert_eq!(pooled(&[0.3], None).p, 0.3);
        assert!(pooled(&[f64::NAN], None).p.is_nan());
    }

    #[test]
    fn histogram_counts_in_equal_bins() {
        let h = p_value_histogram(&[0.0, 0.05, 0.1, 0.55, 1.0, f64::NAN, 1.5], 10);
        assert_eq!(h, vec![2, 1, 0, 0, 0, 1, 0, 0, 0, 1]);
        let mut rng = crate::rng::stream(14, "two-sample histogram");
        let p: Vec<f64> =
            (0..2000).map(|_| test(&sample(&mut rng, 20, 0.0, 1.0), &sample(&mut rng, 20, 0.0, 1.0)).p).collect();
        let h = p_value_histogram(&p, 10);
        assert!(h.iter().all(|&k| within(k as usize, 2000, 0.1)), "{h:?}");
    }
}

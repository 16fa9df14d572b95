//! The power of the location tests: the smallest shift a two-sided test detects with a given
//! probability, for one z- or t-test and for the strongest of several, and the skewness up to
//! which a t-test keeps its nominal size.

use super::hypothesis::{t_quantile, NORMAL_LIMIT_DOF};
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};
use statrs::function::erf::erfc;

/// Smallest absolute shift that a two-sided t-test at level `alpha` with `dof` degrees of freedom
/// detects with probability `power`, given its standard error:
/// `(t_{1-alpha/2, dof} + t_{power, dof}) * std_err` (the noncentral t approximated by a shifted
/// central one, as for [`detectable_shift`]).
pub fn detectable_shift_t(std_err: f64, alpha: f64, power: f64, dof: f64) -> f64 {
    let in_unit = |x: f64| x > 0.0 && x < 1.0;
    if !in_unit(alpha) || !in_unit(power) {
        return f64::NAN;
    }
    (t_quantile(1.0 - alpha / 2.0, dof) + t_quantile(power, dof)) * std_err
}

/// Smallest absolute bias that a two-sided z-test at level `alpha` detects with probability
/// `power`, given the standard error of the estimate: `(z_{1-alpha/2} + z_{power}) * std_err`.
///
/// (The negligible opposite-tail rejection probability is ignored, as is standard.) Returns `NaN`
/// unless `0 < alpha < 1` and `0 < power < 1`.
pub fn detectable_shift(std_err: f64, alpha: f64, power: f64) -> f64 {
    let in_unit = |x: f64| x > 0.0 && x < 1.0;
    if !in_unit(alpha) || !in_unit(power) {
        return f64::NAN;
    }
    let normal = Normal::new(0.0, 1.0).expect("standard normal parameters are valid");
    // Upper quantile from the lower tail keeps precision for tiny alpha.
    let z_alpha = -normal.inverse_cdf(alpha / 2.0);
    let z_power = normal.inverse_cdf(power);
    (z_alpha + z_power) * std_err
}

/// Smallest shift `s` at which at least one of several independent two-sided t-tests, each at
/// level `alpha` with `dof` degrees of freedom, rejects with probability `power`, when test `i`'s
/// statistic has noncentrality `s * strength[i]` (its signal per unit shift over its standard
/// error). Each test's power is `F_t(s q_i - t_{1-alpha/2})` (the noncentral t approximated by a
/// shifted central one and the opposite tail ignored, as for [`detectable_shift_t`]), and the
/// tests' powers combine as `1 - prod(1 - P_i)`. With one test it is `detectable_shift_t` with
/// unit standard error over `strength[0]`. For dependent tests the combined power is smaller: pass
/// only the strongest test then, whose power bounds it from below whatever the dependence.
///
/// Returns `NaN` without a positive finite strength or outside `0 < alpha, power < 1`.
pub fn detectable_shift_any(strength: &[f64], alpha: f64, power: f64, dof: f64) -> f64 {
    let in_unit = |x: f64| x > 0.0 && x < 1.0;
    let q: Vec<f64> = strength.iter().copied().filter(|q| q.is_finite() && *q > 0.0).collect();
    if !in_unit(alpha) || !in_unit(power) || q.is_empty() || dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    let crit = t_quantile(1.0 - alpha / 2.0, dof);
    let cdf = |x: f64| {
        if dof > NORMAL_LIMIT_DOF {
            0.5 * erfc(-x / std::f64::consts::SQRT_2)
        } else {
            StudentsT::new(0.0, 1.0, dof).map(|t| t.cdf(x)).unwrap_or(f64::NAN)
        }
    };
    // log(1 - combined power): the sum of each test's log miss probability, decreasing in s.
    let log_miss = |s: f64| q.iter().map(|&qi| (-cdf(s * qi - crit)).ln_1p()).sum::<f64>();
    let target = (-power).ln_1p();
    // The strongest test alone reaches the power at `hi`; a shift that no test sees leaves `lo`.
    let q_max = q.iter().copied().fold(0.0, f64::max);
    let (mut lo, mut hi) = (0.0, (crit + t_quantile(power, dof)) / q_max);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if log_miss(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The largest sample skewness at which a one-sample t-test of `n` observations keeps its two-sided
/// tail at `alpha` within a factor 2 of nominal, by the first Edgeworth term of the studentised
/// mean: one tail moves by about `phi(z) |G1| (2 z^2 + 1) / (6 sqrt(n))` against
/// `1 - Phi(z) ~ phi(z) / z` at the critical value `z`, so the limit is
/// `6 sqrt(n) / (z (2 z^2 + 1))`. A skewed estimator (a rare large value, a binary outcome) needs
/// many repetitions before a t-test at a tiny per-test alpha means anything; beyond the limit the
/// test is not run (its p-value would be an artefact of the skew, not evidence of bias).
pub fn t_test_skewness_limit(n: u64, alpha: f64) -> f64 {
    if n < 3 || !(alpha > 0.0 && alpha < 1.0) {
        return 0.0;
    }
    let normal = Normal::new(0.0, 1.0).expect("standard normal parameters are valid");
    let z = -normal.inverse_cdf(alpha / 2.0);
    6.0 * (n as f64).sqrt() / (z * (2.0 * z * z + 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::hypothesis::one_sample_t;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn detectable_shift_any_reduces_to_one_test_and_gains_from_many() {
        let one = detectable_shift_any(&[2.0], 1e-3, 0.8, 30.0);
        assert!(close(one, detectable_shift_t(0.5, 1e-3, 0.8, 30.0), 1e-9), "{one}");
        // Many equal independent tests at a Bonferroni level: each weak, together they resolve a
        // shift smaller than one of them alone at that level.
        let m = 1000;
        let alone = detectable_shift_any(&[1.0], 1e-3 / m as f64, 0.8, 1e9);
        let all = detectable_shift_any(&vec![1.0; m], 1e-3 / m as f64, 0.8, 1e9);
        assert!(all < 0.6 * alone, "{all} vs {alone}");
        // The combined power at the returned shift is the asked one.
        let normal = Normal::new(0.0, 1.0).unwrap();
        let crit = -normal.inverse_cdf(1e-3 / m as f64 / 2.0);
        let miss = (1.0 - normal.cdf(all - crit)).powi(m as i32);
        assert!(close(1.0 - miss, 0.8, 1e-6), "{}", 1.0 - miss);
        // Tests that see nothing do not count; none at all gives NaN.
        assert_eq!(detectable_shift_any(&[2.0, 0.0, f64::NAN], 1e-3, 0.8, 30.0), one);
        assert!(detectable_shift_any(&[], 1e-3, 0.8, 30.0).is_nan());
    }

    #[test]
    fn detectable_shift_known_values() {
        // alpha = 0.05, power = 0.8: 1.959964 + 0.841621 = 2.801585.
        let d = detectable_shift(2.0, 0.05, 0.8);
        assert!(close(d, 2.0 * 2.801_585_218_1, 1e-8), "{d}");
        // power = 0.5 leaves only the critical value.
        assert!(close(detectable_shift(1.0, 1e-3, 0.5), 3.290_526_731_5, 1e-8));
        assert!(detectable_shift(1.0, 0.0, 0.8).is_nan());
        assert!(detectable_shift(1.0, 0.05, 1.0).is_nan());
        // A bias of exactly that size is detected with about the stated power.
        let se = 0.1;
        let shift = detectable_shift(se, 0.01, 0.9);
        let crit = 2.575_829_303_548_901;
        let normal = Normal::new(0.0, 1.0).unwrap();
        let power = normal.sf(crit - shift / se) + normal.cdf(-crit - shift / se);
        assert!((power - 0.9).abs() < 1e-6, "{power}");
    }

    /// Type I error of the two-sided t-test at `alpha` over `trials` samples of 16 draws of `draw`
    /// (whose mean is `mu`).
    fn t_test_size(mut draw: impl FnMut(&mut rand_pcg::Pcg64) -> f64, mu: f64, alpha: f64, trials: usize) -> f64 {
        use rand::SeedableRng;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0x7e57);
        let mut rejected = 0;
        for _ in 0..trials {
            let m: crate::stats::Moments = (0..16).map(|_| draw(&mut rng)).collect();
            rejected += usize::from(one_sample_t(m.mean(), m.std_err(), 16, mu).p_value < alpha);
        }
        rejected as f64 / trials as f64
    }

    #[test]
    fn skewness_limit_separates_valid_from_invalid_t_tests() {
        use rand::Rng;
        // n = 16 at the Holm per-test alpha of a 768-integral cell at family alpha 1e-3.
        let tiny = t_test_skewness_limit(16, 1e-3 / 768.0);
        assert!((tiny - 0.1037).abs() < 1e-3, "{tiny}");
        assert!(t_test_skewness_limit(64, 0.01) > t_test_skewness_limit(16, 0.01));
        assert_eq!(t_test_skewness_limit(2, 0.01), 0.0);
        // At alpha = 0.01 and n = 16 the limit is about 0.65. Exponential draws (skewness 2, beyond
        // it) give a size more than twice nominal; Gamma(44) draws (skewness 0.30, within it) do not.
        let limit = t_test_skewness_limit(16, 0.01);
        assert!((limit - 0.653).abs() < 1e-2, "{limit}");
        let exp = |r: &mut rand_pcg::Pcg64| -(1.0 - r.gen::<f64>()).ln();
        let skewed = t_test_size(exp, 1.0, 0.01, 40_000);
        let gamma = |r: &mut rand_pcg::Pcg64| (0..44).map(|_| exp(r)).sum::<f64>();
        let mild = t_test_size(gamma, 44.0, 0.01, 40_000);
        assert!(skewed > 0.02, "exponential: size {skewed}");
        assert!(mild < 0.02 && mild > 0.005, "gamma(44): size {mild}");
    }
}

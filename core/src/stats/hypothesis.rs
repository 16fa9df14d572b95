//! Location tests (one-sample t, z, Welch), their quantiles and multiple-testing corrections;
//! the power of a test (the smallest shift it detects) is [`crate::stats::power`]'s, re-exported here.
//!
//! All p-values are two-sided and computed from the lower tail, `2 * cdf(-|t|)`, never as
//! `1 - cdf`, so values down to about `1e-300` survive instead of rounding to zero. A zero standard
//! error is handled explicitly: the p-value is `1` when the mean equals the reference exactly and
//! `0` otherwise (the statistic is then `±inf`).

pub use super::power::{detectable_shift, detectable_shift_any, detectable_shift_t, t_test_skewness_limit};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};
use statrs::function::erf::erfc;

/// Above this many degrees of freedom the Student t tail is evaluated as a normal tail: statrs'
/// incomplete beta loses accuracy there, while the normal limit is accurate to better than `1e-7`.
pub(crate) const NORMAL_LIMIT_DOF: f64 = 1e7;

/// Result of a two-sided test.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestOutcome {
    /// Test statistic (t or z), signed: positive when the estimate exceeds the reference.
    pub statistic: f64,
    /// Two-sided p-value; `NaN` when the test is undefined (e.g. fewer than 2 observations).
    pub p_value: f64,
    /// Degrees of freedom of the reference distribution (`inf` for a z-test).
    pub dof: f64,
}

/// Two-sided normal tail `2 * Phi(-|z|)`, accurate far into the tail.
fn two_sided_normal(z: f64) -> f64 {
    erfc(z.abs() / std::f64::consts::SQRT_2)
}

/// Two-sided Student t tail `2 * F(-|t|)` with `dof` degrees of freedom.
fn two_sided_t(t: f64, dof: f64) -> f64 {
    if dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    if dof > NORMAL_LIMIT_DOF {
        return two_sided_normal(t);
    }
    match StudentsT::new(0.0, 1.0, dof) {
        Ok(dist) => (2.0 * dist.cdf(-t.abs())).min(1.0),
        Err(_) => f64::NAN,
    }
}

/// Shared core: statistic from a difference and its standard error, with the zero-error guard.
fn outcome(diff: f64, std_err: f64, dof: f64, tail: impl Fn(f64) -> f64) -> TestOutcome {
    if diff.is_nan() || std_err.is_nan() || std_err < 0.0 {
        return TestOutcome { statistic: f64::NAN, p_value: f64::NAN, dof };
    }
    if std_err == 0.0 {
        let (statistic, p_value) = if diff == 0.0 { (0.0, 1.0) } else { (f64::INFINITY.copysign(diff), 0.0) };
        return TestOutcome { statistic, p_value, dof };
    }
    let statistic = diff / std_err;
    TestOutcome { statistic, p_value: tail(statistic), dof }
}

/// One-sample two-sided t-test of `mean` against `reference`, given the standard error of the
/// mean and the sample size `n` (Student t with `n - 1` degrees of freedom).
///
/// `n < 2` gives a `NaN` p-value (no variance estimate). A zero standard error gives `p = 1` if
/// `mean == reference` and `p = 0` otherwise.
pub fn one_sample_t(mean: f64, std_err: f64, n: u64, reference: f64) -> TestOutcome {
    let dof = n.saturating_sub(1) as f64;
    let mut out = outcome(mean - reference, std_err, dof, |t| two_sided_t(t, dof));
    if n < 2 {
        out.p_value = f64::NAN;
    }
    out
}

/// Two-sided t-test of a difference `diff` with standard error `std_err` and `dof` degrees of
/// freedom (infinite: a z-test). A zero standard error gives `p = 1` for a zero difference, `0`
/// otherwise.
pub fn t_test(diff: f64, std_err: f64, dof: f64) -> TestOutcome {
    if dof.is_infinite() {
        return outcome(diff, std_err, dof, two_sided_normal);
    }
    outcome(diff, std_err, dof, |t| two_sided_t(t, dof))
}

/// The upper `p` quantile of Student's t with `dof` degrees of freedom (normal for infinite or
/// very large `dof`); `NaN` outside `0 < p < 1` or for `dof <= 0`.
pub fn t_quantile(p: f64, dof: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) || dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    if dof > NORMAL_LIMIT_DOF {
        return Normal::new(0.0, 1.0).map(|n| n.inverse_cdf(p)).unwrap_or(f64::NAN);
    }
    StudentsT::new(0.0, 1.0, dof).map(|t| t.inverse_cdf(p)).unwrap_or(f64::NAN)
}

/// The lower `p` quantile of the chi-square distribution with `dof` degrees of freedom; `NaN`
/// outside `0 < p < 1` or for `dof <= 0`.
pub fn chi_square_quantile(p: f64, dof: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) || dof.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    statrs::distribution::ChiSquared::new(dof).map(|c| c.inverse_cdf(p)).unwrap_or(f64::NAN)
}

/// Two-sided z-test of `mean` against `reference` with a known standard error.
///
/// A zero standard error gives `p = 1` if `mean == reference` and `p = 0` otherwise.
pub fn z_test(mean: f64, std_err: f64, reference: f64) -> TestOutcome {
    outcome(mean - reference, std_err, f64::INFINITY, two_sided_normal)
}

/// Welch's two-sample two-sided t-test of `mean1 - mean2 = 0`, from each sample's mean, standard
/// error of the mean and size.
///
/// Degrees of freedom by Welch–Satterthwaite from the standard errors:
/// `(se1² + se2²)² / (se1⁴/(n1-1) + se2⁴/(n2-1))`. Either sample with fewer than 2 observations
/// gives a `NaN` p-value; both standard errors zero gives `p = 1` for equal means, `0` otherwise.
pub fn welch(mean1: f64, se1: f64, n1: u64, mean2: f64, se2: f64, n2: u64) -> TestOutcome {
    let v1 = se1 * se1;
    let v2 = se2 * se2;
    let small = n1 < 2 || n2 < 2;
    let dof = if small {
        f64::NAN
    } else {
        let denom = v1 * v1 / (n1 - 1) as f64 + v2 * v2 / (n2 - 1) as f64;
        if denom > 0.0 {
            (v1 + v2) * (v1 + v2) / denom
        } else {
            // Both errors zero: the guard below decides; report the pooled sample dof.
            (n1 + n2 - 2) as f64
        }
    };
    let se = if se1 < 0.0 || se2 < 0.0 { f64::NAN } else { (v1 + v2).sqrt() };
    let mut out = outcome(mean1 - mean2, se, dof, |t| two_sided_t(t, dof));
    if small {
        out.p_value = f64::NAN;
    }
    out
}

/// Holm–Bonferroni adjusted p-values, returned in the input order.
///
/// The smallest of `m` p-values is multiplied by `m`, the next by `m - 1`, and so on; the result is
/// made monotone (step-down running maximum) and capped at 1. Reject hypothesis `i` at family-wise
/// level `alpha` iff `adjusted[i] <= alpha`. `NaN` inputs count as `1` in the procedure (they still
/// count towards `m`, which is conservative) and come back as `NaN`, which never compares
/// `<= alpha`.
pub fn holm_bonferroni(p_values: &[f64]) -> Vec<f64> {
    let m = p_values.len();
    let key = |p: f64| if p.is_nan() { 1.0 } else { p };
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| key(p_values[a]).total_cmp(&key(p_values[b])));
    let mut adjusted = vec![0.0; m];
    let mut running = 0.0f64;
    for (rank, &i) in order.iter().enumerate() {
        let scaled = ((m - rank) as f64 * key(p_values[i])).min(1.0);
        running = running.max(scaled);
        adjusted[i] = if p_values[i].is_nan() { f64::NAN } else { running };
    }
    adjusted
}

/// Holm–Bonferroni over the finite p-values only, returned in the input order: a `NaN` (no test)
/// does not count towards `m` and comes back as `NaN`. For a family of which only some members
/// could be tested (a claim over many cells or rows, some without a valid test).
pub fn holm_bonferroni_finite(p_values: &[f64]) -> Vec<f64> {
    let finite: Vec<f64> = p_values.iter().copied().filter(|p| !p.is_nan()).collect();
    let mut holm = holm_bonferroni(&finite).into_iter();
    p_values.iter().map(|p| if p.is_nan() { f64::NAN } else { holm.next().unwrap_or(f64::NAN) }).collect()
}

/// Šidák per-test level `1 - (1 - alpha)^(1/m)` for a family-wise level `alpha` over `m`
/// independent tests, computed as `-expm1(ln_1p(-alpha) / m)` to stay accurate for tiny `alpha`.
/// `m = 0` returns `alpha` unchanged.
pub fn sidak_alpha(alpha: f64, m: usize) -> f64 {
    if m == 0 {
        return alpha;
    }
    -((-alpha).ln_1p() / m as f64).exp_m1()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn t_test_known_value() {
        // t = 2, dof = 10: two-sided p = 0.073388034770740...
        let out = one_sample_t(3.0, 0.5, 11, 2.0);
        assert_eq!(out.statistic, 2.0);
        assert_eq!(out.dof, 10.0);
        assert!(close(out.p_value, 0.073_388_034_770_74, 1e-9), "{}", out.p_value);
        // Sign does not matter for a two-sided test.
        let neg = one_sample_t(1.0, 0.5, 11, 2.0);
        assert_eq!(neg.statistic, -2.0);
        assert_eq!(neg.p_value, out.p_value);
    }

    #[test]
    fn t_test_guards() {
        assert!(one_sample_t(1.0, 0.1, 1, 0.0).p_value.is_nan());
        assert!(one_sample_t(1.0, 0.1, 0, 0.0).p_value.is_nan());
        let exact = one_sample_t(2.0, 0.0, 10, 2.0);
        assert_eq!((exact.statistic, exact.p_value), (0.0, 1.0));
        let off = one_sample_t(2.5, 0.0, 10, 2.0);
        assert_eq!((off.statistic, off.p_value), (f64::INFINITY, 0.0));
        assert_eq!(one_sample_t(1.5, 0.0, 10, 2.0).statistic, f64::NEG_INFINITY);
        assert!(one_sample_t(f64::NAN, 0.1, 10, 2.0).p_value.is_nan());
    }

    #[test]
    fn t_test_extreme_tail_is_not_rounded_to_zero() {
        // dof = 10, t = 1e6: p ~ 2.5e-57 analytically; 1 - cdf would give 0.
        let p = one_sample_t(1e6, 1.0, 11, 0.0).p_value;
        assert!(p > 0.0 && p < 1e-50, "{p}");
        // Huge dof falls back to the normal tail and stays continuous.
        let big = one_sample_t(2.0, 1.0, 100_000_000, 0.0).p_value;
        assert!(close(big, 0.045_500_263_896_358, 1e-6), "{big}");
    }

    #[test]
    fn z_test_known_values_and_deep_tail() {
        let out = z_test(1.959_963_984_540_054, 1.0, 0.0);
        // statrs erfc is accurate to ~1e-10 relative here.
        assert!(close(out.p_value, 0.05, 1e-9), "{}", out.p_value);
        assert_eq!(out.dof, f64::INFINITY);
        // 2 * Phi(-37) = 1.1451e-299: representable, must not be 0.
        let deep = z_test(0.0, 1.0, 37.0);
        assert!(close(deep.p_value, 1.145_114e-299, 1e-5), "{}", deep.p_value);
        assert_eq!(z_test(1.0, 0.0, 1.0).p_value, 1.0);
        assert_eq!(z_test(1.0, 0.0, 0.0).p_value, 0.0);
    }

    #[test]
    fn welch_matches_textbook_dof_and_reduces_to_t() {
        // se1 = 1, n1 = 11; se2 = 0 -> dof = n1 - 1 and the test is the one-sample t.
        let one = welch(3.0, 0.5, 11, 2.0, 0.0, 5);
        assert!(close(one.dof, 10.0, 1e-12), "{}", one.dof);
        assert!(close(one.p_value, 0.073_388_034_770_74, 1e-9));
        // Equal errors and sizes: dof = 2 (n - 1).
        let eq = welch(1.0, 0.3, 8, 0.0, 0.3, 8);
        assert!(close(eq.dof, 14.0, 1e-12), "{}", eq.dof);
        // Hand computation: se1^2 = 0.04, se2^2 = 0.09, n1 = 10, n2 = 20.
        let w = welch(1.0, 0.2, 10, 0.5, 0.3, 20);
        let dof = 0.13f64.powi(2) / (0.0016 / 9.0 + 0.0081 / 19.0);
        assert!(close(w.dof, dof, 1e-12));
        assert!(close(w.statistic, 0.5 / 0.13f64.sqrt(), 1e-12));
        assert!(w.p_value > 0.1 && w.p_value < 0.2, "{}", w.p_value);
        assert!(welch(1.0, 0.2, 1, 0.5, 0.3, 20).p_value.is_nan());
        assert_eq!(welch(1.0, 0.0, 5, 1.0, 0.0, 5).p_value, 1.0);
    }

    #[test]
    fn holm_textbook_examples() {
        // R: p.adjust(c(0.01, 0.02, 0.03, 0.04, 0.05), "holm") = 0.05 0.08 0.09 0.09 0.09
        let adj = holm_bonferroni(&[0.01, 0.02, 0.03, 0.04, 0.05]);
        let want = [0.05, 0.08, 0.09, 0.09, 0.09];
        for (a, w) in adj.iter().zip(want) {
            assert!(close(*a, w, 1e-12), "{adj:?}");
        }
        // Unsorted input, output in input order; monotone step-down.
        let adj = holm_bonferroni(&[0.01, 0.04, 0.03, 0.005]);
        let want = [0.03, 0.06, 0.06, 0.02];
        for (a, w) in adj.iter().zip(want) {
            assert!(close(*a, w, 1e-12), "{adj:?}");
        }
        // Capped at 1.
        assert_eq!(holm_bonferroni(&[0.6, 0.7]), vec![1.0, 1.0]);
        assert!(holm_bonferroni(&[]).is_empty());
    }

    #[test]
    fn holm_over_the_finite_values_only() {
        let adj = holm_bonferroni_finite(&[f64::NAN, 0.01, 0.2]);
        assert!(adj[0].is_nan());
        // m = 2, not 3: 0.01 * 2 and 0.2 * 1 made monotone.
        assert_eq!((adj[1], adj[2]), (0.02, 0.2));
        assert_eq!(holm_bonferroni(&[0.01, 0.2]), adj[1..].to_vec());
    }

    #[test]
    fn holm_nan_safe() {
        let adj = holm_bonferroni(&[f64::NAN, 0.01, 0.2]);
        assert!(adj[0].is_nan());
        assert!(close(adj[1], 0.03, 1e-12));
        assert!(close(adj[2], 0.4, 1e-12));
    }

    #[test]
    fn sidak_values() {
        assert!(close(sidak_alpha(0.01, 1), 0.01, 1e-14));
        let a = sidak_alpha(0.05, 10);
        assert!(close(a, 1.0 - 0.95f64.powf(0.1), 1e-12));
        assert!(close(a, 0.005_116_196_891_275, 1e-9), "{a}");
        // Tiny alpha: ~ alpha / m without cancellation.
        assert!(close(sidak_alpha(1e-15, 3), 1e-15 / 3.0, 1e-9));
        assert_eq!(sidak_alpha(0.01, 0), 0.01);
    }
}

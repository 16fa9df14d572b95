//! What a run concludes: convergence-slope fits (SPEC §5), unbiasedness tests (SPEC §6) and the
//! papers' speed-up computation (paper 000/001).

use crate::cell::CellResult;
use crate::metrics::SummaryRow;
use estimators::estimator::Bias;
use estimators::stats::{
    detectable_shift, holm_bonferroni, log_log_fit, one_sample_t, t_test_skewness_limit, welch, z_test,
};
use estimators::testbed::{Reference, ReferenceKind};
use serde::{Deserialize, Serialize};

/// Family-wise significance of the unbiasedness tests (SPEC §6).
pub const UNBIASEDNESS_ALPHA: f64 = 1e-3;
/// Power at which the detectable bias is reported.
pub const POWER: f64 = 0.8;

/// A convergence-slope fit of log RMSE on log budget.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// Fitted slope (the order of convergence is -slope).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub slope: f64,
    /// 95% confidence interval, low end.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub slope_ci_low: f64,
    /// 95% confidence interval, high end.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub slope_ci_high: f64,
    /// Coefficient of determination.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub r2: f64,
    /// Intercept of the fit (log RMSE at budget 1).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub intercept: f64,
    /// Budgets used.
    pub budgets: Vec<u64>,
}

/// Fits every (test bed, variant, estimator) series of rows (at least 3 budgets with RMSE > 0).
pub fn fits(rows: &[SummaryRow]) -> Vec<Fit> {
    let mut out = Vec::new();
    for series in group(rows) {
        let pts: Vec<&SummaryRow> = series.into_iter().filter(|r| r.rmse > 0.0).collect();
        let x: Vec<f64> = pts.iter().map(|r| r.budget as f64).collect();
        let y: Vec<f64> = pts.iter().map(|r| r.rmse).collect();
        if let Ok(f) = log_log_fit(&x, &y) {
            out.push(Fit {
                testbed: pts[0].testbed.clone(),
                variant: pts[0].variant.clone(),
                estimator: pts[0].estimator.clone(),
                slope: f.slope,
                slope_ci_low: f.slope_ci_low,
                slope_ci_high: f.slope_ci_high,
                r2: f.r2,
                intercept: f.intercept,
                budgets: pts.iter().map(|r| r.budget).collect(),
            });
        }
    }
    out
}

/// Rows grouped by (test bed, variant, estimator), in first-appearance order.
pub fn group(rows: &[SummaryRow]) -> Vec<Vec<&SummaryRow>> {
    let mut groups: Vec<Vec<&SummaryRow>> = Vec::new();
    for r in rows {
        match groups
            .iter_mut()
            .find(|g| g[0].testbed == r.testbed && g[0].variant == r.variant && g[0].estimator == r.estimator)
        {
            Some(g) => g.push(r),
            None => groups.push(vec![r]),
        }
    }
    groups
}

/// One statistical test verdict.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestRow {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// `holm_t` (exact reference), `holm_welch` (stored reference) or `pooled_z`.
    pub test: String,
    /// Budget the test ran at.
    pub budget: u64,
    /// Test statistic (largest |t| for the Holm tests; infinite when an estimate has zero
    /// variance and misses the reference, which JSON stores as `null` and reads back as NaN).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub statistic: f64,
    /// Smallest Holm-adjusted p-value (or the pooled test's p-value); `NaN` when nothing was tested.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub p_value: f64,
    /// `pass` (no bias detected), `biased` (flagged at alpha) or `untested` (every integral too
    /// skewed for a t-test at this many repetitions, see `untested`).
    pub verdict: String,
    /// Family-wise alpha.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub alpha: f64,
    /// Relative bias the test detects with 80% power (median over integrals for Holm tests).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub detectable_rel_bias: f64,
    /// What the paper claims (`unbiased`, `consistent`, `biased`).
    pub claim: String,
    /// Whether the verdict agrees with the claim (a biased control must be flagged).
    pub agrees: bool,
    /// Holm tests: integral-channels left out because their sample skewness exceeds
    /// [`t_test_skewness_limit`] at the per-test alpha or their repetitions all agree (the t-test's
    /// p-value would reflect the skew, not a bias); the pooled test covers them.
    #[serde(default)]
    pub untested: usize,
}

fn row(cell: &CellResult, claim: Bias, test: &str, statistic: f64, p: f64, detectable: f64) -> TestRow {
    let flagged = p < UNBIASEDNESS_ALPHA;
    let verdict = if p.is_nan() {
        "untested"
    } else if flagged {
        "biased"
    } else {
        "pass"
    };
    TestRow {
        testbed: cell.key.testbed.clone(),
        variant: cell.key.variant.clone(),
        estimator: cell.key.estimator.clone(),
        test: test.to_string(),
        budget: cell.key.budget.amount,
        statistic,
        p_value: p,
        verdict: verdict.to_string(),
        alpha: UNBIASEDNESS_ALPHA,
        detectable_rel_bias: detectable,
        claim: claim.name().to_string(),
        agrees: match claim {
            Bias::Unbiased => !flagged,
            Bias::Biased => flagged,
            Bias::Consistent => true,
        },
        untested: 0,
    }
}

/// The standard error of the sample skewness of `n` normal observations,
/// `sqrt(6 n (n - 1) / ((n - 2) (n + 1) (n + 3)))`.
fn skewness_se(n: u64) -> f64 {
    let n = n as f64;
    (6.0 * n * (n - 1.0) / ((n - 2.0) * (n + 1.0) * (n + 3.0))).sqrt()
}

/// The SPEC §6 unbiasedness tests of one cell.
///
/// `holm_t` / `holm_welch`: per integral and channel a t-test (exact reference) or Welch test
/// (stored reference), Holm-Bonferroni over those that are valid: an integral-channel whose
/// repetitions are too skewed for a t-test at the per-test alpha (sample skewness beyond
/// [`t_test_skewness_limit`] by more than twice its own standard error, so that symmetric data are
/// not dropped for the noise of their skewness estimate; a delta-tracking pixel of low
/// transmittance scores mostly 0) or all agree on a value off the reference is counted in
/// `untested` instead, because its t statistic measures the skew, not a bias (unless every integral
/// of the cell has zero variance: a deterministic estimator off an exact reference beyond its
/// bound is biased, p = 0). When the mean skewness
/// over all the cell's integrals is beyond the limit, every integral is (a heavy tail shows across
/// integrals even where one integral's repetitions missed it), and the Holm verdict is `untested`.
///
/// `pooled_z`: the summed deviation `sum (mean - ref)` over every integral and channel against its
/// standard error (integrals independent, channels of an integral taken as fully correlated). Its weights do not depend on the outcomes and the sum of many
/// independent deviations is close to normal, so skewed or zero-variance integrals cannot fake a bias
/// (a sum of relative deviations would be dominated by the integrals of smallest reference).
pub fn unbiasedness(cell: &CellResult, reference: &Reference, claim: Bias) -> Vec<TestRow> {
    let reps = cell.key.reps as u64;
    let m = cell.moments.len() * 3;
    let stored_n = match &reference.kind {
        ReferenceKind::Stored { samples, .. } => Some(*samples),
        ReferenceKind::Exact { .. } => None,
    };
    let exact_bound = match &reference.kind {
        ReferenceKind::Exact { bound, .. } => bound.max(0.0),
        ReferenceKind::Stored { .. } => 0.0,
    };
    let (mut ps, mut max_t, mut detect, mut untested) = (Vec::with_capacity(m), 0.0f64, Vec::with_capacity(m), 0);
    let (mut dev, mut dev_var, mut ref_sum) = (0.0, 0.0, 0.0);
    let per_test_alpha = UNBIASEDNESS_ALPHA / m as f64;
    let skew_limit = t_test_skewness_limit(reps, per_test_alpha);
    // A deterministic estimator (no repetition of any integral differs: a noise-free quadrature)
    // is compared exactly: any value off an exact reference by more than its bound is a bias.
    let deterministic = reps >= 2 && cell.moments.iter().flatten().all(|m| m.std_err() == 0.0);
    for (i, mom) in cell.moments.iter().enumerate() {
        // The channels of one integral come from the same samples (often exactly proportional), so
        // their deviations are summed with the worst-case (fully correlated) standard error.
        let mut se_channels = 0.0;
        for (c, mc) in mom.iter().enumerate() {
            let (r, rse) = (reference.value[i][c], reference.std_err[i][c]);
            let se = mc.std_err();
            // An exact reference is only known to within its error bound, so a mean inside
            // [r - bound, r + bound] is no evidence of bias: the tests measure the distance from
            // that interval (the composite null; e.g. a zero-variance estimator whose estimates
            // differ from a closed form by rounding, or 0 for a radiance of 1e-38).
            let r_test = if stored_n.is_none() { mc.mean().clamp(r - exact_bound, r + exact_bound) } else { r };
            let se_total = (se * se + rse * rse).sqrt();
            dev += mc.mean() - r_test;
            se_channels += se_total;
            ref_sum += r.abs();
            if r != 0.0 {
                detect.push(detectable_shift(se_total, per_test_alpha, POWER) / r.abs());
            }
            let t = match stored_n {
                // Every repetition returned the same value within the reference's own error bound:
                // nothing to test, no evidence of bias.
                None if se == 0.0 && mc.mean() == r_test => {
                    estimators::stats::TestOutcome { statistic: 0.0, p_value: 1.0, dof: f64::INFINITY }
                }
                None if deterministic => {
                    estimators::stats::TestOutcome { statistic: f64::INFINITY, p_value: 0.0, dof: f64::INFINITY }
                }
                _ if se == 0.0 || mc.skewness().abs() > skew_limit + 2.0 * skewness_se(reps) => {
                    untested += 1;
                    continue;
                }
                None => one_sample_t(mc.mean(), se, reps, r_test),
                Some(n) => welch(mc.mean(), se, reps, r_test, rse, n),
            };
            max_t = max_t.max(t.statistic.abs());
            ps.push(t.p_value);
        }
        dev_var += se_channels * se_channels;
    }
    // Rare large values that none of the repetitions of an integral happened to draw leave no trace
    // in its own sample skewness (its mean and standard error are then both low, and t is large and
    // negative); across the cell's integrals they do show. When the mean skewness over the cell is
    // beyond the limit by more than twice its standard error, no per-integral t-test is valid.
    let skews: Vec<f64> = cell.moments.iter().flatten().map(|m| m.skewness()).filter(|g| g.is_finite()).collect();
    let cell_skew = skews.iter().sum::<f64>() / skews.len().max(1) as f64;
    if !skews.is_empty() && cell_skew.abs() > skew_limit + 2.0 * skewness_se(reps) / (skews.len() as f64).sqrt() {
        untested += ps.len();
        ps.clear();
    }
    let adjusted = holm_bonferroni(&ps);
    let min_p =
        if ps.is_empty() { f64::NAN } else { adjusted.iter().copied().filter(|p| !p.is_nan()).fold(1.0, f64::min) };
    detect.sort_by(f64::total_cmp);
    let median_detect = detect.get(detect.len() / 2).copied().unwrap_or(f64::NAN);
    let name = if stored_n.is_some() { "holm_welch" } else { "holm_t" };
    let mut holm = row(cell, claim, name, max_t, min_p, median_detect);
    holm.untested = untested;
    let mut out = vec![holm];
    if dev_var > 0.0 && ref_sum > 0.0 {
        let se = dev_var.sqrt();
        let z = z_test(dev, se, 0.0);
        out.push(row(
            cell,
            claim,
            "pooled_z",
            z.statistic,
            z.p_value,
            detectable_shift(se, UNBIASEDNESS_ALPHA, POWER) / ref_sum,
        ));
    }
    out
}

/// The papers' speed-up at the rightmost budget (paper 000 §5, 001 §5): samples the baseline needs
/// to reach the method's error (from the baseline's fitted slope) over the method's samples, divided
/// by the method's overhead (its time per estimate over the baseline's).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpeedUp {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// Baseline name.
    pub baseline: String,
    /// The rightmost budget.
    pub budget: u64,
    /// Baseline samples needed for the method's RMSE over the method's samples.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub sample_ratio: f64,
    /// Method seconds per estimate over the baseline's at the same budget.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub overhead: f64,
    /// sample_ratio / overhead.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub speedup: f64,
}

/// Speed-ups of every series against `baseline`.
pub fn speedups(rows: &[SummaryRow], fits: &[Fit], baseline: &str) -> Vec<SpeedUp> {
    let mut out = Vec::new();
    for series in group(rows) {
        let last = series[series.len() - 1];
        if last.estimator == baseline {
            continue;
        }
        let same = |r: &&SummaryRow| r.testbed == last.testbed && r.variant == last.variant && r.estimator == baseline;
        let (Some(fit), Some(base)) = (
            fits.iter().find(|f| f.testbed == last.testbed && f.variant == last.variant && f.estimator == baseline),
            rows.iter().filter(same).find(|r| r.budget == last.budget),
        ) else {
            continue;
        };
        if last.rmse <= 0.0 || fit.slope >= 0.0 {
            continue;
        }
        let needed = ((last.rmse.ln() - fit.intercept) / fit.slope).exp();
        let sample_ratio = needed / last.budget as f64;
        let overhead = last.seconds / base.seconds;
        out.push(SpeedUp {
            testbed: last.testbed.clone(),
            variant: last.variant.clone(),
            estimator: last.estimator.clone(),
            baseline: baseline.to_string(),
            budget: last.budget,
            sample_ratio,
            overhead,
            speedup: sample_ratio / overhead,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{CellKey, TimeStats};
    use crate::metrics::summarize;
    use estimators::budget::Budget;
    use estimators::math::Rgb;
    use estimators::stats::Moments;
    use estimators::task::Costs;

    fn cell(values: &[[f64; 3]], reps: usize) -> CellResult {
        // Integral i gets `reps` estimates v_i + k * 0.1 for k in -(reps/2)..
        let moments = values
            .iter()
            .map(|v| {
                let mut m = [Moments::default(), Moments::default(), Moments::default()];
                for k in 0..reps {
                    for c in 0..3 {
                        m[c].push(v[c] + 0.1 * (k as f64 - (reps as f64 - 1.0) / 2.0));
                    }
                }
                m
            })
            .collect();
        let key = CellKey {
            testbed: "t".into(),
            variant: "v".into(),
            testbed_params: "{}".into(),
            estimator: "e".into(),
            budget: Budget::samples(4).unwrap(),
            reps,
            seed: 1,
            version: "0".into(),
        };
        let mut time = TimeStats::default();
        time.push(1e-3);
        CellResult {
            key,
            moments,
            costs: Costs { samples: 4, ..Costs::default() },
            estimates: 1,
            time,
            diagnostics: vec![],
        }
    }

    fn exact(values: &[[f64; 3]]) -> Reference {
        Reference {
            kind: ReferenceKind::Exact { method: "test".into(), bound: 0.0 },
            value: values.iter().map(|v| Rgb(*v)).collect(),
            std_err: vec![Rgb::ZERO; values.len()],
        }
    }

    #[test]
    fn metrics_follow_their_definitions() {
        let c = cell(&[[1.0, 2.0, 3.0], [1.0, 1.0, 1.0]], 4);
        // Reference off by +0.5 in every channel: bias -0.5, MSE = 0.25 + population variance.
        let r = exact(&[[1.5, 2.5, 3.5], [1.5, 1.5, 1.5]]);
        let row = summarize(&c, &r);
        let pop_var = (0.15f64.powi(2) * 2.0 + 0.05f64.powi(2) * 2.0) / 4.0;
        assert!((row.bias + 0.5).abs() < 1e-12);
        assert!((row.mse - (0.25 + pop_var)).abs() < 1e-12, "{}", row.mse);
        assert!((row.variance - pop_var * 4.0 / 3.0).abs() < 1e-12);
        assert!((row.efficiency.unwrap() - 1.0 / (row.variance * 1e-3)).abs() < 1e-6);
        assert_eq!(row.fom, None);
    }

    #[test]
    fn stored_reference_variance_is_subtracted_and_welch_is_used() {
        let c = cell(&[[1.0, 1.0, 1.0]], 8);
        let mut r = exact(&[[1.0, 1.0, 1.0]]);
        r.kind = ReferenceKind::Stored { command: "x".into(), samples: 100 };
        r.std_err = vec![Rgb::splat(0.01)];
        let exact_row = summarize(&c, &exact(&[[1.0, 1.0, 1.0]]));
        let row = summarize(&c, &r);
        assert!((exact_row.mse - row.mse - 1e-4).abs() < 1e-12);
        let tests = unbiasedness(&c, &r, Bias::Unbiased);
        assert_eq!(tests[0].test, "holm_welch");
        assert_eq!(tests[0].verdict, "pass");
    }

    #[test]
    fn the_test_flags_a_shift_and_reports_its_power() {
        let c = cell(&[[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]], 16);
        let t = unbiasedness(&c, &exact(&[[3.0, 3.0, 3.0], [4.0, 4.0, 4.0]]), Bias::Biased);
        assert_eq!(t[0].verdict, "biased");
        assert!(t[0].agrees && t[0].p_value < 1e-6);
        // se = 0.1 * sqrt(340 / 15) / 4 = 0.119, so t = 2 / 0.119 = 16.8; the detectable shift
        // (z_{1 - alpha/(2m)} + z_0.8) se = 0.55 is 0.14-0.18 of the references 3 and 4.
        assert!(t[0].detectable_rel_bias > 0.1 && t[0].detectable_rel_bias < 0.2, "{}", t[0].detectable_rel_bias);
        let ok = unbiasedness(&c, &exact(&[[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]]), Bias::Unbiased);
        assert!(ok.iter().all(|t| t.verdict == "pass" && t.agrees));
    }

    /// A deterministic estimate that misses the reference has an infinite t statistic: the row
    /// still round-trips through summary.json (`mcbench plot` reads it back).
    #[test]
    fn zero_variance_rows_round_trip_through_json() {
        let mut c = cell(&[[1.0, 1.0, 1.0]], 8);
        let mut same = Moments::default();
        (0..8).for_each(|_| same.push(1.0));
        c.moments = vec![[same.clone(), same.clone(), same]];
        let t = &unbiasedness(&c, &exact(&[[3.0, 3.0, 3.0]]), Bias::Biased)[0];
        assert!(t.statistic.is_infinite() && t.p_value == 0.0 && t.verdict == "biased");
        let back: TestRow = serde_json::from_str(&serde_json::to_string(t).unwrap()).unwrap();
        assert!(back.statistic.is_nan() && back.p_value == 0.0 && back.verdict == "biased");
    }

    /// A rare-hit estimator (10 with probability 0.1, else 0; mean 1, skewness 2.7) over 200
    /// integrals of 16 repetitions: its per-integral t-tests are not run (many integrals see no
    /// hit), the pooled test passes it against the true mean and flags a 40% shifted reference (it detects ~19% with 80% power).
    #[test]
    fn skewed_cells_are_judged_by_the_pooled_test() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0x5ce3);
        let mut c = cell(&[[1.0, 1.0, 1.0]], 16);
        c.moments = (0..200)
            .map(|_| {
                let mut m = Moments::default();
                (0..16).for_each(|_| m.push(if rng.gen::<f64>() < 0.1 { 10.0 } else { 0.0 }));
                [m.clone(), m.clone(), m]
            })
            .collect();
        let truth = exact(&vec![[1.0; 3]; 200]);
        let t = unbiasedness(&c, &truth, Bias::Unbiased);
        assert_eq!((t[0].verdict.as_str(), t[0].untested), ("untested", 600), "{t:?}");
        assert_eq!(t[1].test, "pooled_z");
        assert!(t[1].verdict == "pass" && t[1].agrees, "{:?}", t[1]);
        let shifted = unbiasedness(&c, &exact(&vec![[1.4; 3]; 200]), Bias::Unbiased);
        assert_eq!(shifted[1].verdict, "biased", "{:?}", shifted[1]);
    }

    /// A zero-variance estimator whose estimates differ from an exact reference by rounding
    /// (inside the reference's error bound) passes; the same spread outside the bound is flagged.
    #[test]
    fn differences_inside_the_exact_bound_are_no_evidence_of_bias() {
        let mut c = cell(&[[0.5, 0.5, 0.5]], 8);
        for (k, m) in c.moments[0].iter_mut().enumerate() {
            *m = Moments::default();
            (0..8).for_each(|j| m.push(0.5 + 1e-16 * (1.0 + (j + k) as f64 % 2.0)));
        }
        let mut r = exact(&[[0.5, 0.5, 0.5]]);
        r.kind = ReferenceKind::Exact { method: "closed form".into(), bound: 1e-13 };
        assert!(unbiasedness(&c, &r, Bias::Unbiased).iter().all(|t| t.verdict == "pass"));
        r.kind = ReferenceKind::Exact { method: "closed form".into(), bound: 1e-17 };
        assert!(unbiasedness(&c, &r, Bias::Unbiased).iter().all(|t| t.verdict == "biased"));
    }

    #[test]
    fn speedup_uses_the_baseline_fit() {
        let mk = |est: &str, budget: u64, rmse: f64, seconds: f64| SummaryRow {
            testbed: "t".into(),
            variant: "v".into(),
            estimator: est.into(),
            budget_kind: "samples".into(),
            budget,
            reps: 2,
            integrals: 1,
            rmse,
            mse: rmse * rmse,
            variance: rmse * rmse,
            bias: 0.0,
            bias_se: 0.0,
            samples: budget as f64,
            fetches: 0.0,
            rays: 0.0,
            seconds,
            efficiency: None,
            fom: None,
            rel_rmse: 0.0,
            reference_var: 0.0,
            cheap_fetches: 0.0,
            seconds_median: seconds,
            efficiency_mse: None,
            p_err: 0.0,
            p_eff: None,
            estimator_id: String::new(),
            params: String::new(),
            testbed_params: String::new(),
        };
        let mut rows = Vec::new();
        for b in [4u64, 16, 64] {
            rows.push(mk("base", b, 1.0 / (b as f64).sqrt(), b as f64));
            rows.push(mk("fast", b, 1.0 / b as f64, 2.0 * b as f64));
        }
        let f = fits(&rows);
        let s = speedups(&rows, &f, "base");
        // At 64 spp the fast method's RMSE 1/64 needs 4096 baseline samples: 64x, overhead 2x.
        assert_eq!(s.len(), 1);
        assert!((s[0].sample_ratio - 64.0).abs() < 1e-6 && (s[0].overhead - 2.0).abs() < 1e-12);
        assert!((s[0].speedup - 32.0).abs() < 1e-6);
    }
}

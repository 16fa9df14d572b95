//! What a run concludes: convergence-slope fits (SPEC §5), unbiasedness tests (SPEC §6) and the
//! papers' speed-up computation (paper 000/001).

pub mod bias;

pub use bias::{unbiasedness, Gate, TestRow, DEFAULT_TOLERANCE};

use crate::metrics::SummaryRow;
use estimators::stats::log_log_fit;
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

/// The repetitions `R'` at which a detectable relative bias `d` measured at `reps` would reach
/// `tolerance`, when a share `est_share` of the tested variance comes from the estimates (the rest
/// from a stored reference, which more repetitions do not shrink): `d^2 (s R / R' + 1 - s) =
/// tolerance^2`. `None` when `d` already meets it, is unknown, or the reference alone is too noisy.
pub fn reps_for(d: f64, reps: usize, est_share: f64, tolerance: f64) -> Option<f64> {
    if !d.is_finite() || d <= tolerance {
        return None;
    }
    let s = est_share.clamp(0.0, 1.0);
    let room = tolerance * tolerance - (1.0 - s) * d * d;
    (room > 0.0).then(|| (reps as f64 * s * d * d / room - 1e-9).ceil().max(2.0))
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
    use super::bias::tests::{cell_from, exact};
    use super::*;
    use crate::metrics::summarize;
    use estimators::testbed::ReferenceKind;

    #[test]
    fn metrics_follow_their_definitions() {
        // Integral values v + k * 0.1 for k in -1.5..1.5, against a reference off by +0.5.
        let per_rep: Vec<Vec<[f64; 3]>> = (0..4)
            .map(|k| {
                let e = 0.1 * (k as f64 - 1.5);
                vec![[1.0 + e, 2.0 + e, 3.0 + e], [1.0 + e; 3]]
            })
            .collect();
        let r = exact(&[[1.5, 2.5, 3.5], [1.5, 1.5, 1.5]]);
        let row = summarize(&cell_from(&per_rep, &r), &r);
        let pop_var = (0.15f64.powi(2) * 2.0 + 0.05f64.powi(2) * 2.0) / 4.0;
        assert!((row.bias + 0.5).abs() < 1e-12);
        assert!((row.mse - (0.25 + pop_var)).abs() < 1e-12, "{}", row.mse);
        assert!((row.variance - pop_var * 4.0 / 3.0).abs() < 1e-12);
        assert_eq!(row.fom, None);
    }

    #[test]
    fn stored_reference_variance_is_subtracted_from_the_mse() {
        let per_rep: Vec<Vec<[f64; 3]>> = (0..8).map(|k| vec![[1.0 + 0.1 * (k as f64 - 3.5); 3]]).collect();
        let mut r = exact(&[[1.0, 1.0, 1.0]]);
        let exact_row = summarize(&cell_from(&per_rep, &r), &r);
        r.kind = ReferenceKind::Stored { command: "x".into(), samples: 100 };
        r.std_err = vec![estimators::math::Rgb::splat(0.01)];
        let row = summarize(&cell_from(&per_rep, &r), &r);
        assert!((exact_row.mse - row.mse - 1e-4).abs() < 1e-12);
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

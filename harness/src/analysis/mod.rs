//! What a run concludes: convergence-slope fits (book: slope-fits.md), unbiasedness tests (book: statistics.md) and the
//! papers' speed-up computation (paper 000/001).

pub mod bias;
pub mod claim_check;
pub mod claims;
mod direct;
mod holm;
pub mod metrics;
mod pooled;
pub mod rmse_band;
pub mod roundoff;
pub mod speedup;
pub mod spread;

pub use bias::{unbiasedness, unbiasedness_at, Gate, TestRow, DEFAULT_TOLERANCE, POOLED_SHARE};
pub use speedup::{speedups, SpeedUp, SpeedUpOutcome};
pub use spread::Spread;

use crate::analysis::metrics::SummaryRow;
use mcbench_core::stats::{log_log_fit, weighted_linear_fit, SlopeFit};
use serde::{Deserialize, Serialize};

/// Family-wise significance of the unbiasedness tests (book: statistics.md).
pub const UNBIASEDNESS_ALPHA: f64 = 1e-3;
/// Power at which the detectable bias is reported.
pub const POWER: f64 = 0.8;

/// How many of the largest budgets the right-end fit uses.
pub const RIGHT_END_BUDGETS: usize = 3;

/// A convergence-slope fit of log RMSE on log budget (book: slope-fits.md), over the whole range of budgets and
/// over its right end (the last [`RIGHT_END_BUDGETS`] budgets), where a method "reaches" its order.
///
/// Both fits are weighted least squares with delta-method variances ([`rmse_fit`]): each budget's
/// log RMSE carries its own variance, known from the spread of the per-repetition squared errors,
/// and is corrected for the bias of a logarithm of a noisy mean. `slope`, `slope_ci_low` and
/// `slope_ci_high` keep their meaning (the whole-range slope and its 95% interval) but come from this
/// fit since `summary.csv` has `mse_se`; before, they were ordinary least squares, whose interval
/// ignored the points' unequal noise and undercovered under heavy tails. Rows without `mse_se`
/// (files written before it, one repetition, or an error with no spread) are fitted by ordinary
/// least squares, and `method` says which. Formulas and measured coverage: `docs/src/slope-fits.md`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// Fitted slope over every budget (the order of convergence is -slope).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub slope: f64,
    /// 95% confidence interval of `slope`, low end.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub slope_ci_low: f64,
    /// 95% confidence interval of `slope`, high end.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub slope_ci_high: f64,
    /// Coefficient of determination (weighted, for a weighted fit).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub r2: f64,
    /// Intercept of the fit (log RMSE at budget 1).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub intercept: f64,
    /// Budgets used.
    pub budgets: Vec<u64>,
    /// Slope over the last [`RIGHT_END_BUDGETS`] budgets (the order the method reaches); NaN for a
    /// series with fewer budgets than that, and in files written before it.
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub slope_right: f64,
    /// 95% confidence interval of `slope_right`, low end.
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub slope_right_ci_low: f64,
    /// 95% confidence interval of `slope_right`, high end.
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub slope_right_ci_high: f64,
    /// Budgets of the right-end fit.
    #[serde(default)]
    pub budgets_right: Vec<u64>,
    /// `wls` (weighted least squares with delta-method variances) or `ols` (ordinary least squares,
    /// where the rows carry no usable `mse_se`); `none` for an exact series (no fit); empty in
    /// files written before it.
    #[serde(default)]
    pub method: String,
    /// `fitted`, or `exact`: every budget's RMSE at round-off ([`SummaryRow::at_roundoff`]), so
    /// there is no slope to fit (`slope` and its interval, `r2`, `intercept` and the right-end
    /// fit are NaN, `null` in summary.json). `fitted` in files written before it.
    #[serde(default)]
    pub outcome: SlopeOutcome,
}

/// What the convergence fit of a series found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SlopeOutcome {
    /// A slope fitted to the RMSEs.
    #[default]
    Fitted,
    /// Every budget's RMSE at round-off: the estimator is exact at every budget, and a slope
    /// fitted to rounding errors would describe the arithmetic, not the estimator.
    Exact,
}

impl Fit {
    /// The slope and its 95% interval over `range`.
    pub fn range(&self, range: SlopeRange) -> (f64, f64, f64) {
        match range {
            SlopeRange::Whole => (self.slope, self.slope_ci_low, self.slope_ci_high),
            SlopeRange::Right => (self.slope_right, self.slope_right_ci_low, self.slope_right_ci_high),
        }
    }

    /// The slope over `range` with its 95% interval as tables print it, or "exact at every
    /// budget" (`-` without a slope over that range).
    pub fn describe(&self, range: SlopeRange) -> String {
        let (slope, lo, hi) = self.range(range);
        match self.outcome {
            SlopeOutcome::Exact => "exact at every budget".into(),
            SlopeOutcome::Fitted if slope.is_finite() => format!("{slope:.3} [{lo:.3}, {hi:.3}]"),
            SlopeOutcome::Fitted => "-".into(),
        }
    }

    /// The budgets the fit over `range` used.
    pub fn budgets_of(&self, range: SlopeRange) -> &[u64] {
        match range {
            SlopeRange::Whole => &self.budgets,
            SlopeRange::Right => &self.budgets_right,
        }
    }
}

/// Which budgets a slope is fitted over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SlopeRange {
    /// Every budget of the series.
    #[default]
    Whole,
    /// The last [`RIGHT_END_BUDGETS`] budgets: the slope a method "reaches".
    Right,
}

impl SlopeRange {
    /// How result tables and notes name it.
    pub fn describe(self) -> &'static str {
        match self {
            SlopeRange::Whole => "whole-range",
            SlopeRange::Right => "right-end",
        }
    }
}

/// Fits log RMSE on log budget over `rows` (one series, budgets increasing), and says how.
///
/// With every row's MSE `m_k > 0` and its standard error `se_k` (`mse_se`) finite and `> 0`, by
/// weighted least squares with delta-method variances: the relative variance of the estimated MSE
/// is `rho_k = se_k^2 / m_k^2` (`Var(e) / (R m_k^2)` with `e` a repetition's mean squared error and
/// `R` the repetitions), so `log RMSE_k = log(m_k) / 2` has variance `rho_k / 4`, and since
/// `E[log m_hat] ≈ log m - rho / 2`, the point `log(m_k) / 2 + rho_k / 4` is unbiased to that order.
/// Weights are `4 / rho_k`; the interval is [`weighted_linear_fit`]'s (Student t with `R - 1` degrees
/// of freedom, widened by the residual chi-square per degree of freedom when the points scatter
/// more than their variances say). Otherwise by ordinary least squares of `log RMSE` ([`log_log_fit`]).
pub fn rmse_fit(rows: &[&SummaryRow]) -> Option<(SlopeFit, &'static str)> {
    let pts: Vec<&SummaryRow> = rows.iter().copied().filter(|r| r.rmse > 0.0).collect();
    let x: Vec<f64> = pts.iter().map(|r| (r.budget as f64).ln()).collect();
    let weighted = pts.iter().all(|r| r.mse > 0.0 && r.mse_se.is_finite() && r.mse_se > 0.0);
    if weighted && pts.iter().all(|r| r.budget > 0) {
        let rho: Vec<f64> = pts.iter().map(|r| (r.mse_se / r.mse).powi(2)).collect();
        let y: Vec<f64> = pts.iter().zip(&rho).map(|(r, rho)| 0.5 * r.mse.ln() + rho / 4.0).collect();
        let var: Vec<f64> = rho.iter().map(|rho| rho / 4.0).collect();
        let reps = pts.iter().map(|r| r.reps).min().unwrap_or(0);
        if let Ok(f) = weighted_linear_fit(&x, &y, &var, reps.saturating_sub(1) as f64) {
            return Some((f, "wls"));
        }
    }
    let b: Vec<f64> = pts.iter().map(|r| r.budget as f64).collect();
    let y: Vec<f64> = pts.iter().map(|r| r.rmse).collect();
    log_log_fit(&b, &y).ok().map(|f| (f, "ols"))
}

/// Fits every (test bed, variant, estimator) series of rows with at least 3 budgets with RMSE > 0,
/// over the whole range and over its right end ([`rmse_fit`]); a series of at least 3 budgets
/// whose every RMSE is round-off ([`SummaryRow::at_roundoff`]) is reported exact, without a slope.
pub fn fits(rows: &[SummaryRow]) -> Vec<Fit> {
    let mut out = Vec::new();
    for series in group(rows) {
        if series.len() >= 3 && series.iter().all(|r| r.at_roundoff()) {
            out.push(Fit {
                testbed: series[0].testbed.clone(),
                variant: series[0].variant.clone(),
                estimator: series[0].estimator.clone(),
                slope: f64::NAN,
                slope_ci_low: f64::NAN,
                slope_ci_high: f64::NAN,
                r2: f64::NAN,
                intercept: f64::NAN,
                budgets: series.iter().map(|r| r.budget).collect(),
                slope_right: f64::NAN,
                slope_right_ci_low: f64::NAN,
                slope_right_ci_high: f64::NAN,
                budgets_right: Vec::new(),
                method: "none".into(),
                outcome: SlopeOutcome::Exact,
            });
            continue;
        }
        let pts: Vec<&SummaryRow> = series.into_iter().filter(|r| r.rmse > 0.0).collect();
        let Some((f, method)) = rmse_fit(&pts) else { continue };
        let right = &pts[pts.len().saturating_sub(RIGHT_END_BUDGETS)..];
        let r = if right.len() == RIGHT_END_BUDGETS { rmse_fit(right).map(|(f, _)| f) } else { None };
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
            slope_right: r.as_ref().map_or(f64::NAN, |r| r.slope),
            slope_right_ci_low: r.as_ref().map_or(f64::NAN, |r| r.slope_ci_low),
            slope_right_ci_high: r.as_ref().map_or(f64::NAN, |r| r.slope_ci_high),
            budgets_right: if r.is_some() { right.iter().map(|r| r.budget).collect() } else { Vec::new() },
            method: method.to_string(),
            outcome: SlopeOutcome::Fitted,
        });
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

#[cfg(test)]
mod tests {
    use super::bias::tests::{cell_from, exact};
    use super::*;
    use crate::analysis::metrics::summarize;
    use mcbench_core::testbed::ReferenceKind;

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
        r.std_err = vec![mcbench_core::math::Rgb::splat(0.01)];
        let row = summarize(&cell_from(&per_rep, &r), &r);
        assert!((exact_row.mse - row.mse - 1e-4).abs() < 1e-12);
    }

    /// A series whose per-repetition mean squared errors are `(1 / n) chi2_d / d` (mean `1 / n`,
    /// so the true slope of RMSE is -1/2), summarised as the harness does (mean and its standard
    /// error over repetitions).
    fn synthetic_series(rng: &mut rand_pcg::Pcg64, reps: usize, d: usize) -> Vec<SummaryRow> {
        use rand::Rng;
        let normal = |rng: &mut rand_pcg::Pcg64| {
            let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        (1..=6)
            .map(|k| {
                let n = 4f64.powi(k);
                let mut m = mcbench_core::stats::Moments::new();
                for _ in 0..reps {
                    let chi2: f64 = (0..d).map(|_| normal(rng).powi(2)).sum();
                    m.push(chi2 / d as f64 / n);
                }
                let mut r = crate::output::plot::tests::row("x", n as u64, m.mean().sqrt(), 1.0);
                r.reps = reps;
                r.mse = m.mean();
                r.mse_se = (m.variance() / reps as f64).sqrt();
                r
            })
            .collect()
    }

    /// A series whose every RMSE is round-off is exact at every budget, not a slope fitted to
    /// rounding errors; with one budget above round-off, or without a bound (files written before
    /// it), it is fitted as before.
    #[test]
    fn a_series_at_round_off_is_exact_at_every_budget() {
        let series = |rmse: [f64; 4], bound: f64| -> Vec<SummaryRow> {
            (0..4u32)
                .map(|k| {
                    let mut r = crate::output::plot::tests::row("x", 4u64.pow(k + 1), rmse[k as usize], 1.0);
                    (r.rmse_roundoff, r.mse_se) = (bound, 0.1 * r.mse);
                    r
                })
                .collect()
        };
        // Rounding errors of longer sums grow with the budget: a slope near +1 if fitted.
        let roundoff = [6e-17, 7e-17, 5.6e-16, 2e-15];
        let f = &fits(&series(roundoff, 1e-14))[0];
        assert_eq!((f.outcome, f.method.as_str()), (SlopeOutcome::Exact, "none"), "{f:?}");
        assert!(f.slope.is_nan() && f.slope_ci_low.is_nan() && f.slope_right.is_nan(), "{f:?}");
        assert_eq!(f.budgets, vec![4, 16, 64, 256]);
        assert_eq!(f.describe(SlopeRange::Whole), "exact at every budget");
        // An RMSE of exactly zero everywhere: no fit at all before, exact now.
        let f = &fits(&series([0.0; 4], 1e-14))[0];
        assert_eq!(f.outcome, SlopeOutcome::Exact);
        // One budget above round-off: fitted.
        let f = &fits(&series([6e-17, 7e-17, 5.6e-16, 2e-13], 1e-14))[0];
        assert_eq!(f.outcome, SlopeOutcome::Fitted);
        assert!(f.slope.is_finite() && f.describe(SlopeRange::Whole).starts_with(&format!("{:.3}", f.slope)));
        let f = &fits(&series(roundoff, f64::NAN))[0];
        assert!(f.outcome == SlopeOutcome::Fitted && f.slope > 0.5, "{f:?}");
        // summary.json keeps the outcome; files written before it read as fitted.
        let text = serde_json::to_string(&fits(&series(roundoff, 1e-14))[0]).expect("serialises");
        assert!(text.contains("\"outcome\":\"exact\"") && text.contains("\"slope\":null"), "{text}");
        let old = text.replace(",\"outcome\":\"exact\"", "");
        assert_eq!(serde_json::from_str::<Fit>(&old).expect("reads").outcome, SlopeOutcome::Fitted);
    }

    #[test]
    fn weighted_fits_cover_the_true_slope_where_per_point_noise_differs() {
        use rand::SeedableRng;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(2024);
        let trials = 200;
        let (mut whole, mut right, mut sum) = (0, 0, 0.0);
        for _ in 0..trials {
            let rows = synthetic_series(&mut rng, 8, 2);
            let f = &fits(&rows)[0];
            assert_eq!(f.method, "wls");
            assert_eq!(f.budgets_right, vec![256, 1024, 4096]);
            whole += usize::from(f.slope_ci_low <= -0.5 && -0.5 <= f.slope_ci_high);
            right += usize::from(f.slope_right_ci_low <= -0.5 && -0.5 <= f.slope_right_ci_high);
            sum += f.slope;
        }
        let (whole, right) = (whole as f64 / trials as f64, right as f64 / trials as f64);
        assert!(whole >= 0.9 && right >= 0.9, "coverage whole {whole}, right end {right}");
        assert!((sum / trials as f64 + 0.5).abs() < 0.01, "mean slope {}", sum / trials as f64);
        // Without standard errors (files written before them) the fit is ordinary least squares.
        let mut rows = synthetic_series(&mut rng, 8, 2);
        rows.iter_mut().for_each(|r| r.mse_se = f64::NAN);
        let f = &fits(&rows)[0];
        assert_eq!(f.method, "ols");
        let x: Vec<f64> = rows.iter().map(|r| r.budget as f64).collect();
        let y: Vec<f64> = rows.iter().map(|r| r.rmse).collect();
        assert_eq!(f.slope, log_log_fit(&x, &y).unwrap().slope);
    }
}

//! The papers' speed-up (paper 000 §5, 001 §5) with its 95% interval, in both cost regimes
//! ([`crate::plan::cost_model`]), and as a function of the cost of a ray.

use super::{group, Fit, SlopeOutcome};
use crate::analysis::claims::bootstrap::{self, Bootstrap};
use crate::analysis::claims::Ratio;
use crate::analysis::metrics::SummaryRow;
use crate::output::query::Query;
use crate::plan::cost_model::{CostModel, RayCostCurve, Regime};
use serde::{Deserialize, Serialize};

use mcbench_core::stats::hypothesis::t_quantile;

/// The normal quantile of a two-sided 95% interval (the slope's interval width to a standard
/// error).
const Z95: f64 = 1.959_963_984_540_054;

/// The quantile of the speed-up's two-sided 95% interval: Student's t with one less degree of
/// freedom than the method's repetitions, since the errors' spreads are estimated from them.
fn quantile(reps: usize) -> f64 {
    t_quantile(0.975, reps as f64 - 1.0)
}

/// The papers' speed-up at the rightmost budget: samples the baseline needs to reach the method's
/// error (from the baseline's fitted slope) over the method's samples, divided by the method's
/// overhead (its seconds per estimate over the baseline's at that budget).
///
/// Its interval, in each cost regime, is a bootstrap over blocks of repetitions
/// ([`crate::analysis::claims::bootstrap`]) when both cells at that budget carry them: each resample
/// recomputes the method's error and CPU seconds and costs per estimate and the baseline's (paired
/// when the two were cut into the same blocks), moves the baseline's fitted error at this budget by
/// its own cell's resampled error (its point's noise, an upper bound for the fit's there), and
/// draws the baseline's slope from a normal with its fitted standard error; the interval is the
/// expanded percentile one of the log speed-up, widened by the heavy-tail allowance
/// ([`crate::analysis::claims::bootstrap::HEAVY_TAIL_ALLOWANCE`]). Without blocks it is a delta-method one on the log scale over the
/// noise of the two errors (each budget's `mse_se`) and of the baseline's slope, with a Student's t
/// quantile at one less degree of freedom than the method's repetitions, the seconds per estimate
/// taken as exact. `interval_method` says which. The overhead is reported in CPU time (`measured`),
/// on the wall clock (load-dependent, for comparison) and with counted operations priced by the
/// sweep's [`CostModel`] (`renderer`).
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
    /// Method CPU seconds per estimate over the baseline's at the same budget
    /// ([`SummaryRow::metric_seconds`]).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub overhead: f64,
    /// sample_ratio / overhead.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub speedup: f64,
    /// Method wall-clock seconds per estimate over the baseline's: what `overhead` was before CPU
    /// time, which depends on how loaded the machine was while each cell ran (NaN in files written
    /// before it).
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub overhead_wall: f64,
    /// sample_ratio / overhead_wall (NaN in files written before it).
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub speedup_wall: f64,
    /// Standard error of ln(`sample_ratio`) (delta method); NaN without `mse_se` (files written
    /// before it, or before this column).
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub log_se: f64,
    /// 95% interval of `speedup`, low end.
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub speedup_ci_low: f64,
    /// 95% interval of `speedup`, high end.
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub speedup_ci_high: f64,
    /// The overhead with counted operations priced by the cost model (`renderer` regime).
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub overhead_renderer: f64,
    /// sample_ratio / overhead_renderer.
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub speedup_renderer: f64,
    /// The speed-up as rays get costly: sample_ratio x baseline rays / method rays (NaN when the
    /// method traces none).
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub speedup_ray_limit: f64,
    /// The ray cost (ns, other costs as measured) at which the speed-up crosses 1: 0 when it is
    /// above 1 at every ray cost, NaN when it crosses at none.
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub break_even_ray_ns: f64,
    /// (method, baseline) CPU seconds per estimate at the budget.
    #[serde(default)]
    pub cpu_seconds: Option<(f64, f64)>,
    /// (method, baseline) rays per estimate at the budget.
    #[serde(default)]
    pub rays: Option<(f64, f64)>,
    /// Repetitions of the method's cell (what `log_se` was measured at).
    #[serde(default)]
    pub reps: usize,
    /// 95% interval of `speedup_renderer`, low end (NaN in files written before it).
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub speedup_renderer_ci_low: f64,
    /// 95% interval of `speedup_renderer`, high end (NaN in files written before it).
    #[serde(default = "crate::output::nan", deserialize_with = "crate::output::f64_or_nan")]
    pub speedup_renderer_ci_high: f64,
    /// How the intervals were made: "bootstrap over 16 blocks of repetitions, paired (expanded
    /// percentile, 2000 resamples)" or "delta method" (empty in files written before it: the delta method;
    /// `none` for an unbounded speed-up).
    #[serde(default)]
    pub interval_method: String,
    /// `measured`, or `unbounded`: the method's RMSE at the budget is round-off
    /// ([`SummaryRow::at_roundoff`]), so no baseline budget reaches it. The sample ratio, the
    /// speed-ups and their intervals are then infinite (`null` in summary.json), the overheads as
    /// measured. `measured` in files written before it.
    #[serde(default)]
    pub outcome: SpeedUpOutcome,
}

/// What a speed-up found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpeedUpOutcome {
    /// A finite speed-up from the baseline's fitted slope.
    #[default]
    Measured,
    /// The method is exact at the budget (its error is round-off): the baseline reaches its error at
    /// no budget, and a ratio to rounding errors would be a number about the arithmetic.
    Unbounded,
}

impl SpeedUp {
    /// The speed-up in `regime`.
    pub fn in_regime(&self, regime: Regime) -> f64 {
        match regime {
            Regime::Measured => self.speedup,
            Regime::Renderer => self.speedup_renderer,
        }
    }

    /// The 95% interval of the speed-up in `regime` with the method that made it, as a [`Ratio`]
    /// for the verdict rule of ratio claims.
    pub fn ratio(&self, regime: Regime) -> Ratio {
        let value = self.in_regime(regime);
        let (lo, hi) = match regime {
            Regime::Measured => (self.speedup_ci_low, self.speedup_ci_high),
            Regime::Renderer => (self.speedup_renderer_ci_low, self.speedup_renderer_ci_high),
        };
        if self.interval_method.starts_with("bootstrap") && lo.is_finite() && hi.is_finite() && lo > 0.0 {
            Ratio::with_bootstrap(value, self.reps, Bootstrap::from_interval(value, (lo, hi), &self.interval_method))
        } else {
            Ratio::delta(value, self.log_se, self.reps)
        }
    }

    /// The speed-up in `regime` as tables print it: `unbounded (exact)` for an exact method.
    pub fn describe(&self, regime: Regime) -> String {
        match self.outcome {
            SpeedUpOutcome::Unbounded => "unbounded (exact)".into(),
            SpeedUpOutcome::Measured => crate::output::report::sig(self.in_regime(regime), 4),
        }
    }

    /// The speed-up as a function of the cost of a ray (None in files written before it, and for
    /// an unbounded speed-up).
    pub fn curve(&self) -> Option<RayCostCurve> {
        if self.outcome == SpeedUpOutcome::Unbounded {
            return None;
        }
        let (t, r) = (self.cpu_seconds?, self.rays?);
        Some(RayCostCurve { sample_ratio: self.sample_ratio, method: (t.0, r.0), baseline: (t.1, r.1) })
    }
}

/// The variance of a log RMSE from a row's `mse_se` (delta method: d ln sqrt(m) = dm / 2m).
fn log_rmse_var(r: &SummaryRow) -> f64 {
    (r.mse_se / (2.0 * r.mse)).powi(2)
}

/// Speed-ups of every series against `baseline`, with unit costs from `model`.
pub fn speedups(rows: &[SummaryRow], fits: &[Fit], baseline: &str, model: &CostModel) -> Vec<SpeedUp> {
    let mut out = Vec::new();
    for series in group(rows) {
        let last = series[series.len() - 1];
        if last.estimator == baseline {
            continue;
        }
        let bed = (last.testbed.as_str(), last.variant.as_str());
        let (Some(fit), Some(base)) = (
            Query::new(fits).bed(bed).estimator(baseline).first(),
            Query::new(rows).bed(bed).estimator(baseline).at(last.budget).first(),
        ) else {
            continue;
        };
        if fit.outcome == SlopeOutcome::Exact {
            // An exact baseline: no method reaches its error sooner.
            continue;
        }
        if last.at_roundoff() {
            out.push(unbounded(last, base, baseline, model));
            continue;
        }
        if last.rmse <= 0.0 || fit.slope >= 0.0 {
            continue;
        }
        let needed = ((last.rmse.ln() - fit.intercept) / fit.slope).exp();
        let sample_ratio = needed / last.budget as f64;
        // ln needed = (ln rmse_m - a) / b: the method's error and the fitted baseline at this
        // budget (its own point's variance, an upper bound for the fit there) enter as 1/b, the
        // slope as ln(sample ratio) / b.
        let slope_var = ((fit.slope_ci_high - fit.slope_ci_low) / (2.0 * Z95)).powi(2);
        let log_se = ((log_rmse_var(last) + log_rmse_var(base)) / fit.slope.powi(2)
            + (sample_ratio.ln() / fit.slope).powi(2) * slope_var)
            .sqrt();
        let overhead = model.seconds(Regime::Measured, last) / model.seconds(Regime::Measured, base);
        let overhead_renderer = model.seconds(Regime::Renderer, last) / model.seconds(Regime::Renderer, base);
        let overhead_wall = last.seconds / base.seconds;
        let speedup = sample_ratio / overhead;
        let w = (quantile(last.reps) * log_se).exp();
        let speedup_renderer = sample_ratio / overhead_renderer;
        // The bootstrap: the baseline's fitted log error at this budget moves with its own
        // cell's resampled error, the slope by a normal draw with its standard error, and the
        // sample ratio pivots about this budget as in the delta method above.
        let fitted = fit.intercept + fit.slope * (last.budget as f64).ln();
        let slope_se = slope_var.sqrt();
        let boot = |regime: Regime| {
            let seed = bootstrap::seed_of(&format!(
                "speedup|{}|{}/{}|{}|{}@{}",
                regime.name(),
                last.testbed,
                last.variant,
                last.estimator,
                baseline,
                last.budget
            ));
            bootstrap::log_ratio(&last.rep_blocks, &base.rep_blocks, seed, |m, b, z| {
                let slope = fit.slope + if slope_se.is_finite() { slope_se * z } else { 0.0 };
                if slope >= 0.0 {
                    return None;
                }
                let f = fitted + 0.5 * (b.mse().ln() - base.mse.ln());
                let log_ratio = (0.5 * m.mse().ln() - f) / slope;
                Some(log_ratio - (m.seconds(regime, model) / b.seconds(regime, model)).ln())
            })
        };
        let (ci, ci_renderer, interval_method) = match (boot(Regime::Measured), boot(Regime::Renderer)) {
            (Some(m), Some(r)) => {
                ((m.log95.0.exp(), m.log95.1.exp()), (r.log95.0.exp(), r.log95.1.exp()), m.describe())
            }
            _ => ((speedup / w, speedup * w), (speedup_renderer / w, speedup_renderer * w), "delta method".into()),
        };
        let curve = RayCostCurve {
            sample_ratio,
            method: (last.metric_seconds(), last.rays),
            baseline: (base.metric_seconds(), base.rays),
        };
        out.push(SpeedUp {
            testbed: last.testbed.clone(),
            variant: last.variant.clone(),
            estimator: last.estimator.clone(),
            baseline: baseline.to_string(),
            budget: last.budget,
            sample_ratio,
            overhead,
            speedup,
            overhead_wall,
            speedup_wall: sample_ratio / overhead_wall,
            log_se,
            speedup_ci_low: ci.0,
            speedup_ci_high: ci.1,
            overhead_renderer,
            speedup_renderer,
            speedup_ray_limit: curve.limit(),
            break_even_ray_ns: curve.reaching(1.0).ns(),
            cpu_seconds: Some(curve.method.0).zip(Some(curve.baseline.0)),
            rays: Some((last.rays, base.rays)),
            reps: last.reps,
            speedup_renderer_ci_low: ci_renderer.0,
            speedup_renderer_ci_high: ci_renderer.1,
            interval_method,
            outcome: SpeedUpOutcome::Measured,
        });
    }
    out
}

/// The speed-up of a method whose error at its budget is round-off: unbounded, with the overheads
/// as measured.
fn unbounded(last: &SummaryRow, base: &SummaryRow, baseline: &str, model: &CostModel) -> SpeedUp {
    let inf = f64::INFINITY;
    SpeedUp {
        testbed: last.testbed.clone(),
        variant: last.variant.clone(),
        estimator: last.estimator.clone(),
        baseline: baseline.to_string(),
        budget: last.budget,
        sample_ratio: inf,
        overhead: model.seconds(Regime::Measured, last) / model.seconds(Regime::Measured, base),
        speedup: inf,
        overhead_wall: last.seconds / base.seconds,
        speedup_wall: inf,
        log_se: f64::NAN,
        speedup_ci_low: inf,
        speedup_ci_high: inf,
        overhead_renderer: model.seconds(Regime::Renderer, last) / model.seconds(Regime::Renderer, base),
        speedup_renderer: inf,
        speedup_ray_limit: inf,
        break_even_ray_ns: 0.0,
        cpu_seconds: Some((last.metric_seconds(), base.metric_seconds())),
        rays: Some((last.rays, base.rays)),
        reps: last.reps,
        speedup_renderer_ci_low: inf,
        speedup_renderer_ci_high: inf,
        interval_method: "none".into(),
        outcome: SpeedUpOutcome::Unbounded,
    }
}

#[cfg(test)]
#[path = "speedup_tests.rs"]
mod tests;

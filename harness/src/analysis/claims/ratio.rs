//! Ratio and ordering claims between two cells at one budget, judged on a 95% interval: "A has
//! lower error than B", "A's figure of merit is k times B's", "A ranks first".
//!
//! The interval is a bootstrap over blocks of repetitions ([`super::bootstrap`]) when both rows
//! carry their cell's repetition blocks ([`SummaryRow::rep_blocks`]): each resample recomputes
//! both cells' MSE, `Err`, CPU seconds and fetches per estimate, so the noise of costs enters as
//! that of errors, and cells cut into the same blocks (interleaved in one run) are resampled
//! jointly. Seeded from the claim, a rerun gives the same interval.
//!
//! Rows without blocks (cells stored before them, rows read back from `summary.csv`) fall back to
//! the delta method: each cell's MSE carries its standard error `mse_se` (the spread of the
//! per-repetition squared errors), so the log of a ratio of MSE-based metrics has the standard
//! error `sqrt((se_a / mse_a)^2 + (se_b / mse_b)^2)` for independent cells (halved for an RMSE
//! ratio; [`RatioMetric::PEff`] says what stands in for the error of `Err`), costs per estimate are
//! taken as exact, and the quantile is Student's t with one less degree of freedom than the
//! smaller cell's repetitions, since each `mse_se` is itself estimated from them.
//!
//! A cell whose error is round-off ([`SummaryRow::at_roundoff`]) makes the ratio zero or unbounded
//! rather than a number about rounding errors ([`ExactRatio`]); the claim is judged on that side.
//!
//! A claim holds when the interval clears its threshold, does not when it lies on the other side,
//! and is `inconclusive`, with the repetitions that would decide, when it straddles; its note says
//! which method made the interval.

use super::bootstrap::{self, Bootstrap, CellSample};
use super::exact_ratio::ExactRatio;
use crate::analysis::metrics::SummaryRow;
use crate::output::{Claim, RunReport};
use crate::plan::cost_model::Regime;
use crate::verdict::Verdict;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

use mcbench_core::stats::hypothesis::t_quantile;

/// The two-sided level of the intervals.
pub const LEVEL: f64 = 0.95;

/// The quantity a ratio claim compares.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RatioMetric {
    /// Root mean square error (paper 002's Err).
    #[default]
    Rmse,
    /// Mean square error.
    Mse,
    /// Figure of merit 1 / (MSE x fetches).
    Fom,
    /// Efficiency 1 / (MSE x CPU seconds).
    EfficiencyMse,
    /// Paper 003's perceptual efficiency `P-Eff = 1 / (T Err)`. The bootstrap resamples `Err`
    /// itself (each repetition's tvi-weighted error is in the blocks); the delta method uses the
    /// relative standard error of the MSE for that of `Err` (a tvi-weighted MSE: the two coincide
    /// where the weights are even, and the weighting of a bright image changes the spread little).
    PEff,
    /// Paper 003's perceptual error `Err` (mean over integrals of MSE / tvi), resampled like
    /// [`RatioMetric::PEff`]'s.
    PErr,
    /// RMSE of the display-clamped values ([`SummaryRow::rmse_display`]).
    RmseDisplay,
    /// Figure of merit on display-clamped values, 1 / (MSE_display x fetches).
    FomDisplay,
}

impl RatioMetric {
    /// The metric's name in notes.
    pub fn name(self) -> &'static str {
        match self {
            RatioMetric::Rmse => "RMSE",
            RatioMetric::Mse => "MSE",
            RatioMetric::Fom => "FoM",
            RatioMetric::EfficiencyMse => "efficiency 1/(MSE x CPU s)",
            RatioMetric::PEff => "P-Eff",
            RatioMetric::PErr => "Err",
            RatioMetric::RmseDisplay => "display RMSE",
            RatioMetric::FomDisplay => "display FoM",
        }
    }

    /// Its value in a row, when defined (finite and positive).
    pub(crate) fn value(self, r: &SummaryRow) -> Option<f64> {
        let v = match self {
            RatioMetric::Rmse => Some(r.rmse),
            RatioMetric::Mse => Some(r.mse),
            RatioMetric::Fom => r.fom,
            RatioMetric::EfficiencyMse => r.efficiency_mse,
            RatioMetric::PEff => r.p_eff,
            RatioMetric::PErr => Some(r.p_err),
            RatioMetric::RmseDisplay => r.rmse_display,
            RatioMetric::FomDisplay => r.fom_display,
        };
        v.filter(|v| v.is_finite() && *v > 0.0)
    }

    /// The log of the metric recomputed from a resample of a cell's blocks.
    fn log_of(self, s: &CellSample<'_>) -> Option<f64> {
        let v = match self {
            RatioMetric::Rmse => s.mse().sqrt(),
            RatioMetric::Mse => s.mse(),
            RatioMetric::Fom => 1.0 / (s.mse() * s.fetches()),
            RatioMetric::EfficiencyMse => 1.0 / (s.mse() * s.cpu_seconds()),
            RatioMetric::PEff => 1.0 / (s.cpu_seconds() * s.integrals() * s.p_err()),
            RatioMetric::PErr => s.p_err(),
            RatioMetric::RmseDisplay => s.mse_display().sqrt(),
            RatioMetric::FomDisplay => 1.0 / (s.mse_display() * s.fetches()),
        };
        (v.is_finite() && v > 0.0).then(|| v.ln())
    }

    /// The cost regime of a time-based metric (the CPU seconds it divides by).
    fn regime(self) -> Option<Regime> {
        matches!(self, RatioMetric::EfficiencyMse | RatioMetric::PEff).then_some(Regime::Measured)
    }

    /// Whether the metric is an error (it vanishes for an exact cell) rather than an inverse error
    /// (it is unbounded there).
    pub(crate) fn is_error(self) -> bool {
        matches!(self, RatioMetric::Rmse | RatioMetric::Mse | RatioMetric::PErr | RatioMetric::RmseDisplay)
    }

    /// The power of the MSE the metric scales with (an RMSE is its square root).
    fn mse_power(self) -> f64 {
        match self {
            RatioMetric::Rmse | RatioMetric::RmseDisplay => 0.5,
            _ => 1.0,
        }
    }
}

/// A ratio `a / b` of one metric between two cells, with the log-scale standard error and, when
/// the cells carry repetition blocks, its bootstrap distribution.
#[derive(Clone, Debug, PartialEq)]
pub struct Ratio {
    /// The ratio.
    pub value: f64,
    /// Standard error of its logarithm: the bootstrap's when there is one, else the delta
    /// method's (NaN without `mse_se` on both cells).
    pub log_se: f64,
    /// The smaller repetition count of the two cells.
    pub reps: usize,
    /// The bootstrap over repetition blocks that gives the interval (`None`: the delta method).
    pub bootstrap: Option<Arc<Bootstrap>>,
}

impl Ratio {
    /// Of `metric` between rows `a` and `b`: a bootstrap over their repetition blocks when both
    /// carry them ([`bootstrap::log_ratio`], seeded from the metric and the two cells), the delta
    /// method otherwise.
    pub fn of(metric: RatioMetric, a: &SummaryRow, b: &SummaryRow) -> Option<Ratio> {
        let value = metric.value(a)? / metric.value(b)?;
        let rel = |r: &SummaryRow| r.mse_se / r.mse;
        let log_se = metric.mse_power() * (rel(a).powi(2) + rel(b).powi(2)).sqrt();
        let seed = bootstrap::seed_of(&format!(
            "ratio|{}|{}/{}|{}@{}|{}@{}",
            metric.name(),
            a.testbed,
            a.variant,
            a.estimator,
            a.budget,
            b.estimator,
            b.budget
        ));
        let boot = bootstrap::log_ratio(&a.rep_blocks, &b.rep_blocks, seed, |x, y, _| {
            Some(metric.log_of(x)? - metric.log_of(y)?)
        });
        let reps = a.reps.min(b.reps);
        Some(match boot {
            Some(bs) => Ratio { value, log_se: bs.log_se(), reps, bootstrap: Some(Arc::new(bs)) },
            None => Ratio::delta(value, log_se, reps),
        })
    }

    /// A ratio whose interval is the delta method's: `value` times or over `exp(t log_se)`.
    pub fn delta(value: f64, log_se: f64, reps: usize) -> Ratio {
        Ratio { value, log_se, reps, bootstrap: None }
    }

    /// A ratio with a bootstrap interval already made (e.g. a speed-up's): `log95` is the 95%
    /// interval of its logarithm; other levels fall back to the normal approximation.
    pub fn with_bootstrap(value: f64, reps: usize, boot: Bootstrap) -> Ratio {
        Ratio { value, log_se: boot.log_se(), reps, bootstrap: Some(Arc::new(boot)) }
    }

    /// Which method made the interval, for notes: "bootstrap over 16 blocks of repetitions, paired
    /// (expanded percentile x1.25 for heavy tails, 2000 resamples)" or "delta method".
    pub fn method(&self) -> String {
        match &self.bootstrap {
            Some(b) => b.describe(),
            None => "delta method".into(),
        }
    }

    /// The quantile of a two-sided interval at `level`.
    fn quantile(&self, level: f64) -> f64 {
        t_quantile(0.5 + 0.5 * level, self.reps as f64 - 1.0)
    }

    /// The 95% interval.
    pub fn interval(&self) -> (f64, f64) {
        self.interval_at(LEVEL)
    }

    /// The interval at a two-sided `level` (e.g. a Bonferroni-adjusted one for a family): the
    /// bootstrap's at that level when there is one, else the delta method's.
    pub fn interval_at(&self, level: f64) -> (f64, f64) {
        if let Some(b) = &self.bootstrap {
            let ends = if level == LEVEL { Some(b.log95) } else { b.ratio_interval_at(level) };
            if let Some((lo, hi)) = ends {
                return (lo.exp(), hi.exp());
            }
        }
        let w = (self.quantile(level) * self.log_se).exp();
        (self.value / w, self.value * w)
    }

    /// `above`: whether the ratio lies above `threshold` (else below): `held`, `not held` or
    /// `inconclusive`, with the reason.
    pub fn verdict(&self, threshold: f64, above: bool) -> (Verdict, Option<bool>, String) {
        let (lo, hi) = self.interval();
        let side = if above { "above" } else { "below" };
        if !(lo.is_finite() && hi.is_finite()) {
            return (Verdict::Inconclusive, None, "no interval: the cells carry no error spread (mse_se)".into());
        }
        let (yes, no) = if above { (lo > threshold, hi < threshold) } else { (hi < threshold, lo > threshold) };
        if yes {
            (Verdict::Held, Some(true), format!("the 95% interval lies {side} {threshold}"))
        } else if no {
            (Verdict::NotHeld, Some(false), format!("the 95% interval lies on the other side of {threshold}"))
        } else {
            let z = t_quantile(0.5 + 0.5 * LEVEL, f64::INFINITY);
            let widen = if self.bootstrap.is_some() { super::bootstrap::HEAVY_TAIL_ALLOWANCE } else { 1.0 };
            let need =
                (self.reps as f64 * (z * widen * self.log_se / (self.value / threshold).ln().abs()).powi(2)).ceil();
            let more = if need.is_finite() {
                format!("about {need} repetitions would decide it")
            } else {
                "no repetition count decides it (the ratio sits at the threshold)".into()
            };
            (Verdict::Inconclusive, None, format!("the 95% interval straddles {threshold}; {more}"))
        }
    }
}

/// The row of `estimator` on `tb` at `budget`.
pub fn row<'a>(report: &'a RunReport, tb: (&str, &str), estimator: &str, budget: u64) -> Option<&'a SummaryRow> {
    report.query().bed(tb).estimator(estimator).at(budget).first()
}

/// What a ratio claim compares and how it is judged.
#[derive(Clone, Debug, PartialEq)]
pub struct RatioSpec<'a> {
    /// (test bed, variant).
    pub tb: (&'a str, &'a str),
    /// The numerator's estimator.
    pub estimator: &'a str,
    /// The denominator's estimator.
    pub baseline: &'a str,
    /// The budget both are compared at.
    pub budget: u64,
    /// The metric.
    pub metric: RatioMetric,
    /// The threshold the ratio is claimed to clear (1 for an ordering).
    pub threshold: f64,
    /// Claimed above the threshold (else below).
    pub above: bool,
    /// The paper's ratio, when it gives one.
    pub paper: Option<f64>,
}

/// A claim that `metric(estimator) / metric(baseline)` lies above (or below) `threshold` at
/// `budget`, judged on its 95% interval; `note` is appended to the generated one.
pub fn ratio_claim(report: &RunReport, spec: &RatioSpec<'_>, claim: &str, note: &str) -> Claim {
    let RatioSpec { tb, estimator, baseline, budget, metric, threshold, above, paper } = spec.clone();
    let base = Claim {
        testbed: format!("{}/{}", tb.0, tb.1),
        claim: claim.into(),
        paper_value: paper,
        pair: format!("{estimator} vs {baseline}"),
        regime: metric.regime().map_or(String::new(), |r| r.name().into()),
        ..Default::default()
    };
    let (Some(a), Some(b)) = (row(report, tb, estimator, budget), row(report, tb, baseline, budget)) else {
        return Claim {
            verdict: Some(Verdict::NotMeasured),
            note: format!("no {} cell for {estimator} or {baseline} at {budget}", metric.name()),
            ..base
        };
    };
    if let Some(exact) = ExactRatio::of(metric, a, b) {
        let (verdict, held, reason) = exact.verdict(threshold, above);
        return Claim {
            held,
            note: format!(
                "{} {estimator} / {baseline} at {budget} {}: {}; {note}",
                metric.name(),
                a.budget_kind,
                exact.describe()
            ),
            verdict: Some(verdict),
            reason,
            ..base
        };
    }
    let Some(r) = Ratio::of(metric, a, b) else {
        return Claim {
            verdict: Some(Verdict::NotMeasured),
            note: format!("{} not defined for {estimator} or {baseline} at {budget}", metric.name()),
            ..base
        };
    };
    let (verdict, held, reason) = r.verdict(threshold, above);
    let (lo, hi) = r.interval();
    Claim {
        our_value: Some(r.value),
        held,
        note: format!(
            "{} {estimator} / {baseline} at {budget} {}: {:.4} [{lo:.4}, {hi:.4}] ({} repetitions; {}); {note}",
            metric.name(),
            a.budget_kind,
            r.value,
            r.reps,
            r.method()
        ),
        verdict: Some(verdict),
        interval: Some([lo, hi]),
        reason,
        ..base
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(report: &mut RunReport, mse: (f64, f64), se: (f64, f64)) {
        let template = report.rows[0].clone();
        report.rows.clear();
        for (name, m, s) in [("a", mse.0, se.0), ("b", mse.1, se.1)] {
            let mut r = template.clone();
            (r.estimator, r.budget, r.mse, r.rmse, r.mse_se, r.reps) = (name.into(), 64, m, m.sqrt(), s, 16);
            r.fom = Some(1.0 / (m * 10.0));
            report.rows.push(r);
        }
    }

    fn spec(metric: RatioMetric, above: bool) -> RatioSpec<'static> {
        RatioSpec {
            tb: ("gradient-plane", "default"),
            estimator: "a",
            baseline: "b",
            budget: 64,
            metric,
            threshold: 1.0,
            above,
            paper: Some(2.0),
        }
    }

    #[test]
    fn ratios_are_judged_on_their_interval() {
        let mut report = crate::output::plot::tests::synthetic_report();
        // MSE 4 vs 1 with 5% relative errors: RMSE ratio 2, log SE 0.5 x sqrt(2) x 0.05.
        rows(&mut report, (4.0, 1.0), (0.2, 0.05));
        let c = ratio_claim(&report, &spec(RatioMetric::Rmse, true), "a has the larger error", "");
        assert_eq!((c.verdict, c.held, c.pair.as_str()), (Some(Verdict::Held), Some(true), "a vs b"), "{c:?}");
        let [lo, hi] = c.interval.expect("interval");
        let w = (t_quantile(0.975, 15.0) * 0.5 * 2f64.sqrt() * 0.05).exp();
        assert!((lo - 2.0 / w).abs() < 1e-12 && (hi - 2.0 * w).abs() < 1e-12);
        // The FoM ratio is the inverse MSE ratio: 1/4, below 1.
        let f = ratio_claim(&report, &spec(RatioMetric::Fom, false), "a has the lower FoM", "");
        assert_eq!((f.verdict, f.our_value), (Some(Verdict::Held), Some(0.25)), "{f:?}");
        assert_eq!(ratio_claim(&report, &spec(RatioMetric::Fom, true), "", "").verdict, Some(Verdict::NotHeld));
        // Noisy cells straddle 1: inconclusive, with the repetitions that would decide.
        rows(&mut report, (1.1, 1.0), (0.3, 0.3));
        let i = ratio_claim(&report, &spec(RatioMetric::Mse, true), "", "");
        assert_eq!((i.verdict, i.held), (Some(Verdict::Inconclusive), None), "{i:?}");
        assert!(i.reason.contains("repetitions would decide"), "{}", i.reason);
        // A missing cell is not measured.
        let mut s = spec(RatioMetric::Mse, true);
        s.budget = 4;
        assert_eq!(ratio_claim(&report, &s, "", "").verdict(), Verdict::NotMeasured);
    }
}

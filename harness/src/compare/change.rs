//! The statistics of one change from run A to run B: a 95% interval and a verdict.
//!
//! Ratio metrics (RMSE, the two efficiencies, FoM) are bootstrapped over the cells' repetition
//! blocks with the claims' machinery ([`crate::analysis::claims::bootstrap`]): every resample
//! recomputes both cells' MSE (or variance), CPU seconds and fetches per estimate, so the noise of
//! the costs enters as that of the errors. The two cells are resampled **jointly** (paired) when
//! the runs share their seed and repetitions, so that an unchanged part of the code draws the
//! same random numbers in both and its noise cancels; independently otherwise. Cells without
//! blocks fall back to the delta method on `mse_se`. Slopes compare as a difference of the two
//! fits, their standard errors taken from their 95% intervals and combined as independent.
//!
//! The verdict is an equivalence statement: [`ChangeVerdict::NoChange`] only when the whole
//! interval lies inside the margin (RMSE ratios within `[1 / (1 + m), 1 + m]`, efficiency and FoM
//! ratios within the square of that band, slope differences within `±m`); [`ChangeVerdict::Improved`] or [`ChangeVerdict::Regressed`] when the interval excludes no
//! change (1, or 0 for a difference) and does not lie inside the margin;
//! [`ChangeVerdict::Inconclusive`] otherwise.

use crate::analysis::claims::bootstrap::{self, CellSample};
use crate::analysis::metrics::{RowBlocks, SummaryRow};
use mcbench_core::stats::hypothesis::t_quantile;
use serde::{Deserialize, Serialize};

/// The default margin of "no change" for RMSE ratios: within ±5% (`[1/1.05, 1.05]`); efficiency
/// and FoM ratios, which scale as 1 / MSE, within its square ([`Metric::margin`]).
pub const DEFAULT_MARGIN: f64 = 0.05;
/// The default drift of CPU time between two runs of the same code that the timing rows allow
/// (a factor 1.25 on top of their band): measured on a 2-core machine under changing load, CPU
/// time per estimate moved by 10-15% between runs, which the bootstrap within a run cannot see.
pub const DEFAULT_TIME_MARGIN: f64 = 0.25;
/// The default margin of "no change" for convergence slopes: a difference within ±0.1.
pub const DEFAULT_SLOPE_MARGIN: f64 = 0.1;
/// The two-sided level of the intervals.
pub const LEVEL: f64 = 0.95;

/// What a change from A to B amounts to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChangeVerdict {
    /// B is better: the interval excludes no change and leaves the margin on the better side.
    Improved,
    /// B is worse: the interval excludes no change and leaves the margin on the worse side.
    Regressed,
    /// The interval lies inside the margin.
    NoChange,
    /// The interval straddles the margin and includes no change.
    Inconclusive,
}

impl ChangeVerdict {
    /// Every verdict, in the order the summaries count them.
    pub const ALL: [ChangeVerdict; 4] =
        [ChangeVerdict::Improved, ChangeVerdict::Regressed, ChangeVerdict::NoChange, ChangeVerdict::Inconclusive];

    /// The word of the verdict in files and on the console.
    pub fn word(self) -> &'static str {
        match self {
            ChangeVerdict::Improved => "improved",
            ChangeVerdict::Regressed => "regressed",
            ChangeVerdict::NoChange => "no change",
            ChangeVerdict::Inconclusive => "inconclusive",
        }
    }
}

/// The quantity a change row compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// RMSE at one budget (lower is better); the change is the ratio B / A.
    Rmse,
    /// Variance-based efficiency 1 / (variance x CPU seconds) (higher is better; timing).
    Efficiency,
    /// MSE-based efficiency 1 / (MSE x CPU seconds) (higher is better; timing).
    EfficiencyMse,
    /// Figure of merit 1 / (MSE x fetches) (higher is better).
    Fom,
    /// Convergence slope over every budget (more negative is better); the change is B - A.
    Slope,
    /// The unbiasedness verdict (`combined` test) at a budget; a row only where it changed.
    Unbiasedness,
}

impl Metric {
    /// The metric's name in files.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Rmse => "rmse",
            Metric::Efficiency => "efficiency",
            Metric::EfficiencyMse => "efficiency_mse",
            Metric::Fom => "fom",
            Metric::Slope => "slope",
            Metric::Unbiasedness => "unbiasedness",
        }
    }

    /// Whether a larger value is better.
    pub fn higher_is_better(self) -> bool {
        matches!(self, Metric::Efficiency | Metric::EfficiencyMse | Metric::Fom)
    }

    /// The margin of no change for this metric's ratio given the margin `m` of the RMSE: efficiencies
    /// and FoM scale as 1 / MSE, so an RMSE within `1 + m` is a merit within `(1 + m)^2`.
    pub fn margin(self, m: f64) -> f64 {
        match self {
            Metric::Efficiency | Metric::EfficiencyMse | Metric::Fom => (1.0 + m).powi(2) - 1.0,
            _ => m,
        }
    }

    /// Whether the metric divides by CPU time (its change depends on the machines and their load).
    pub fn timing(self) -> bool {
        matches!(self, Metric::Efficiency | Metric::EfficiencyMse)
    }
}

/// A change with its interval: the ratio B / A (or the difference B - A for slopes).
#[derive(Clone, Debug, PartialEq)]
pub struct Interval {
    /// The point estimate.
    pub change: f64,
    /// Low end of the 95% interval.
    pub lo: f64,
    /// High end of the 95% interval.
    pub hi: f64,
    /// Whether the two cells were resampled jointly.
    pub paired: bool,
    /// How the interval was made.
    pub method: String,
}

/// The verdict on a ratio interval `[lo, hi]` of B / A with margin `margin`.
pub fn decide_ratio(lo: f64, hi: f64, margin: f64, higher_is_better: bool) -> ChangeVerdict {
    if !(lo > 0.0 && hi.is_finite() && lo <= hi) {
        return ChangeVerdict::Inconclusive;
    }
    decide(lo.ln(), hi.ln(), (1.0 + margin).ln(), higher_is_better)
}

/// The verdict on a difference interval `[lo, hi]` of B - A with margin `margin`.
pub fn decide_difference(lo: f64, hi: f64, margin: f64, higher_is_better: bool) -> ChangeVerdict {
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return ChangeVerdict::Inconclusive;
    }
    decide(lo, hi, margin, higher_is_better)
}

/// The verdict on an interval of a signed change (0: none) with the band `±band`.
fn decide(lo: f64, hi: f64, band: f64, higher_is_better: bool) -> ChangeVerdict {
    let (better, worse) = if higher_is_better {
        (ChangeVerdict::Improved, ChangeVerdict::Regressed)
    } else {
        (ChangeVerdict::Regressed, ChangeVerdict::Improved)
    };
    if lo >= -band && hi <= band {
        ChangeVerdict::NoChange
    } else if lo > 0.0 {
        better
    } else if hi < 0.0 {
        worse
    } else {
        ChangeVerdict::Inconclusive
    }
}

/// One side's cell: its row and its repetition blocks, twice: with the offset that turns a
/// resample's squared errors into the row's MSE, and into the row's variance (the squared bias
/// held at the row's value).
#[derive(Clone, Debug)]
pub struct CellData {
    /// The summary row.
    pub row: SummaryRow,
    /// Blocks for the MSE.
    pub mse: RowBlocks,
    /// The same blocks for the variance.
    pub variance: RowBlocks,
}

/// The log of one cell's error-times-cost for `metric` (the log of the inverse of a merit, or of
/// the MSE): what a ratio B / A compares.
fn log_cost(metric: Metric, s: &CellSample<'_>) -> Option<f64> {
    let v = match metric {
        Metric::Rmse => 0.5 * s.mse().ln(),
        Metric::Efficiency | Metric::EfficiencyMse => (s.mse() * s.cpu_seconds()).ln(),
        Metric::Fom => (s.mse() * s.fetches()).ln(),
        Metric::Slope | Metric::Unbiasedness => return None,
    };
    v.is_finite().then_some(v)
}

/// The ratio B / A of `metric` between two cells with its 95% interval; `pair` when the runs
/// share seed and repetitions. `None` where the metric is not defined on both.
pub fn ratio(metric: Metric, a: &CellData, b: &CellData, pair: bool, seed: u64) -> Option<Interval> {
    let (ba, bb) = match metric {
        Metric::Efficiency => (&a.variance, &b.variance),
        _ => (&a.mse, &b.mse),
    };
    // A merit's ratio B / A is cost_A / cost_B; an RMSE's is rmse_B / rmse_A.
    let sign = if metric.higher_is_better() { -1.0 } else { 1.0 };
    let stat = |sa: &CellSample<'_>, sb: &CellSample<'_>, _z: f64| {
        Some(sign * (log_cost(metric, sb)? - log_cost(metric, sa)?))
    };
    if let Some(boot) = bootstrap::log_ratio_paired(ba, bb, seed, pair, stat) {
        return Some(Interval {
            change: boot.estimate.exp(),
            lo: boot.log95.0.exp(),
            hi: boot.log95.1.exp(),
            paired: boot.paired,
            method: boot.describe(),
        });
    }
    delta(metric, &a.row, &b.row)
}

/// The delta-method interval of a ratio from the rows alone (cells without usable blocks): each
/// MSE (or variance) carries `mse_se`, costs per estimate are taken as exact.
fn delta(metric: Metric, a: &SummaryRow, b: &SummaryRow) -> Option<Interval> {
    let err = |r: &SummaryRow| if metric == Metric::Efficiency { r.variance } else { r.mse };
    let cost = |r: &SummaryRow| match metric {
        Metric::Rmse => Some(1.0),
        Metric::Efficiency | Metric::EfficiencyMse => Some(r.metric_seconds()),
        Metric::Fom => Some(r.fetches),
        _ => None,
    };
    let (ea, eb, ca, cb) = (err(a), err(b), cost(a)?, cost(b)?);
    if !(ea > 0.0 && eb > 0.0 && ca > 0.0 && cb > 0.0 && a.mse_se.is_finite() && b.mse_se.is_finite()) {
        return None;
    }
    let power = if metric == Metric::Rmse { 0.5 } else { 1.0 };
    let sign = if metric.higher_is_better() { -1.0 } else { 1.0 };
    let log = sign * power * ((eb * cb).ln() - (ea * ca).ln());
    let se = power * ((a.mse_se / ea).powi(2) + (b.mse_se / eb).powi(2)).sqrt();
    let dof = (a.reps.min(b.reps) as f64 - 2.0).max(1.0);
    let q = t_quantile(0.5 + LEVEL / 2.0, dof);
    Some(Interval {
        change: log.exp(),
        lo: (log - q * se).exp(),
        hi: (log + q * se).exp(),
        paired: false,
        method: "delta method on mse_se (no repetition blocks; costs taken as exact)".into(),
    })
}

/// The difference B - A of two fitted slopes `(slope, ci_low, ci_high)` with its 95% interval:
/// each standard error from its 95% interval, combined as independent (conservative for runs
/// that share random numbers). Bit-identical fits of a paired comparison differ by exactly 0.
pub fn slope_difference(a: (f64, f64, f64), b: (f64, f64, f64), paired: bool) -> Option<Interval> {
    if ![a.0, a.1, a.2, b.0, b.1, b.2].iter().all(|v| v.is_finite()) {
        return None;
    }
    let d = b.0 - a.0;
    if paired && a == b {
        return Some(Interval { change: 0.0, lo: 0.0, hi: 0.0, paired, method: "identical fits".into() });
    }
    let z = t_quantile(0.5 + LEVEL / 2.0, f64::INFINITY);
    let se = |(_, lo, hi): (f64, f64, f64)| (hi - lo) / (2.0 * z);
    let half = z * (se(a).powi(2) + se(b).powi(2)).sqrt();
    Some(Interval {
        change: d,
        lo: d - half,
        hi: d + half,
        paired: false,
        method: "difference of the fitted slopes, standard errors from their 95% intervals".into(),
    })
}

#[cfg(test)]
#[path = "change_tests.rs"]
mod tests;

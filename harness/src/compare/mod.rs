//! Two runs compared (`mcbench compare A B`; book: compare.md): per (experiment, test bed,
//! variant, estimator, budget) present in both, the change from A to B in RMSE, the two
//! efficiencies, FoM and the convergence slope, each with a 95% interval and a typed verdict
//! ([`change`]), and a row for each unbiasedness verdict that changed. Runs of different test-bed
//! parameters or references are refused ([`fingerprint`]). [`mod@write`] writes `compare.csv`,
//! `compare.json` and `compare.html` and prints the summary; [`baseline`] keeps named copies of a
//! run's results to compare against. With `--two-sample EA EB`, [`two_sample`] tests estimator EA of
//! A against estimator EB of B without a reference (`two_sample.csv`, `two_sample_integrals.csv`).

pub mod baseline;
pub mod change;
pub mod command;
pub mod fingerprint;
pub mod html;
pub mod load;
pub mod two_sample;
pub mod two_sample_html;
pub mod two_sample_maps;
pub mod write;

use crate::error::{HarnessError, Result};
use change::{CellData, ChangeVerdict, Metric};
use load::{Experiment, Side};
use serde::{Deserialize, Serialize};

/// One row of `compare.csv` (book: contract.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Change {
    /// Experiment name.
    pub experiment: String,
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// Budget kind (`samples`, `fetches`, `micros`).
    pub budget_kind: String,
    /// Budget per estimate; empty for slopes (fitted over every budget).
    pub budget: Option<u64>,
    /// What is compared.
    pub metric: Metric,
    /// The metric in A (NaN for unbiasedness rows).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub a: f64,
    /// The metric in B.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub b: f64,
    /// B / A for ratio metrics, B - A for slopes (NaN for unbiasedness rows).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub change: f64,
    /// Low end of the 95% interval of `change`.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub change_lo: f64,
    /// High end of the 95% interval of `change`.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub change_hi: f64,
    /// The verdict.
    pub verdict: ChangeVerdict,
    /// Whether the two cells were resampled jointly (the runs share seed and repetitions).
    pub paired: bool,
    /// How the interval was made.
    pub method: String,
    /// The unbiasedness verdicts in A and B (unbiasedness rows only).
    pub a_verdict: String,
    /// See `a_verdict`.
    pub b_verdict: String,
    /// What the row depends on (CPU time, a missing interval).
    pub note: String,
}

/// Settings of a comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Margins {
    /// RMSE ratios within `[1 / (1 + ratio), 1 + ratio]` are no change (efficiency and FoM ratios
    /// within the square of that band).
    pub ratio: f64,
    /// Slope differences within `±slope` are no change.
    pub slope: f64,
    /// The drift of CPU time between two runs of the same code allowed on top of `ratio` for the
    /// rows that divide by CPU time: their band is widened by the factor `1 + time`.
    pub time: f64,
}

impl Default for Margins {
    fn default() -> Self {
        Margins {
            ratio: change::DEFAULT_MARGIN,
            slope: change::DEFAULT_SLOPE_MARGIN,
            time: change::DEFAULT_TIME_MARGIN,
        }
    }
}

impl Margins {
    /// The margin of no change of `metric`'s ratio ([`Metric::margin`], widened by the CPU-time
    /// drift [`Margins::time`] for the timing rows).
    pub fn of(&self, metric: Metric) -> f64 {
        let m = metric.margin(self.ratio);
        if metric.timing() {
            (1.0 + m) * (1.0 + self.time) - 1.0
        } else {
            m
        }
    }
}

/// A comparison of two runs (`compare.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// What A was named by, and its folder.
    pub a: String,
    /// A's folder.
    pub a_dir: String,
    /// What B was named by.
    pub b: String,
    /// B's folder.
    pub b_dir: String,
    /// The margin of no change for ratios.
    pub margin: f64,
    /// The margin of no change for slope differences.
    pub slope_margin: f64,
    /// The CPU-time drift the timing rows allow ([`Margins::time`]).
    pub time_margin: f64,
    /// Experiments compared.
    pub experiments: Vec<String>,
    /// Notes (experiments or cells in one run only, pairing, timing).
    pub notes: Vec<String>,
    /// The rows.
    pub changes: Vec<Change>,
    /// Two estimators against each other (`--two-sample`), when asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sample: Option<two_sample::TwoSample>,
}

impl Comparison {
    /// Rows per verdict, in [`ChangeVerdict::ALL`] order.
    pub fn counts(&self) -> Vec<(ChangeVerdict, usize)> {
        ChangeVerdict::ALL.iter().map(|&v| (v, self.changes.iter().filter(|c| c.verdict == v).count())).collect()
    }
}

/// Compares two sides read from disk, refusing experiments whose test beds differ.
pub fn compare(a: &Side, b: &Side, margins: Margins) -> Result<Comparison> {
    let common: Vec<&String> = a.experiments.keys().filter(|k| b.experiments.contains_key(*k)).collect();
    if common.is_empty() {
        return Err(HarnessError::bad_file(
            &b.dir,
            format!("shares no experiment with {} (A has {}; B has {})", a.dir.display(), names(a), names(b)),
        ));
    }
    let mut notes = Vec::new();
    for (side, other) in [(a, b), (b, a)] {
        for name in side.experiments.keys().filter(|k| !other.experiments.contains_key(*k)) {
            notes.push(format!("experiment {name} is only in {}", side.label));
        }
    }
    for name in &common {
        fingerprint::check(&a.experiments[*name], &b.experiments[*name])?;
    }
    let mut changes = Vec::new();
    for name in &common {
        changes.extend(experiment_changes(&a.experiments[*name], &b.experiments[*name], margins, &mut notes));
    }
    Ok(Comparison {
        a: a.label.clone(),
        a_dir: a.dir.display().to_string(),
        b: b.label.clone(),
        b_dir: b.dir.display().to_string(),
        margin: margins.ratio,
        slope_margin: margins.slope,
        time_margin: margins.time,
        experiments: common.into_iter().cloned().collect(),
        notes,
        changes,
        two_sample: None,
    })
}

fn names(s: &Side) -> String {
    s.experiments.keys().cloned().collect::<Vec<_>>().join(", ")
}

/// A row with the identification of `cell` filled in.
fn blank(experiment: &str, row: &crate::analysis::metrics::SummaryRow, metric: Metric) -> Change {
    Change {
        experiment: experiment.to_string(),
        testbed: row.testbed.clone(),
        variant: row.variant.clone(),
        estimator: row.estimator.clone(),
        budget_kind: row.budget_kind.clone(),
        budget: Some(row.budget),
        metric,
        a: f64::NAN,
        b: f64::NAN,
        change: f64::NAN,
        change_lo: f64::NAN,
        change_hi: f64::NAN,
        verdict: ChangeVerdict::Inconclusive,
        paired: false,
        method: String::new(),
        a_verdict: String::new(),
        b_verdict: String::new(),
        note: String::new(),
    }
}

/// The value of a ratio metric in a row.
fn value(metric: Metric, c: &CellData) -> Option<f64> {
    match metric {
        Metric::Rmse => Some(c.row.rmse),
        Metric::Efficiency => c.row.efficiency,
        Metric::EfficiencyMse => c.row.efficiency_mse,
        Metric::Fom => c.row.fom,
        _ => None,
    }
}

/// The note on a timing row.
pub const TIMING_NOTE: &str = "CPU time: depends on the machines and their load, compare runs of one machine";

/// Every change of one experiment present in both runs.
fn experiment_changes(a: &Experiment, b: &Experiment, m: Margins, notes: &mut Vec<String>) -> Vec<Change> {
    let name = &a.report.meta.experiment;
    let (ma, mb) = (&a.report.meta, &b.report.meta);
    let pair = ma.seed == mb.seed && ma.reps == mb.reps && ma.reproducible && mb.reproducible;
    notes.push(format!(
        "{name}: seeds {} and {}, {} and {} repetitions: {}",
        ma.seed,
        mb.seed,
        ma.reps,
        mb.reps,
        if pair { "paired (same random numbers for unchanged code)" } else { "unpaired (independent runs)" }
    ));
    let mut out = Vec::new();
    let mut only = 0usize;
    for row in &a.report.rows {
        let id = load::cell_id(row);
        let (Some(ca), Some(cb)) = (a.cells.get(&id), b.cells.get(&id)) else {
            only += 1;
            continue;
        };
        let seed = crate::analysis::claims::bootstrap::seed_of(&format!("compare {name} {id:?}"));
        for metric in [Metric::Rmse, Metric::EfficiencyMse, Metric::Efficiency, Metric::Fom] {
            let (Some(va), Some(vb)) = (value(metric, ca), value(metric, cb)) else { continue };
            if metric.timing() && !(ca.row.time_clock == "cpu" && cb.row.time_clock == "cpu") {
                continue;
            }
            let mut c = blank(name, row, metric);
            (c.a, c.b) = (va, vb);
            match change::ratio(metric, ca, cb, pair, seed) {
                Some(i) => {
                    (c.change, c.change_lo, c.change_hi, c.paired, c.method) =
                        (i.change, i.lo, i.hi, i.paired, i.method);
                    c.verdict = change::decide_ratio(i.lo, i.hi, m.of(metric), metric.higher_is_better());
                }
                None => c.note = "no interval: the metric is not defined on every resample".into(),
            }
            if metric.timing() {
                c.note = crate::output::report::join_present(&[c.note.as_str(), TIMING_NOTE]);
            }
            out.push(c);
        }
    }
    only += b.report.rows.iter().filter(|r| !a.cells.contains_key(&load::cell_id(r))).count();
    if only > 0 {
        notes.push(format!("{name}: {only} cells are in one run only and are not compared"));
    }
    out.extend(slope_changes(name, a, b, pair, m));
    out.extend(unbiasedness_changes(name, a, b));
    out
}

/// The slope rows of the series in both runs.
fn slope_changes(name: &str, a: &Experiment, b: &Experiment, pair: bool, m: Margins) -> Vec<Change> {
    let mut out = Vec::new();
    for fa in &a.report.fits {
        let Some(fb) = b
            .report
            .fits
            .iter()
            .find(|f| (&f.testbed, &f.variant, &f.estimator) == (&fa.testbed, &fa.variant, &fa.estimator))
        else {
            continue;
        };
        let Some(row) = a
            .report
            .rows
            .iter()
            .find(|r| (&r.testbed, &r.variant, &r.estimator) == (&fa.testbed, &fa.variant, &fa.estimator))
        else {
            continue;
        };
        let mut c = blank(name, row, Metric::Slope);
        c.budget = None;
        (c.a, c.b) = (fa.slope, fb.slope);
        let identical = pair && fa.budgets == fb.budgets;
        match change::slope_difference(
            (fa.slope, fa.slope_ci_low, fa.slope_ci_high),
            (fb.slope, fb.slope_ci_low, fb.slope_ci_high),
            identical,
        ) {
            Some(i) => {
                (c.change, c.change_lo, c.change_hi, c.paired, c.method) = (i.change, i.lo, i.hi, i.paired, i.method);
                c.verdict = change::decide_difference(i.lo, i.hi, m.slope, false);
            }
            None => c.note = "no fitted slope in both runs (exact, or too few budgets)".into(),
        }
        out.push(c);
    }
    out
}

/// A row per cell whose decisive unbiasedness verdict (`combined`) changed: `pass` to `biased` is a
/// regression, `biased` to `pass` an improvement, any other change inconclusive.
fn unbiasedness_changes(name: &str, a: &Experiment, b: &Experiment) -> Vec<Change> {
    let mut out = Vec::new();
    for ta in a.report.tests.iter().filter(|t| t.test == "combined") {
        let same = |t: &&crate::analysis::TestRow| {
            t.test == "combined"
                && (&t.testbed, &t.variant, &t.estimator, t.budget)
                    == (&ta.testbed, &ta.variant, &ta.estimator, ta.budget)
        };
        let Some(tb) = b.report.tests.iter().find(same) else { continue };
        if ta.verdict == tb.verdict {
            continue;
        }
        let Some(row) = a.report.rows.iter().find(|r| {
            (&r.testbed, &r.variant, &r.estimator, r.budget) == (&ta.testbed, &ta.variant, &ta.estimator, ta.budget)
        }) else {
            continue;
        };
        let mut c = blank(name, row, Metric::Unbiasedness);
        c.verdict = match (ta.verdict.as_str(), tb.verdict.as_str()) {
            ("pass", "biased") => ChangeVerdict::Regressed,
            ("biased", "pass") => ChangeVerdict::Improved,
            _ => ChangeVerdict::Inconclusive,
        };
        (c.a, c.b) = (ta.rel_bias, tb.rel_bias);
        (c.a_verdict, c.b_verdict) = (ta.verdict.clone(), tb.verdict.clone());
        c.method =
            "the unbiasedness tests' decisive verdict (`combined`); a and b are the measured relative biases".into();
        out.push(c);
    }
    out
}

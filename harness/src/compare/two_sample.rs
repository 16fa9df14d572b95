//! Two estimators against each other without a reference (`mcbench compare A B --two-sample EA EB`;
//! book: compare.md): for each (test bed, variant, budget) where estimator `EA` of run A and
//! estimator `EB` of run B both have repetitions, whether they estimate the same means.
//!
//! What is read is what every run stores per cell: per integral and channel the mean and variance
//! over the repetitions, and each repetition's sum over every integral and channel (its variance,
//! [`crate::run::cell::CellResult::rep_dev`]). Repetitions are independent, and the two estimators
//! draw from different streams, so per integral and channel a Welch test compares the two means
//! ([`mcbench_core::stats::two_sample::welch_test`]); the pooled test
//! ([`mcbench_core::stats::two_sample::pooled`]) combines the Welch test of the per-repetition sums
//! with Holm over the integrals. Integral-channels without spread on either side are not tested
//! (their p-value would be 0 or 1 by definition), unless their means differ (p = 0).
//!
//! Limits: the tests' tails at `ALPHA` assume near-normal means; unlike the unbiasedness tests
//! there is no skewness gate, so a heavy-tailed estimator's rare values can move a verdict.

use super::load::{CellMoments, Side};
use crate::error::Result;
use mcbench_core::error::ConfigError;
use mcbench_core::stats::detectable_shift_t;
use mcbench_core::stats::two_sample::{p_value_histogram, pooled, welch_test, SUM_SHARE};
use serde::{Deserialize, Serialize};

/// The level the pooled p-value is compared with.
pub const ALPHA: f64 = 1e-3;
/// `same` needs the test to detect this relative difference of the sums with 80% power.
pub const SAME_WITHIN: f64 = 0.01;
/// Bins of the p-value histogram.
pub const BINS: usize = 10;
/// The flag that asks for the test.
pub const FLAG: &str = "--two-sample";

/// The verdict of one row.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TwoSampleVerdict {
    /// No difference found, and a relative difference of [`SAME_WITHIN`] would have been found.
    Same,
    /// The pooled p-value is below [`ALPHA`].
    Differ,
    /// Neither.
    Inconclusive,
}

impl TwoSampleVerdict {
    /// The word written.
    pub fn word(self) -> &'static str {
        match self {
            TwoSampleVerdict::Same => "same",
            TwoSampleVerdict::Differ => "differ",
            TwoSampleVerdict::Inconclusive => "inconclusive",
        }
    }
}

/// One row of `two_sample.csv`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TwoSampleRow {
    /// Estimator of run A.
    pub estimator_a: String,
    /// Estimator of run B.
    pub estimator_b: String,
    /// Experiment of A's cell.
    pub experiment_a: String,
    /// Experiment of B's cell.
    pub experiment_b: String,
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Budget kind.
    pub budget_kind: String,
    /// Budget per estimate.
    pub budget: u64,
    /// Repetitions of A's cell.
    pub reps_a: u64,
    /// Repetitions of B's cell.
    pub reps_b: u64,
    /// Integrals (pixels, points) of the cell.
    pub integrals: usize,
    /// Integral-channels with a per-integral test.
    pub tested: usize,
    /// Welch t of the per-repetition sums over every integral and channel (A - B).
    pub statistic: f64,
    /// Its p-value.
    pub p_sum: f64,
    /// The smallest Holm-adjusted per-integral p-value.
    pub p_holm: f64,
    /// The pooled p-value (weighted Bonferroni of the two).
    pub pooled_p: f64,
    /// Difference of the sums over the mean of the sums of |mean| per integral-channel.
    pub rel_diff: f64,
    /// The relative difference of the sums the sum test finds with 80% power at its level.
    pub detectable_rel_diff: f64,
    /// The verdict.
    pub verdict: TwoSampleVerdict,
    /// Counts of the per-integral p-values in 10 equal bins of [0, 1] (flat when the two agree).
    pub p_histogram: Vec<u64>,
}

/// One per-integral test (`two_sample_integrals.csv`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IntegralTest {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Budget per estimate.
    pub budget: u64,
    /// Integral index.
    pub integral: usize,
    /// Pixel column, from A's `integrals.csv` (empty when the run wrote none).
    pub px: Option<usize>,
    /// Pixel row, the same.
    pub py: Option<usize>,
    /// Channel 0..3.
    pub channel: usize,
    /// Mean of A.
    pub mean_a: f64,
    /// Standard error of A's mean.
    pub se_a: f64,
    /// Mean of B.
    pub mean_b: f64,
    /// Standard error of B's mean.
    pub se_b: f64,
    /// Welch t (A - B).
    pub t: f64,
    /// Welch–Satterthwaite degrees of freedom.
    pub df: f64,
    /// Two-sided p-value (`NaN`: not tested).
    pub p: f64,
}

/// The test of two estimators over every shared (test bed, variant, budget).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TwoSample {
    /// Estimator of run A.
    pub estimator_a: String,
    /// Estimator of run B.
    pub estimator_b: String,
    /// One row per shared cell.
    pub rows: Vec<TwoSampleRow>,
    /// The per-integral tests of every row.
    pub integrals: Vec<IntegralTest>,
}

type Found<'a> = Vec<(&'a str, &'a super::load::CellId, &'a CellMoments)>;

/// The stored cells of `estimator` in `side`: its full name (with parameters), or its id when that
/// names one estimator of the side; an unknown or ambiguous name is refused, with the names there.
fn cells<'a>(side: &'a Side, estimator: &str) -> Result<Found<'a>> {
    let all: Found<'a> = side
        .experiments
        .iter()
        .flat_map(|(name, e)| e.moments.iter().map(move |(id, m)| (name.as_str(), id, m)))
        .collect();
    let mut names: Vec<&str> = all.iter().map(|(_, id, _)| id.2.as_str()).collect();
    names.sort();
    names.dedup();
    let id_of = |n: &str| n.split('[').next().unwrap_or(n).to_string();
    let by_id: Vec<&str> = names.iter().copied().filter(|n| id_of(n) == estimator).collect();
    let chosen = if names.contains(&estimator) {
        estimator
    } else if let [one] = by_id.as_slice() {
        one
    } else {
        let why = format!(
            "{} stored repetitions in {} ({}); its estimators: {}",
            if by_id.is_empty() { "has no" } else { "names more than one estimator with" },
            side.label,
            side.dir.display(),
            names.join(", ")
        );
        return Err(ConfigError::invalid(FLAG, estimator, why).into());
    };
    Ok(all.into_iter().filter(|(_, id, _)| id.2 == chosen).collect())
}

/// The test bed's parameters (every default filled in) of a cell: cells of one test bed and variant
/// under other parameters measure other integrals and are not paired.
fn params<'a>(side: &'a Side, experiment: &str, id: &super::load::CellId) -> Option<&'a str> {
    let rows = &side.experiments.get(experiment)?.report.rows;
    rows.iter().find(|r| &super::load::cell_id(r) == id).map(|r| r.testbed_params.as_str())
}

/// The two-sample test of `estimator_a` in `a` against `estimator_b` in `b`; an estimator with no
/// stored cell in its run, or no shared (test bed, variant, budget), is refused (naming the flag).
pub fn two_sample(a: &Side, b: &Side, estimator_a: &str, estimator_b: &str) -> Result<TwoSample> {
    let ca = cells(a, estimator_a)?;
    let cb = cells(b, estimator_b)?;
    let name = |c: &Found| c.first().map_or(String::new(), |(_, id, _)| id.2.clone());
    let (estimator_a, estimator_b) = (name(&ca), name(&cb));
    let (estimator_a, estimator_b) = (estimator_a.as_str(), estimator_b.as_str());
    let mut out = TwoSample {
        estimator_a: estimator_a.into(),
        estimator_b: estimator_b.into(),
        rows: Vec::new(),
        integrals: Vec::new(),
    };
    let mut pairs: Vec<_> = ca
        .iter()
        .flat_map(|x| cb.iter().map(move |y| (x, y)))
        .filter(|((xa, ia, ma), (xb, ib, mb))| {
            (&ia.0, &ia.1, &ia.3, ia.4) == (&ib.0, &ib.1, &ib.3, ib.4)
                && ma.per_integral.len() == mb.per_integral.len()
                && params(a, xa, ia) == params(b, xb, ib)
        })
        .collect();
    pairs.sort_by(|(x, y), (u, v)| (x.1, x.0, y.0).cmp(&(u.1, u.0, v.0)));
    let mut geometry = super::two_sample_maps::Geometry::default();
    for ((ea, id, ma), (eb, _, mb)) in pairs {
        let (row, mut tests) = test_cell(ma, mb);
        geometry.place(&a.experiments[*ea].dir, &id.0, &id.1, &mut tests)?;
        out.rows.push(TwoSampleRow {
            estimator_a: estimator_a.into(),
            estimator_b: estimator_b.into(),
            experiment_a: ea.to_string(),
            experiment_b: eb.to_string(),
            testbed: id.0.clone(),
            variant: id.1.clone(),
            budget_kind: id.3.clone(),
            budget: id.4,
            ..row
        });
        out.integrals.extend(tests.into_iter().map(|t| IntegralTest {
            testbed: id.0.clone(),
            variant: id.1.clone(),
            budget: id.4,
            ..t
        }));
    }
    if out.rows.is_empty() {
        let why = format!(
            "{estimator_a} (in {}) and {estimator_b} (in {}) share no (test bed, variant, budget) with the same test-bed parameters",
            a.label, b.label
        );
        return Err(ConfigError::invalid(FLAG, format!("{estimator_a} {estimator_b}"), why).into());
    }
    Ok(out)
}

/// The row (without its names) and the per-integral tests of one pair of cells.
pub fn test_cell(a: &CellMoments, b: &CellMoments) -> (TwoSampleRow, Vec<IntegralTest>) {
    let mut tests = Vec::new();
    let (mut diff, mut scale) = (0.0, 0.0);
    for (i, (pa, pb)) in a.per_integral.iter().zip(&b.per_integral).enumerate() {
        for c in 0..3 {
            let (x, y) = (&pa[c], &pb[c]);
            let (mx, my) = (x.mean(), y.mean());
            diff += mx - my;
            scale += 0.5 * (mx.abs() + my.abs());
            let w = welch_test(mx, x.variance(), x.count(), my, y.variance(), y.count());
            // Without spread on either side the p-value is 0 or 1 by definition: a difference is
            // kept (p = 0), an agreement is not a test.
            let flat = x.variance() == 0.0 && y.variance() == 0.0 && mx == my;
            let p = if flat { f64::NAN } else { w.p };
            tests.push(IntegralTest {
                testbed: String::new(),
                variant: String::new(),
                budget: 0,
                integral: i,
                px: None,
                py: None,
                channel: c,
                mean_a: mx,
                se_a: x.std_err(),
                mean_b: my,
                se_b: y.std_err(),
                t: w.t,
                df: w.df,
                p,
            });
        }
    }
    let (sa, sb) = (&a.rep_sum, &b.rep_sum);
    let sum = welch_test(diff, sa.variance(), sa.count(), 0.0, sb.variance(), sb.count());
    let ps: Vec<f64> = tests.iter().map(|t| t.p).collect();
    let pooled = pooled(&ps, Some(&sum));
    let se = (sa.variance() / sa.count() as f64 + sb.variance() / sb.count() as f64).sqrt();
    let detectable = detectable_shift_t(se, SUM_SHARE * ALPHA, 0.8, sum.df) / scale;
    let verdict = if pooled.p < ALPHA {
        TwoSampleVerdict::Differ
    } else if !pooled.p.is_nan() && detectable <= SAME_WITHIN {
        TwoSampleVerdict::Same
    } else {
        TwoSampleVerdict::Inconclusive
    };
    let row = TwoSampleRow {
        estimator_a: String::new(),
        estimator_b: String::new(),
        experiment_a: String::new(),
        experiment_b: String::new(),
        testbed: String::new(),
        variant: String::new(),
        budget_kind: String::new(),
        budget: 0,
        reps_a: sa.count(),
        reps_b: sb.count(),
        integrals: a.per_integral.len(),
        tested: pooled.tested,
        statistic: sum.t,
        p_sum: pooled.p_sum,
        p_holm: pooled.p_holm,
        pooled_p: pooled.p,
        rel_diff: diff / scale,
        detectable_rel_diff: detectable,
        verdict,
        p_histogram: p_value_histogram(&ps, BINS),
    };
    (row, tests)
}

/// `two_sample.csv`: the rows, the histogram as its counts separated by spaces.
pub fn csv_bytes(t: &TwoSample) -> std::result::Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "estimator_a",
        "estimator_b",
        "experiment_a",
        "experiment_b",
        "testbed",
        "variant",
        "budget_kind",
        "budget",
        "reps_a",
        "reps_b",
        "integrals",
        "tested",
        "statistic",
        "p_sum",
        "p_holm",
        "pooled_p",
        "rel_diff",
        "detectable_rel_diff",
        "verdict",
        "p_histogram",
    ])?;
    for r in &t.rows {
        let hist: Vec<String> = r.p_histogram.iter().map(u64::to_string).collect();
        let num = |x: f64| format!("{x:?}");
        w.write_record([
            r.estimator_a.clone(),
            r.estimator_b.clone(),
            r.experiment_a.clone(),
            r.experiment_b.clone(),
            r.testbed.clone(),
            r.variant.clone(),
            r.budget_kind.clone(),
            r.budget.to_string(),
            r.reps_a.to_string(),
            r.reps_b.to_string(),
            r.integrals.to_string(),
            r.tested.to_string(),
            num(r.statistic),
            num(r.p_sum),
            num(r.p_holm),
            num(r.pooled_p),
            num(r.rel_diff),
            num(r.detectable_rel_diff),
            r.verdict.word().to_string(),
            hist.join(" "),
        ])?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// `two_sample_integrals.csv`: every per-integral test.
pub fn integrals_csv_bytes(t: &TwoSample) -> std::result::Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in &t.integrals {
        w.serialize(r)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

#[cfg(test)]
#[path = "two_sample_tests.rs"]
mod tests;

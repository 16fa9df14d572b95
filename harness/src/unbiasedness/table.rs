//! The table of `unbiasedness`: one row per (estimator, test bed, variant) from the cell's SPEC §6
//! tests, judged against what the paper claims (registry [`Bias`]); `unbiasedness.csv`, the
//! per-row `paper` entries and the per-control claims of summary.json.

pub use super::stats::{combined, measured, pooled_over_sequences, reps_for_target, TARGET_REL_BIAS};
use crate::analysis::{unbiasedness, TestRow, UNBIASEDNESS_ALPHA};
use crate::cell::CellResult;
use crate::error::Result;
use crate::folder::OutputDir;
use crate::output::Claim;
use estimators::estimator::Bias;
use estimators::testbed::Reference;
use serde::Serialize;

/// One row of `unbiasedness.csv`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// Estimator name (id with parameters).
    pub estimator: String,
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// What the paper claims (registry): `unbiased`, `consistent`, `biased`.
    pub paper_bias: String,
    /// The deciding test (`holm_t`, `holm_welch`, `pooled_z`), empty when not run.
    pub test: String,
    /// Its p-value (Holm-adjusted minimum for the Holm tests); NaN when nothing was tested.
    pub p_value: f64,
    /// `pass`, `biased`, `untested` or `not-run`.
    pub verdict: String,
    /// Relative bias the deciding test detects with 80% power.
    pub detectable_rel_bias: f64,
    /// Repetitions run.
    pub reps: usize,
    /// Repetitions that would resolve a 0.1% relative bias given the measured variance; empty when
    /// the stored reference's own standard error alone exceeds that (no R suffices) or unknown.
    #[serde(rename = "reps_for_0.1pct")]
    pub reps_for_target: Option<f64>,
    /// Samples per estimate.
    pub budget: u64,
    /// Measured relative bias: sum over integrals and channels of (mean - reference) over the sum
    /// of |reference|.
    pub rel_bias: f64,
    /// Its standard error (channels taken as independent).
    pub rel_bias_se: f64,
    /// Whether the verdict agrees with what is expected here (empty: consistent, untested, not run).
    pub agrees: Option<bool>,
    /// How to read the row.
    pub note: String,
    /// For a biased control: why it is not required to be flagged here (its registry entry's
    /// exemption), if it is not.
    #[serde(skip)]
    pub exempt: Option<&'static str>,
}

/// Sets a test row's claim and whether its verdict agrees with it.
pub fn set_claim(t: &mut TestRow, bias: Bias) {
    t.claim = bias.name().into();
    t.agrees = match bias {
        Bias::Unbiased => t.verdict != "biased",
        Bias::Biased => t.verdict == "biased",
        Bias::Consistent => true,
    };
}

/// The SPEC §6 tests of one cell: the harness's, plus `pooled_z_seq` where integrals come in
/// sequences of `sequence > 1` (the independent-integral `pooled_z` stays in summary.json and in
/// the note but does not decide: [`combined`] prefers the sequence-aware tests).
pub fn tests_of(cell: &CellResult, reference: &Reference, bias: Bias, sequence: usize) -> Vec<TestRow> {
    let mut tests = unbiasedness(cell, reference, bias);
    if sequence > 1 {
        if let Some(mut t) = pooled_over_sequences(cell, reference, sequence) {
            set_claim(&mut t, bias);
            tests.push(t);
        }
    }
    tests
}

/// The row of one cell: its SPEC §6 tests (also returned, for summary.json) and the judgement.
pub fn row(
    cell: &CellResult,
    reference: &Reference,
    bias: Bias,
    sequence: usize,
    exempt: Option<&'static str>,
) -> (Row, Vec<TestRow>) {
    let tests = tests_of(cell, reference, bias, sequence);
    (row_from_tests(cell, reference, bias, &tests, exempt), tests)
}

/// The row of one cell from its tests (see [`tests_of`]; more may be added, e.g. `pooled_z_rep`).
pub fn row_from_tests(
    cell: &CellResult,
    reference: &Reference,
    bias: Bias,
    tests: &[TestRow],
    exempt: Option<&'static str>,
) -> Row {
    let (rel_bias, rel_bias_se, share) = measured(cell, reference);
    let k = &cell.key;
    let (test, p_value, detectable) = combined(tests);
    let verdict = if p_value.is_nan() {
        "untested"
    } else if p_value < UNBIASEDNESS_ALPHA {
        "biased"
    } else {
        "pass"
    };
    let mut r = Row {
        estimator: k.estimator.clone(),
        testbed: k.testbed.clone(),
        variant: k.variant.clone(),
        paper_bias: bias.name().into(),
        test,
        p_value,
        verdict: verdict.into(),
        detectable_rel_bias: detectable,
        reps: k.reps,
        reps_for_target: None,
        budget: k.budget.amount,
        rel_bias,
        rel_bias_se,
        agrees: None,
        note: String::new(),
        exempt,
    };
    r.reps_for_target = reps_for_target(r.detectable_rel_bias, r.reps, share);
    judge(&mut r);
    let shared = r.test.contains("pooled_z_seq") || r.test.contains("pooled_z_rep");
    if let (true, Some(z)) = (shared, tests.iter().find(|t| t.test == "pooled_z")) {
        r.note.push_str(&format!(
            "; pooled z taking integrals as independent (not valid under shared state): p = {:.2e}",
            z.p_value
        ));
    }
    r
}

fn pct(x: f64) -> String {
    format!("{}%", crate::report::sig(100.0 * x, 2))
}

/// Fills `agrees` and `note`: unbiased ids must pass, controls must be flagged (except where
/// the row's exemption says why they are not a control there), consistent ids are reported.
pub fn judge(r: &mut Row) {
    let measured = format!("measured relative bias {} ± {}", pct(r.rel_bias), pct(r.rel_bias_se));
    let p = if r.p_value.is_nan() { "-".to_string() } else { format!("{:.2e}", r.p_value) };
    let exempt = r.exempt;
    let weak = exempt.is_some_and(|w| w.starts_with("a weak control"));
    // Exempt controls are expected to pass (unbiased by construction there), weak ones either way.
    let expect = match (r.paper_bias.as_str(), exempt) {
        ("biased", None) => "biased",
        ("biased", Some(_)) if weak => "either",
        ("biased", Some(_)) => "unbiased",
        (claim, _) => claim,
    };
    let (agrees, mut note) = match (expect, r.verdict.as_str()) {
        (_, "not-run") => (None, r.note.clone()),
        (_, "untested") => {
            (None, "no valid test: every integral too skewed for a t-test and no pooled test".to_string())
        }
        ("consistent", "biased") => {
            (None, format!("flagged ({} p = {p}): reported as consistent only (SPEC §6); {measured}", r.test))
        }
        ("consistent", _) => (None, format!("no bias detected (consistent id); {measured}")),
        ("either", v) => (None, format!("{v} ({} p = {p}); {measured}", r.test)),
        ("biased", "biased") => (Some(true), format!("control flagged ({} p = {p}); {measured}", r.test)),
        ("biased", _) => (
            Some(false),
            format!("control NOT flagged ({} p = {p}); {measured}, detectable {}", r.test, pct(r.detectable_rel_bias)),
        ),
        (_, "biased") => (Some(false), format!("the claim of unbiasedness FAILS here: {} p = {p}; {measured}", r.test)),
        _ => (Some(true), format!("no bias detected; {measured}")),
    };
    if let Some(why) = exempt {
        note = format!("{why}; {note}");
    }
    if r.verdict != "not-run" && r.verdict != "untested" {
        let reach = if r.detectable_rel_bias <= TARGET_REL_BIAS {
            "0.1% resolved".to_string()
        } else {
            match r.reps_for_target {
                Some(n) => format!("0.1% not resolved: needs about {} reps", crate::report::sig(n, 2)),
                None => "0.1% not resolvable: the stored reference's own error is larger".to_string(),
            }
        };
        note = format!("{note}; {reach}");
    }
    r.agrees = agrees;
    r.note = note;
}

/// A row for a pair that was not run, with the reason.
pub fn not_run(
    estimator: &str,
    testbed: &str,
    variant: &str,
    bias: Bias,
    reason: &str,
    exempt: Option<&'static str>,
) -> Row {
    let mut r = Row {
        estimator: estimator.into(),
        testbed: testbed.into(),
        variant: variant.into(),
        paper_bias: bias.name().into(),
        test: String::new(),
        p_value: f64::NAN,
        verdict: "not-run".into(),
        detectable_rel_bias: f64::NAN,
        reps: 0,
        reps_for_target: None,
        budget: 0,
        rel_bias: f64::NAN,
        rel_bias_se: f64::NAN,
        agrees: None,
        note: format!("not run: {reason}"),
        exempt,
    };
    judge(&mut r);
    r
}

/// Writes `name` (`unbiasedness.csv`) into the results folder.
pub fn write_csv(dir: &OutputDir, name: &str, rows: &[Row]) -> Result<()> {
    let path = dir.join(name);
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r).map_err(|e| crate::error::HarnessError::write(&path, e))?;
    }
    let bytes = w.into_inner().map_err(|e| crate::error::HarnessError::write(&path, e))?;
    dir.write(name, &bytes).map(|_| ())
}

/// The `paper` entries: one per row (the paper's claim against the measured verdict), then one per
/// control id (flagged on every test bed where it is a control) and one over all unbiased ids.
pub fn claims(rows: &[Row]) -> Vec<Claim> {
    let mut out: Vec<Claim> = rows
        .iter()
        .map(|r| Claim {
            testbed: format!("{}/{}", r.testbed, r.variant),
            claim: format!("{} is {} (registry / paper)", r.estimator, r.paper_bias),
            paper_value: None,
            our_value: (!r.p_value.is_nan()).then_some(r.p_value),
            held: r.agrees,
            note: format!("{} {}: {}", r.test, r.verdict, r.note),
        })
        .collect();
    let mut controls: Vec<&str> = Vec::new();
    for r in rows.iter().filter(|r| r.paper_bias == "biased") {
        if !controls.contains(&r.estimator.as_str()) {
            controls.push(&r.estimator);
        }
    }
    for c in controls {
        let mine: Vec<&Row> =
            rows.iter().filter(|r| r.estimator == c && r.verdict != "not-run" && r.exempt.is_none()).collect();
        let missed: Vec<String> =
            mine.iter().filter(|r| r.agrees != Some(true)).map(|r| format!("{}/{}", r.testbed, r.variant)).collect();
        out.push(Claim {
            testbed: "all".into(),
            claim: format!(
                "harness (SPEC §6): the biased control {c} is flagged on every test bed where it is a control"
            ),
            paper_value: None,
            our_value: Some(mine.len() as f64 - missed.len() as f64),
            held: (!mine.is_empty()).then_some(missed.is_empty()),
            note: if missed.is_empty() {
                format!("flagged on all {} test beds (rows with an exemption reason excluded)", mine.len())
            } else {
                format!("NOT flagged (or untested) on: {}", missed.join(", "))
            },
        });
    }
    let unbiased: Vec<&Row> = rows.iter().filter(|r| r.paper_bias == "unbiased" && r.verdict != "not-run").collect();
    let failed: Vec<String> = unbiased
        .iter()
        .filter(|r| r.agrees == Some(false))
        .map(|r| format!("{} on {}/{}", r.estimator, r.testbed, r.variant))
        .collect();
    let untested = unbiased.iter().filter(|r| r.agrees.is_none()).count();
    out.push(Claim {
        testbed: "all".into(),
        claim: "papers: every estimator they call unbiased passes the SPEC §6 test on every test bed".into(),
        paper_value: None,
        our_value: Some((unbiased.len() - failed.len() - untested) as f64),
        held: Some(failed.is_empty()),
        note: format!(
            "{} rows, {} flagged{}, {untested} without a valid test",
            unbiased.len(),
            failed.len(),
            if failed.is_empty() { String::new() } else { format!(" ({})", failed.join("; ")) }
        ),
    });
    out
}

/// The table as markdown (report and README).
pub fn markdown(rows: &[Row]) -> String {
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let num = |x: f64| if x.is_nan() { "-".to_string() } else { crate::report::sig(x, 2) };
            vec![
                r.estimator.clone(),
                format!("{}/{}", r.testbed, r.variant),
                r.paper_bias.clone(),
                r.test.clone(),
                if r.p_value.is_nan() { "-".into() } else { format!("{:.1e}", r.p_value) },
                r.verdict.clone(),
                if r.detectable_rel_bias.is_nan() { "-".into() } else { pct(r.detectable_rel_bias) },
                r.reps.to_string(),
                r.reps_for_target.map_or("-".into(), num),
                match r.agrees {
                    Some(true) => "yes".into(),
                    Some(false) => "NO".into(),
                    None => "-".into(),
                },
                r.note.clone(),
            ]
        })
        .collect();
    let header = [
        "estimator",
        "test bed",
        "paper",
        "test",
        "p",
        "verdict",
        "detectable",
        "reps",
        "reps for 0.1%",
        "agrees",
        "note",
    ];
    crate::report::markdown_table(&header, &body)
}

#[cfg(test)]
#[path = "table_tests.rs"]
mod tests;

//! The table of `unbiasedness`: one row per (estimator, test bed, variant) from the cell's unbiasedness
//! tests, judged against what the paper claims (registry [`Bias`]); `unbiasedness.csv`, the
//! per-row `paper` entries and the per-control claims of summary.json.

pub use super::stats::{reps_for_target, TARGET_REL_BIAS};
use crate::analysis::{TestRow, UNBIASEDNESS_ALPHA};
use crate::error::Result;
use crate::output::Claim;
use crate::run::cell::CellResult;
use crate::store::folder::OutputDir;
use mcbench_core::estimator::Bias;
use mcbench_core::stats::holm_bonferroni_finite;
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
    /// The tests that ran (`holm_t` / `holm_welch`, `pooled_t`), empty when none did.
    pub test: String,
    /// Its p-value (Holm-adjusted minimum for the Holm tests); NaN when nothing was tested.
    pub p_value: f64,
    /// `pass`, `inconclusive`, `biased` or `not-run`.
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
    /// Whether the verdict agrees with what is expected here (empty: consistent, inconclusive for
    /// an unbiased id, not run).
    pub agrees: Option<bool>,
    /// How to read the row.
    pub note: String,
    /// The relative bias a `pass` must detect.
    pub tolerance: f64,
    /// Repetitions that would resolve the tolerance (and the skewness gate) when inconclusive.
    pub reps_for_tolerance: Option<f64>,
    /// Where the tests' gate came from (`pilot`, `previous budget`, `none`).
    pub gate: String,
    /// How the repetitions were spent: `fixed` (the part's repetitions) or `rounds` (doubling
    /// until decided, [`super::rounds`]; `reps` is then where the row stopped).
    pub repetitions: String,
    /// The looks at the row's data: 1 in the fixed mode, the rounds it ran in the rounds mode (0
    /// when not run).
    pub rounds: usize,
    /// The family-wise level each look decided at: 1e-3 in the fixed mode, its share of it per
    /// look in the rounds mode.
    pub decision_alpha: f64,
    /// For a biased control: why it is not required to be flagged here (its registry entry's
    /// exemption), if it is not.
    #[serde(skip)]
    pub exempt: Option<&'static str>,
}

/// The row of one cell from its unbiasedness tests ([`crate::analysis::unbiasedness`], the
/// `combined` row decides).
pub fn row_from_tests(cell: &CellResult, bias: Bias, tests: &[TestRow], exempt: Option<&'static str>) -> Row {
    let k = &cell.key;
    let decision = tests.iter().find(|t| t.test == "combined");
    let ran: Vec<&str> =
        tests.iter().filter(|t| t.test != "combined" && !t.p_value.is_nan()).map(|t| t.test.as_str()).collect();
    let (p_value, verdict, detectable) = decision
        .map_or((f64::NAN, "inconclusive", f64::NAN), |d| (d.p_value, d.verdict.as_str(), d.detectable_rel_bias));
    let mut r = Row {
        estimator: k.estimator.clone(),
        testbed: k.testbed.clone(),
        variant: k.variant.clone(),
        paper_bias: bias.name().into(),
        test: ran.join("+"),
        p_value,
        verdict: verdict.into(),
        detectable_rel_bias: detectable,
        reps: k.reps,
        reps_for_target: None,
        budget: k.budget.amount,
        rel_bias: decision.map_or(f64::NAN, |d| d.rel_bias),
        rel_bias_se: decision.map_or(f64::NAN, |d| d.rel_bias_se),
        agrees: None,
        note: decision.map_or(String::new(), |d| d.reason.clone()),
        tolerance: decision.map_or(f64::NAN, |d| d.tolerance),
        reps_for_tolerance: decision.and_then(|d| d.reps_needed),
        gate: decision.map_or("none".into(), |d| d.gate.clone()),
        repetitions: "fixed".into(),
        rounds: 1,
        decision_alpha: decision.map_or(UNBIASEDNESS_ALPHA, |d| d.alpha),
        exempt,
    };
    r.reps_for_target = reps_for_target(r.detectable_rel_bias, r.reps, 1.0);
    judge(&mut r);
    r
}

fn pct(x: f64) -> String {
    format!("{}%", crate::output::report::sig(100.0 * x, 2))
}

/// Fills `agrees` and `note`: unbiased ids must `pass` (an inconclusive row neither agrees nor
/// fails), controls must be flagged (except where the row's exemption says why they are not a
/// control there; not flagged, whether `pass` or `inconclusive`, is a miss), consistent ids are
/// reported.
pub fn judge(r: &mut Row) {
    let measured = if r.rel_bias.is_nan() {
        String::new()
    } else {
        format!("; measured relative bias {} ± {}", pct(r.rel_bias), pct(r.rel_bias_se))
    };
    let p = if r.p_value.is_nan() { "-".to_string() } else { format!("{:.2e}", r.p_value) };
    let weak = r.exempt.is_some_and(|w| w.starts_with("a weak control"));
    let expect = match (r.paper_bias.as_str(), r.exempt) {
        ("biased", None) => "biased",
        ("biased", Some(_)) if weak => "either",
        ("biased", Some(_)) => "unbiased",
        (claim, _) => claim,
    };
    let why = r.note.clone();
    let (agrees, mut note) = match (expect, r.verdict.as_str()) {
        (_, "not-run") => (None, why),
        ("consistent", "biased") => {
            (None, format!("flagged (p = {p}): reported as consistent only, not judged as unbiased{measured}"))
        }
        ("consistent", v) => (None, format!("{v} (consistent id): {why}{measured}")),
        ("either", v) => (None, format!("{v} (p = {p}): {why}{measured}")),
        ("biased", "biased") => (Some(true), format!("control flagged (p = {p}){measured}")),
        ("biased", v) => (Some(false), format!("control NOT flagged ({v}, p = {p}): {why}{measured}")),
        (_, "biased") => (Some(false), format!("the claim of unbiasedness FAILS here: p = {p}{measured}")),
        (_, "pass") => (Some(true), format!("{why}{measured}")),
        (_, _) => (None, format!("inconclusive: {why}{measured}")),
    };
    if let Some(why) = r.exempt {
        note = format!("{why}; {note}");
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
        tolerance: f64::NAN,
        reps_for_tolerance: None,
        gate: String::new(),
        repetitions: "fixed".into(),
        rounds: 0,
        decision_alpha: UNBIASEDNESS_ALPHA,
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
            p_value: (!r.p_value.is_nan()).then_some(r.p_value),
            held: r.agrees,
            note: format!("{} {}: {}", r.test, r.verdict, r.note),
            ..Default::default()
        })
        .collect();
    // Each control's claim is a conjunction of rejections, one per row at the row's own level:
    // no correction across rows is needed, since requiring every row to reject at alpha is
    // already stricter than any family-wise rule (a Holm or Bonferroni correction would lower
    // each row's level and only make a control harder to flag).
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
                "harness: the biased control {c} is flagged by the unbiasedness test (family-wise alpha 1e-3) on every test bed where it is a control"
            ),
            paper_value: None,
            our_value: Some(mine.len() as f64 - missed.len() as f64),
            held: (!mine.is_empty()).then_some(missed.is_empty()),
            note: if missed.is_empty() {
                format!(
                    "flagged on all {} test beds (rows with an exemption reason excluded; each row at its own alpha {UNBIASEDNESS_ALPHA}, no correction across rows: every row must reject)",
                    mine.len()
                )
            } else {
                format!(
                    "NOT flagged (inconclusive or passing, each row at its own alpha {UNBIASEDNESS_ALPHA}) on: {}",
                    missed.join(", ")
                )
            },
            ..Default::default()
        });
    }
    out.push(every_unbiased_passes(rows));
    out
}

/// The claim over all unbiased ids, judged family-wise: Holm over the rows with a finite p-value
/// at family-wise alpha [`UNBIASEDNESS_ALPHA`]. Each row's own verdict is at its own alpha, so over
/// some 330 correct rows at least one would be flagged in about a third of the seeds
/// (`1 - (1 - 1e-3)^330`); only a row whose p-value survives the correction fails the claim. A row
/// flagged alone but not after the correction is not a pass either: it leaves the claim open.
fn every_unbiased_passes(rows: &[Row]) -> Claim {
    let unbiased: Vec<&Row> = rows.iter().filter(|r| r.paper_bias == "unbiased" && r.verdict != "not-run").collect();
    let p: Vec<f64> = unbiased.iter().map(|r| r.p_value).collect();
    let adjusted = holm_bonferroni_finite(&p);
    let name = |r: &Row| format!("{} on {}/{}", r.estimator, r.testbed, r.variant);
    let per_row: Vec<&Row> = unbiased.iter().copied().filter(|r| r.agrees == Some(false)).collect();
    // A row flagged without a p-value cannot be corrected and fails as it stands.
    let failed: Vec<String> = unbiased
        .iter()
        .zip(&adjusted)
        .filter(|(r, a)| r.agrees == Some(false) && (r.p_value.is_nan() || **a <= UNBIASEDNESS_ALPHA))
        .map(|(r, a)| format!("{} (adjusted p {a:.2e})", name(r)))
        .collect();
    let passed = unbiased.iter().filter(|r| r.verdict == "pass").count();
    let inconclusive = unbiased.len() - passed - failed.len();
    let tested = p.iter().filter(|p| !p.is_nan()).count();
    let alone: Vec<String> = per_row.iter().map(|r| format!("{} (p {:.2e})", name(r), r.p_value)).collect();
    Claim {
        testbed: "all".into(),
        claim: "papers: every estimator they call unbiased passes the unbiasedness test on every test bed".into(),
        paper_value: None,
        our_value: Some(passed as f64),
        // Held only when every row passes; a row flagged family-wise fails it; inconclusive rows
        // (and rows flagged alone but not family-wise) leave it open.
        held: if !failed.is_empty() {
            Some(false)
        } else if inconclusive == 0 {
            Some(true)
        } else {
            None
        },
        note: format!(
            "{} rows: {passed} pass, {} flagged after Holm-Bonferroni over the {tested} rows with a p-value (family-wise alpha {UNBIASEDNESS_ALPHA}){}, {inconclusive} not resolved (inconclusive: cannot detect the tolerance yet, or flagged alone but not family-wise; see each row). Each row's own test at alpha {UNBIASEDNESS_ALPHA} flags {}{}, where {} would be flagged by chance",
            unbiased.len(),
            failed.len(),
            if failed.is_empty() { String::new() } else { format!(" ({})", failed.join("; ")) },
            per_row.len(),
            if alone.is_empty() { String::new() } else { format!(" ({})", alone.join("; ")) },
            crate::output::report::sig(tested as f64 * UNBIASEDNESS_ALPHA, 2),
        ),
        ..Default::default()
    }
}

/// The table as markdown (report and docs/src/unbiasedness.md).
pub fn markdown(rows: &[Row]) -> String {
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let num = |x: f64| if x.is_nan() { "-".to_string() } else { crate::output::report::sig(x, 2) };
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
    crate::output::report::markdown_table(&header, &body)
}

#[cfg(test)]
#[path = "table_tests.rs"]
mod tests;

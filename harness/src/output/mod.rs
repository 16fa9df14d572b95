//! Result files (a contract, book: contract.md and outputs.md): `summary.csv` and `summary.json` (`integrals.csv` is
//! [`crate::output::integrals`]'s); every write is atomic (temp file + rename) so an interrupted run never
//! leaves a half-written file.

pub mod console;
pub mod html;
pub mod integrals;
pub mod listing;
pub mod plot;
pub mod query;
pub mod report;

use crate::analysis::metrics::SummaryRow;
use crate::analysis::{Fit, SpeedUp, TestRow};
use crate::error::{HarnessError, Result};
use crate::plan::Skipped;
use crate::store::folder::OutputDir;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

pub use crate::verdict::Verdict;

/// Writes `bytes` to `path` atomically (a temp file in the same folder, then a rename). The temp
/// file is created new: whatever is in its place (a symbolic link included) is removed first,
/// never written through.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let create = || std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp);
    let result = (|| -> std::io::Result<()> {
        let mut f = match create() {
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                std::fs::remove_file(&tmp)?;
                create()?
            }
            r => r?,
        };
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        HarnessError::write(path, e)
    })
}

/// Run metadata (`meta` in summary.json).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    /// Experiment name.
    pub experiment: String,
    /// Seed.
    pub seed: u64,
    /// Git commit of the source (or `unknown`).
    pub git_commit: String,
    /// Worker threads.
    pub threads: usize,
    /// CPU model.
    pub cpu: String,
    /// Harness version.
    pub version: String,
    /// `quick` or `full`.
    pub mode: String,
    /// Repetitions.
    pub reps: usize,
    /// Wall-clock seconds of the whole run (timing).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub wall_seconds: f64,
    /// Free-form notes (noise corrections applied, references used, ...).
    pub notes: Vec<String>,
    /// This run's id, also in the folder's `commit.json` (empty in files written before it).
    #[serde(default)]
    pub run_id: String,
    /// Whether the same seed reproduces these results bit for bit (false when a time budget was
    /// calibrated on this machine).
    #[serde(default = "yes")]
    pub reproducible: bool,
    /// Unit costs of the `renderer` cost regime the speed-ups were priced with (the defaults in
    /// files written before it).
    #[serde(default)]
    pub cost_model: crate::plan::cost_model::CostModel,
}

fn yes() -> bool {
    true
}

/// A paper claim beside our measurement (`paper` in summary.json).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Claim {
    /// Test bed the claim was checked on.
    pub testbed: String,
    /// The claim in words, with where the paper makes it.
    pub claim: String,
    /// The paper's number.
    pub paper_value: Option<f64>,
    /// Our number.
    pub our_value: Option<f64>,
    /// Whether it held here (`None`: not measured in this run, or inconclusive; `verdict` says
    /// which).
    pub held: Option<bool>,
    /// How it was judged, or why it was not.
    pub note: String,
    /// The verdict, when the claim states one (written `held`, `not held`, `inconclusive`,
    /// `reported` or `not measured`); `None` (the empty word) where `held` is the verdict
    /// ([`Claim::verdict`]), as in files written before it. Any other word is refused on reading.
    #[serde(default, with = "crate::verdict::word")]
    pub verdict: Option<Verdict>,
    /// 95% interval of `our_value`, for claims judged on an interval.
    #[serde(default)]
    pub interval: Option<[f64; 2]>,
    /// The compared pair (`method vs baseline`) of a ratio claim.
    #[serde(default)]
    pub pair: String,
    /// The cost regime (`measured` or `renderer`, [`crate::plan::cost_model::Regime`]) of a time-based
    /// claim.
    #[serde(default)]
    pub regime: String,
    /// Why the verdict is what it is, in one sentence (for an inconclusive claim: what would
    /// resolve it).
    #[serde(default)]
    pub reason: String,
    /// The p-value the verdict rests on, for a claim judged by a test (the largest p-value of a
    /// control's rows, which `our_value` holds too); shown in a column of its own by the HTML page.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p_value: Option<f64>,
}

impl Claim {
    /// The verdict: `verdict` when set, else read from `held` (with no `held`: `reported` when
    /// there is a value, `not measured` when there is none).
    pub fn verdict(&self) -> Verdict {
        if let Some(v) = self.verdict {
            return v;
        }
        match (self.held, self.our_value) {
            (Some(true), _) => Verdict::Held,
            (Some(false), _) => Verdict::NotHeld,
            (None, Some(_)) => Verdict::Reported,
            (None, None) => Verdict::NotMeasured,
        }
    }
}

/// Everything `summary.json` holds, plus the rows of `summary.csv` (for plots and reports).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunReport {
    /// Run metadata.
    pub meta: Meta,
    /// Convergence fits.
    pub fits: Vec<Fit>,
    /// Statistical tests.
    pub tests: Vec<TestRow>,
    /// Paper claims beside our numbers.
    pub paper: Vec<Claim>,
    /// Speed-ups against the baseline.
    pub speedups: Vec<SpeedUp>,
    /// Pairs that did not run, with the reason.
    pub skipped: Vec<Skipped>,
    /// Estimator ids the experiment names that are not registered yet.
    pub unavailable: Vec<String>,
    /// Summary rows (also in summary.csv; not repeated in summary.json).
    #[serde(skip)]
    pub rows: Vec<SummaryRow>,
    /// Paper label per estimator name (legend text).
    pub labels: Vec<(String, String)>,
    /// Mean per estimate of each diagnostic an estimator noted (cache bytes, cells, ESS, ...).
    #[serde(default)]
    pub diagnostics: Vec<Diagnostic>,
    /// Per cell, the target evaluations and cache operations per estimate (the `target_evals` and
    /// `cache_ops` columns of summary.csv; empty in files written before they were counted).
    #[serde(default)]
    pub counts: Vec<CellCounts>,
    /// Per (test bed, variant), its parameters and a digest of its reference, so that runs can be
    /// compared only on the same integrals (empty in files written before it).
    #[serde(default)]
    pub beds: Vec<crate::compare::fingerprint::BedPrint>,
}

/// The adaptive methods' counted operations of one cell, per estimate
/// ([`mcbench_core::task::Costs::target_evals`], [`mcbench_core::task::Costs::cache_ops`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellCounts {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// Budget.
    pub budget: u64,
    /// Target-density evaluations per estimate.
    pub target_evals: f64,
    /// Radiance-cache operations per estimate.
    pub cache_ops: f64,
}

impl From<&SummaryRow> for CellCounts {
    fn from(r: &SummaryRow) -> Self {
        CellCounts {
            testbed: r.testbed.clone(),
            variant: r.variant.clone(),
            estimator: r.estimator.clone(),
            budget: r.budget,
            target_evals: r.target_evals,
            cache_ops: r.cache_ops,
        }
    }
}

/// The mean of one estimator diagnostic over a cell's estimates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Diagnostic {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// Budget.
    pub budget: u64,
    /// Diagnostic name.
    pub name: String,
    /// Mean per estimate.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub mean: f64,
}

impl Diagnostic {
    /// The means per estimate of a cell's diagnostics (summary.json `diagnostics`).
    pub fn of_cell(cell: &crate::run::cell::CellResult) -> impl Iterator<Item = Diagnostic> + '_ {
        cell.diagnostics.iter().map(move |(name, sum)| Diagnostic {
            testbed: cell.key.testbed.clone(),
            variant: cell.key.variant.clone(),
            estimator: cell.key.estimator.clone(),
            budget: cell.key.budget.amount,
            name: name.clone(),
            mean: sum / cell.estimates.max(1) as f64,
        })
    }
}

fn csv_bytes<F: FnOnce(&mut csv::Writer<Vec<u8>>) -> csv::Result<()>>(f: F) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    f(&mut w).map_err(|e| HarnessError::write("csv", e))?;
    w.into_inner().map_err(|e| HarnessError::write("csv", e))
}

/// Writes `summary.csv` into a run's results folder.
pub fn write_summary_csv(dir: &OutputDir, rows: &[SummaryRow]) -> Result<()> {
    let bytes = csv_bytes(|w| {
        if rows.is_empty() {
            w.write_record(SUMMARY_HEADER)?;
        }
        rows.iter().try_for_each(|r| w.serialize(r))
    })?;
    dir.write("summary.csv", &bytes).map(|_| ())
}

/// The header of summary.csv (used when there are no rows).
pub const SUMMARY_HEADER: &[&str] = &[
    "testbed",
    "variant",
    "estimator",
    "budget_kind",
    "budget",
    "reps",
    "integrals",
    "rmse",
    "mse",
    "variance",
    "bias",
    "bias_se",
    "samples",
    "fetches",
    "rays",
    "seconds",
    "efficiency",
    "fom",
    "rel_rmse",
    "reference_var",
    "cheap_fetches",
    "seconds_median",
    "efficiency_mse",
    "p_err",
    "p_eff",
    "estimator_id",
    "params",
    "testbed_params",
    "mse_se",
    "cpu_seconds",
    "efficiency_wall",
    "time_clock",
    "shadow_rays",
    "efficiency_renderer",
    "free_flights",
    "target_evals",
    "cache_ops",
    "rmse_display",
    "fom_display",
    "rmse_lo",
    "rmse_hi",
    "rmse_roundoff",
];

/// Writes `summary.json`: one value per line without indentation (a quarter smaller than
/// indented, and an error in it still points at a short line).
pub fn write_summary_json(dir: &OutputDir, report: &RunReport) -> Result<()> {
    use serde::Serialize;
    let mut text = Vec::new();
    let mut ser = serde_json::Serializer::with_formatter(&mut text, serde_json::ser::PrettyFormatter::with_indent(b""));
    report.serialize(&mut ser).map_err(|e| HarnessError::write(dir.join("summary.json"), e))?;
    dir.write("summary.json", &text).map(|_| ())
}

/// NaN, the value of a number that a file written before the number existed does not hold.
pub fn nan() -> f64 {
    f64::NAN
}

/// Reads back a number of summary.json that serde_json wrote as `null` (it writes NaN and the
/// infinities so: a slope that could not be fitted, a test that did not run) as NaN.
pub fn f64_or_nan<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    use serde::Deserialize;
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Reads a results folder back (`summary.json` and `summary.csv`), for `mcbench plot`: the folder
/// must be one finished run ([`crate::store::folder::verify`]: its files are those its `commit.json` lists),
/// and what is read is checked (the experiment name is a plain name, every row parses).
pub fn read_results(dir: &Path) -> Result<RunReport> {
    crate::store::folder::verify(dir, &["summary.json", "summary.csv"])?;
    read_results_unverified(dir)
}

/// [`read_results`] without the commit check (for tests of the readers' own checks).
pub fn read_results_unverified(dir: &Path) -> Result<RunReport> {
    let json = dir.join("summary.json");
    let text = std::fs::read_to_string(&json).map_err(|e| HarnessError::bad_file(&json, e))?;
    let mut report: RunReport = serde_json::from_str(&text).map_err(|e| HarnessError::bad_file(&json, e))?;
    let name = &report.meta.experiment;
    let plain =
        !name.is_empty() && name.len() <= 64 && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if !plain {
        return Err(HarnessError::bad_file(&json, format!("meta.experiment {name:?} is not a plain experiment name")));
    }
    let csv_path = dir.join("summary.csv");
    let mut rd = csv::Reader::from_path(&csv_path).map_err(|e| HarnessError::bad_file(&csv_path, e))?;
    report.rows = rd
        .deserialize()
        .collect::<std::result::Result<Vec<SummaryRow>, _>>()
        .map_err(|e| HarnessError::bad_file(&csv_path, one_line(&e.to_string())))?;
    Ok(report)
}

fn one_line(s: &str) -> String {
    s.lines().next().unwrap_or("malformed").to_string()
}

#[cfg(test)]
mod tests {
    use super::{Claim, Verdict};

    #[test]
    fn a_claim_without_a_verdict_reads_reported_when_it_has_a_value() {
        let c = |held, our_value| Claim { held, our_value, ..Default::default() };
        assert_eq!(c(Some(true), Some(1.0)).verdict(), Verdict::Held);
        assert_eq!(c(Some(false), None).verdict(), Verdict::NotHeld);
        assert_eq!(c(None, Some(1.0)).verdict(), Verdict::Reported);
        assert_eq!(c(None, None).verdict(), Verdict::NotMeasured);
        let set = Claim { verdict: Some(Verdict::Inconclusive), ..c(None, Some(1.0)) };
        assert_eq!(set.verdict(), Verdict::Inconclusive);
    }

    use crate::analysis::TestRow;

    #[test]
    fn numbers_written_as_null_read_back_as_nan() {
        let row = TestRow {
            testbed: "t".into(),
            variant: "v".into(),
            estimator: "e".into(),
            test: "holm_t".into(),
            budget: 4,
            statistic: 0.0,
            p_value: f64::NAN,
            verdict: "untested".into(),
            alpha: 1e-3,
            detectable_rel_bias: f64::INFINITY,
            claim: "unbiased".into(),
            agrees: true,
            untested: 3,
            ..Default::default()
        };
        let text = serde_json::to_string(&row).expect("serialises");
        assert!(text.contains("\"p_value\":null"), "{text}");
        let back: TestRow = serde_json::from_str(&text).expect("reads back");
        assert!(back.p_value.is_nan() && back.detectable_rel_bias.is_nan());
        assert_eq!(back.untested, 3);
    }
}

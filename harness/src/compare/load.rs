//! The two sides of a comparison read from disk: a results root (`--results` of a run, one folder
//! per experiment), one experiment's folder, or a baseline by name (`<results>/baselines/NAME`).
//! Each experiment folder must be one finished run ([`crate::output::read_results`]); its cells'
//! repetition blocks are read from its cell store (`cells.store`), the records of this run's seed,
//! repetitions, version and test-bed parameters.

use super::change::CellData;
use crate::analysis::metrics::{RowBlocks, SummaryRow};
use crate::error::{HarnessError, Result};
use crate::output::RunReport;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// The folder below a results root that holds the saved baselines.
pub const BASELINES: &str = "baselines";

/// What identifies a cell across runs: test bed, variant, estimator, budget kind and amount.
pub type CellId = (String, String, String, String, u64);

/// What the two-sample test reads of a cell: per integral and channel the moments over the
/// repetitions, and the moments of each repetition's sum over every integral and channel (the
/// stored summed deviation from the reference: the same spread).
#[derive(Clone, Debug, Default)]
pub struct CellMoments {
    /// Per integral, per channel.
    pub per_integral: Vec<[mcbench_core::stats::Moments; 3]>,
    /// Over repetitions, each repetition's summed deviation from the reference.
    pub rep_sum: mcbench_core::stats::Moments,
}

/// One experiment of a side: its report and its cells with their blocks.
#[derive(Debug)]
pub struct Experiment {
    /// The folder.
    pub dir: PathBuf,
    /// `summary.json` and `summary.csv`.
    pub report: RunReport,
    /// The cells, by id.
    pub cells: HashMap<CellId, CellData>,
    /// The cells' per-integral moments, by id (the two-sample test's input).
    pub moments: HashMap<CellId, CellMoments>,
}

/// One side of a comparison: what was named, and its experiments by name.
#[derive(Debug)]
pub struct Side {
    /// The name it is shown by: the baseline's name or the folder's name.
    pub label: String,
    /// The folder read.
    pub dir: PathBuf,
    /// Experiments by name.
    pub experiments: BTreeMap<String, Experiment>,
}

/// The id of a summary row's cell.
pub fn cell_id(r: &SummaryRow) -> CellId {
    (r.testbed.clone(), r.variant.clone(), r.estimator.clone(), r.budget_kind.clone(), r.budget)
}

/// Whether `name` is a plain name (a baseline's or an experiment's): letters, digits, `-`, `_`, `.`
/// (not leading), at most 64 characters.
pub fn plain_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 64
        && !name.starts_with('.')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
}

/// Resolves what the command line named (`field`: `A` or `B`): an existing folder, else the
/// baseline of that name below `results`.
pub fn resolve(field: &str, named: &str, results: &Path) -> Result<(String, PathBuf)> {
    let path = Path::new(named);
    if path.is_dir() {
        let label = std::fs::canonicalize(path)
            .ok()
            .and_then(|p| p.file_name().and_then(|n| n.to_str()).map(String::from))
            .unwrap_or_else(|| named.to_string());
        return Ok((label, path.to_path_buf()));
    }
    let baseline = results.join(BASELINES).join(named);
    if plain_name(named) && baseline.is_dir() {
        return Ok((named.to_string(), baseline));
    }
    Err(mcbench_core::error::ConfigError::invalid(
        field,
        named,
        format!("is neither a results folder nor a baseline in {}", results.join(BASELINES).display()),
    )
    .into())
}

/// Reads a side: the folder is one experiment's (it holds `summary.json`) or a root whose
/// folders are.
pub fn read_side(label: &str, dir: &Path) -> Result<Side> {
    let mut experiments = BTreeMap::new();
    if dir.join("summary.json").exists() {
        let e = read_experiment(dir)?;
        experiments.insert(e.report.meta.experiment.clone(), e);
    } else {
        let entries = std::fs::read_dir(dir).map_err(|e| HarnessError::bad_file(dir, e))?;
        let mut dirs: Vec<PathBuf> = entries
            .filter_map(|e| e.ok())
            .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
            .map(|e| e.path())
            .filter(|p| p.join("summary.json").is_file())
            .collect();
        dirs.sort();
        for d in dirs {
            let e = read_experiment(&d)?;
            experiments.insert(e.report.meta.experiment.clone(), e);
        }
    }
    if experiments.is_empty() {
        return Err(HarnessError::bad_file(dir, "holds no finished run (no summary.json in it or in its folders)"));
    }
    Ok(Side { label: label.to_string(), dir: dir.to_path_buf(), experiments })
}

/// Reads one experiment's folder: the committed summaries and the blocks of its cells.
pub fn read_experiment(dir: &Path) -> Result<Experiment> {
    let report = crate::output::read_results(dir)?;
    let store = crate::store::Store::open(&dir.join(crate::store::CELLS))?;
    let mut blocks: HashMap<CellId, Vec<crate::run::cell::RepBlock>> = HashMap::new();
    let mut moments: HashMap<CellId, CellMoments> = HashMap::new();
    for record in store.records() {
        let cell = crate::store::packed::decode_cell(&record.payload)
            .map_err(|e| HarnessError::bad_file(store.path(), format!("record {}: {e}", record.name)))?;
        let k = &cell.key;
        if k.seed != report.meta.seed || k.version != report.meta.version {
            continue;
        }
        // The cells of this run's test-bed parameters (a store may hold cells of earlier runs);
        // without fingerprints, the last record of a cell's id.
        let bed = report.beds.iter().find(|b| b.testbed == k.testbed && b.variant == k.variant);
        if bed.is_some_and(|b| !b.cell_params.is_empty() && b.cell_params != k.testbed_params) {
            continue;
        }
        let id = (
            k.testbed.clone(),
            k.variant.clone(),
            k.estimator.clone(),
            k.budget.kind.name().to_string(),
            k.budget.amount,
        );
        let matches = report
            .rows
            .iter()
            .any(|r| cell_id(r) == id && r.reps == k.reps && cell.estimates == (r.reps * r.integrals) as u64);
        if matches {
            moments.insert(id.clone(), CellMoments { per_integral: cell.moments, rep_sum: cell.rep_dev });
            blocks.insert(id, cell.blocks);
        }
    }
    let cells = report
        .rows
        .iter()
        .map(|r| {
            let b = blocks.remove(&cell_id(r)).unwrap_or_default();
            (cell_id(r), cell_data(r, b))
        })
        .collect();
    Ok(Experiment { dir: dir.to_path_buf(), report, cells, moments })
}

/// A row with its blocks, the offsets set so that all blocks give back the row's MSE and variance.
pub fn cell_data(row: &SummaryRow, blocks: Vec<crate::run::cell::RepBlock>) -> CellData {
    let reps: u64 = blocks.iter().map(|b| b.reps).sum();
    let (sq, p_err) = blocks.iter().fold((0.0, 0.0), |(s, p), b| (s + b.sq, p + b.p_err));
    let usable = reps > 0 && reps == row.reps as u64;
    let (mean_sq, mean_p) = if usable { (sq / reps as f64, p_err / reps as f64) } else { (0.0, 0.0) };
    let blocks = if usable { blocks } else { Vec::new() };
    let with = |offset: f64| RowBlocks {
        blocks: blocks.clone(),
        integrals: row.integrals,
        mse_offset: offset,
        p_err_offset: row.p_err - mean_p,
    };
    CellData { row: row.clone(), mse: with(row.mse - mean_sq), variance: with(row.variance - mean_sq) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cell::RepBlock;

    #[test]
    fn offsets_give_back_the_rows_mse_and_variance_and_a_mismatch_drops_the_blocks() {
        let row = SummaryRow {
            reps: 4,
            integrals: 2,
            mse: 0.5,
            variance: 0.4,
            ..crate::output::plot::tests::row("e", 4, 1.0, 1.0)
        };
        let blocks: Vec<RepBlock> =
            [0.3, 0.7].iter().map(|&sq| RepBlock { reps: 2, sq, ..Default::default() }).collect();
        let c = cell_data(&row, blocks.clone());
        assert!((c.mse.mse_offset - (0.5 - 0.25)).abs() < 1e-15);
        assert!((c.variance.mse_offset - (0.4 - 0.25)).abs() < 1e-15);
        assert_eq!(c.mse.blocks.len(), 2);
        let short = cell_data(&row, blocks[..1].to_vec());
        assert!(short.mse.blocks.is_empty(), "blocks holding another number of repetitions are not used");
    }

    #[test]
    fn names_resolve_to_folders_or_baselines_and_anything_else_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let results = dir.path().join("results");
        std::fs::create_dir_all(results.join(BASELINES).join("before")).expect("mkdir");
        let (label, path) = resolve("A", "before", &results).expect("a baseline");
        assert_eq!((label.as_str(), path), ("before", results.join(BASELINES).join("before")));
        let (label, _) = resolve("B", results.to_str().expect("utf-8"), &results).expect("a folder");
        assert_eq!(label, "results");
        let e = resolve("A", "missing", &results).expect_err("refused");
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("A") && e.to_string().contains("missing"), "{e}");
        assert!(resolve("A", "../x", &results).is_err());
        assert!(!plain_name(".hidden") && !plain_name("a/b") && plain_name("v1.2_x-y"));
    }
}

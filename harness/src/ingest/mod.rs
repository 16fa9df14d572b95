//! `mcbench ingest`: mcbench's statistics on per-repetition estimates another program wrote
//! (book: your-renderer.md; the manifest's format: contract.md). A manifest names the reference
//! and, per estimator and budget, the files of its repetitions: images (OpenEXR or NumPy) or CSV
//! scalars, with optional seconds. Every file is read and checked before anything is written; the
//! cells are then stored and analysed exactly as a run's ([`crate::run::execute::finish`]), so
//! the results folder holds what a run writes and `mcbench compare` reads it.

pub mod accumulate;
pub mod image;
pub mod manifest;
pub mod npy;
pub mod plan;
pub mod read;
pub mod scalars;

use crate::error::{HarnessError, Result};
use crate::output::integrals::IntegralsFormat;
use crate::registry::Registry;
use crate::run::cell::{CellKey, CellResult};
use crate::run::execute::{ExecOptions, Outcome};
use crate::run::runner::RunResults;
use manifest::{BiasClaim, Manifest};
use mcbench_core::budget::{Budget, BudgetKind};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where an ingested run is written.
pub struct IngestOptions<'a> {
    /// Root of result folders (`results/`).
    pub results_root: PathBuf,
    /// Root of plot folders (`plots/`).
    pub plots_root: PathBuf,
    /// Draw plots and the report.
    pub plots: bool,
    /// Wait for another run's lock on the folders instead of refusing (exit 3).
    pub wait: bool,
    /// How `integrals.csv` is written.
    pub integrals: IntegralsFormat,
    /// Where built-in test beds and stored references are looked up.
    pub registry: &'a Registry,
}

/// Whether an estimator's unbiasedness test agreed with its declared bias.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expectation {
    /// Declared unbiased and passed, or declared biased and flagged `biased`.
    AsDeclared,
    /// Declared unbiased and flagged `biased`, or declared biased and passed.
    Contradicted,
    /// The test did not decide (`inconclusive`).
    Undecided,
    /// Declared `unknown`: no expectation.
    NoClaim,
}

/// One estimator's declared bias and what its combined unbiasedness test said.
#[derive(Clone, Debug)]
pub struct Judged {
    /// The estimator.
    pub estimator: String,
    /// Its declared bias.
    pub declared: BiasClaim,
    /// The combined test's verdict at the largest budget (`pass`, `biased`, `inconclusive`).
    pub verdict: String,
    /// How they agree.
    pub expectation: Expectation,
}

/// Reads the manifest at `manifest_path` and every file it names, then writes the results (and
/// plots) a run of those cells writes. Bad input is refused before anything is written.
pub fn ingest(manifest_path: &Path, opts: &IngestOptions<'_>) -> Result<(Outcome, Vec<Judged>)> {
    let started = Instant::now();
    let m = Manifest::read(manifest_path)?;
    let dir = manifest_path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let bed = match (&m.reference.image, &m.reference.variance) {
        (Some(image), Some(variance)) => {
            plan::image_bed(image, image_reference(manifest_path, dir, image, variance, m.reference.samples)?)
        }
        _ => plan::builtin_bed(&m, opts.registry)?,
    };
    let (w, h) = bed.bed.resolution();
    if bed.bed.integrals() != w * h {
        let why = format!(
            "{} has {} integrals per {w}x{h} image; ingest reads one value per pixel",
            bed.label(),
            bed.bed.integrals()
        );
        return Err(HarnessError::bad_file(manifest_path, format!("field `reference.testbed`: {why}")));
    }
    let plan = plan::plan(&m, bed);
    plan.check_claims().map_err(|e| HarnessError::bad_file(manifest_path, e))?;
    let mut cells = Vec::new();
    for (ei, e) in m.estimators.iter().enumerate() {
        for (bj, b) in e.budgets.iter().enumerate() {
            let pb = &plan.beds[0];
            let key = CellKey {
                testbed: pb.spec.id.clone(),
                variant: pb.variant.clone(),
                testbed_params: serde_json::to_string(&pb.spec.params).unwrap_or_default(),
                estimator: plan.estimators[ei].name.clone(),
                budget: Budget { kind: BudgetKind::Samples, amount: b.samples },
                reps: b.reps,
                seed: plan.sweep.seed,
                version: env!("CARGO_PKG_VERSION").to_string(),
            };
            let src = read::Source {
                manifest: manifest_path,
                dir,
                field: format!("estimators[{ei}].budgets[{bj}]"),
                bed: pb.bed.as_ref(),
            };
            cells.push((0, ei, read::cell(&src, b, key)?));
        }
    }
    let run = RunResults { cells };
    let exec = ExecOptions {
        results_root: opts.results_root.clone(),
        plots_root: opts.plots_root.clone(),
        threads: Some(1),
        observer: &crate::run::runner::Silent,
        plots: opts.plots,
        wait: opts.wait,
        registry: opts.registry,
        integrals: opts.integrals,
    };
    let results_dir = exec.results_root.join(&m.name);
    crate::store::folder::check_own_dir("--results", &results_dir)?;
    if exec.plots {
        crate::store::folder::check_own_dir("--plots", &exec.plots_root.join(&m.name))?;
    }
    let _locks = crate::run::execute::lock_folders(&m.name, &exec)?;
    store_cells(&results_dir.join(crate::store::CELLS), &run.cells)?;
    let outcome = crate::run::execute::finish(&plan, None, &run, &exec, started)?;
    let judged = judge(&m, &outcome);
    Ok((outcome, judged))
}

/// The reference bed of an image of its mean and an image of its variance (same shape, finite,
/// variance not negative).
fn image_reference(
    manifest: &Path,
    dir: &Path,
    image: &str,
    variance: &str,
    samples: Option<u64>,
) -> Result<plan::ImageBed> {
    let load = |field: &str, rel: &str| -> Result<image::Image> {
        let path = manifest::resolve(dir, rel)
            .map_err(|why| HarnessError::bad_file(manifest, format!("field `{field}`: {why}")))?;
        let img = image::read(&path).map_err(|e| HarnessError::bad_file(&path, format!("field `{field}`: {e}")))?;
        if let Some((row, col, c)) = img.first_non_finite() {
            let why = format!("field `{field}`: pixel (row {row}, column {col}) channel {c} is not finite");
            return Err(HarnessError::bad_file(&path, why));
        }
        Ok(img)
    };
    let mean = load("reference.image", image)?;
    let var = load("reference.variance", variance)?;
    let var_path = dir.join(variance);
    if (var.width, var.height) != (mean.width, mean.height) {
        let why = format!(
            "field `reference.variance`: {}x{} (width x height), the reference image is {}x{}",
            var.width, var.height, mean.width, mean.height
        );
        return Err(HarnessError::bad_file(var_path, why));
    }
    if var.pixels.iter().any(|p| p.0.iter().any(|v| *v < 0.0)) {
        return Err(HarnessError::bad_file(var_path, "field `reference.variance`: a variance is negative"));
    }
    Ok(plan::ImageBed::new(image, mean, &var, samples))
}

/// Appends the cells to the results folder's cell store (the last record of a name is the one read).
fn store_cells(path: &Path, cells: &[(usize, usize, CellResult)]) -> Result<()> {
    let mut writer = crate::store::StoreWriter::open(path)?;
    for (_, _, c) in cells {
        writer.append(&c.key.name(), &crate::store::packed::encode_cell(c))?;
    }
    Ok(())
}

/// Each estimator's declared bias against its combined test at the largest budget.
fn judge(m: &Manifest, outcome: &Outcome) -> Vec<Judged> {
    m.estimators
        .iter()
        .map(|e| {
            let verdict = outcome
                .report
                .tests
                .iter()
                .find(|t| t.estimator == e.id && t.test == "combined")
                .map(|t| t.verdict.clone())
                .unwrap_or_else(|| "not tested".into());
            let expectation = match (e.bias, verdict.as_str()) {
                (BiasClaim::Unknown, _) => Expectation::NoClaim,
                (BiasClaim::Unbiased, "pass") | (BiasClaim::Biased, "biased") => Expectation::AsDeclared,
                (BiasClaim::Unbiased, "biased") | (BiasClaim::Biased, "pass") => Expectation::Contradicted,
                _ => Expectation::Undecided,
            };
            Judged { estimator: e.id.clone(), declared: e.bias, verdict, expectation }
        })
        .collect()
}

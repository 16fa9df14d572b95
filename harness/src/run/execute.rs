//! One experiment end to end: plan (all validation before any file is touched), run (with
//! resume), metrics, fits, tests, claims, result files, plots and report.

use crate::analysis::metrics::SummaryRow;
use crate::analysis::{self, TestRow};
use crate::config::Sweep;
use crate::error::Result;
use crate::output::integrals::{IntegralRow, IntegralsFormat};
use crate::output::plot::DisplayNames;
use crate::output::{self, Diagnostic, Meta, RunReport};
use crate::plan::{Plan, PreparedBed, PreparedEstimator};
use crate::registry::{Experiment, Registry};
use crate::run::cell::CellResult;
use crate::run::runner::{self, Observer, RunOptions, RunResults};
use crate::store::folder::{check_own_dir, FolderLock, OutputDir};
use mcbench_core::budget::BudgetKind;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where and how to run.
pub struct ExecOptions<'a> {
    /// Root of result folders (`results/`).
    pub results_root: PathBuf,
    /// Root of plot folders (`plots/`).
    pub plots_root: PathBuf,
    /// Worker threads (None: all cores).
    pub threads: Option<usize>,
    /// Progress receiver.
    pub observer: &'a dyn Observer,
    /// Draw plots and the report.
    pub plots: bool,
    /// Wait for another run's lock on the folders instead of refusing (exit 3).
    pub wait: bool,
    /// Where names are looked up (experiments' own analyses build further plans).
    pub registry: &'a Registry,
    /// How `integrals.csv` is written (gzip-compressed by default).
    pub integrals: IntegralsFormat,
}

/// What a finished experiment produced.
pub struct Outcome {
    /// Everything in summary.json plus the rows.
    pub report: RunReport,
    /// The results folder.
    pub results_dir: PathBuf,
    /// The plots folder.
    pub plots_dir: PathBuf,
}

/// Builds the plan of a sweep (validation only; nothing is written).
pub fn prepare(sweep: Sweep, registry: &Registry) -> Result<Plan> {
    Plan::prepare(sweep, registry)
}

/// [`prepare`] for a named experiment's sweep reshaped by a config that gives no claims: the
/// experiment's claims are not checked against the reshaped plan ([`Plan::prepare_unchecked`]).
pub fn prepare_reshaped(sweep: Sweep, registry: &Registry) -> Result<Plan> {
    Plan::prepare_unchecked(sweep, registry)
}

/// What a run reads before it writes anything: the stored cells it will resume from, checked.
pub struct Preflight {
    stored: Vec<Option<CellResult>>,
}

/// Everything a run checks before it writes anything (after [`prepare`] checked the plan): the
/// output folders are folders or can be made, and every stored cell it will read is well formed.
pub fn preflight(plan: &Plan, def: Option<&Experiment>, opts: &ExecOptions<'_>) -> Result<Preflight> {
    let results_dir = opts.results_root.join(&plan.sweep.experiment);
    check_own_dir("--results", &results_dir)?;
    if opts.plots {
        check_own_dir("--plots", &opts.plots_root.join(&plan.sweep.experiment))?;
    }
    let cells = results_dir.join(crate::store::CELLS);
    let stored = runner::preload(plan, Some(&cells))?;
    if let Some(check) = def.and_then(|d| d.preflight) {
        check(opts.registry, &plan.sweep, &cells)?;
    }
    Ok(Preflight { stored })
}

/// Runs a prepared plan and writes every output ([`preflight`], then [`execute_checked`]).
pub fn execute(plan: &Plan, def: Option<&Experiment>, opts: &ExecOptions<'_>) -> Result<Outcome> {
    let checked = preflight(plan, def, opts)?;
    execute_checked(plan, def, opts, checked)
}

/// The folders' locks of a run: results (with its cell store) and, when plots are drawn, plots.
pub fn lock_folders(experiment: &str, opts: &ExecOptions<'_>) -> Result<Vec<FolderLock>> {
    let mut locks = vec![FolderLock::acquire(&opts.results_root.join(experiment), opts.wait, &[])?];
    if opts.plots {
        locks.push(FolderLock::acquire(&opts.plots_root.join(experiment), opts.wait, &[])?);
    }
    Ok(locks)
}

/// Runs a plan whose [`preflight`] passed: takes the folders' locks (refusing, exit 3, or waiting
/// when another run holds them), runs the missing cells, and writes every output.
pub fn execute_checked(
    plan: &Plan,
    def: Option<&Experiment>,
    opts: &ExecOptions<'_>,
    checked: Preflight,
) -> Result<Outcome> {
    let started = Instant::now();
    let _locks = lock_folders(&plan.sweep.experiment, opts)?;
    let results_dir = opts.results_root.join(&plan.sweep.experiment);
    let run = runner::run_preloaded(
        plan,
        &RunOptions {
            threads: opts.threads,
            store: Some(results_dir.join(crate::store::CELLS)),
            observer: opts.observer,
        },
        checked.stored,
    )?;
    finish(plan, def, &run, opts, started)
}

/// Everything after the cells are known: metrics, fits, tests, claims, the experiment's post hook,
/// result files, plots and report. A single run and a merge of shards
/// ([`crate::run::merge`]) both end here, so equal cells give equal files. The caller holds the
/// folders' locks ([`lock_folders`]); the files of each folder are committed last.
pub fn finish(
    plan: &Plan,
    def: Option<&Experiment>,
    run: &RunResults,
    opts: &ExecOptions<'_>,
    started: Instant,
) -> Result<Outcome> {
    let analysis = crate::run::phases::enter(crate::run::phases::Phase::Analysis);
    let sweep = &plan.sweep;
    let results_dir = opts.results_root.join(&sweep.experiment);
    let plots_dir = opts.plots_root.join(&sweep.experiment);
    let results = OutputDir::new(&results_dir);
    let run_id = crate::store::folder::run_id(&sweep.experiment);
    let mut rows: Vec<SummaryRow> = Vec::new();
    let mut tests: Vec<TestRow> = Vec::new();
    let mut integrals: Vec<IntegralRow> = Vec::new();
    let mut diagnostics = Vec::new();
    let last_budget = sweep.budgets.last().map(|b| b.amount);
    for (bi, ei, cell) in &run.cells {
        let (bed, est) = (&plan.beds[*bi], &plan.estimators[*ei]);
        let reference = bed.bed.reference();
        rows.push(plan.summary_row(*bi, *ei, cell));
        diagnostics.extend(Diagnostic::of_cell(cell));
        if Some(cell.key.budget.amount) == last_budget {
            let group = analysis::Gate::group_of(est.estimator.as_ref(), bed.bed.as_ref());
            let gate = previous_budget_gate(run, *bi, *ei, cell).map(|g| g.with_group(group));
            tests.extend(analysis::unbiasedness(cell, reference, est.bias(), gate.as_ref(), sweep.tolerance()));
            integrals.extend(integral_rows(cell, bed, est));
        }
    }
    let fits = analysis::fits(&rows);
    let speedups =
        sweep.baseline.as_deref().map(|b| analysis::speedups(&rows, &fits, b, &sweep.cost_model)).unwrap_or_default();
    let mut notes = Vec::new();
    for b in &plan.beds {
        notes.push(match &b.bed.reference().kind {
            mcbench_core::testbed::ReferenceKind::Exact { method, bound } => {
                format!("{}: exact reference ({method}), absolute error bound {bound:.3e}", b.label())
            }
            mcbench_core::testbed::ReferenceKind::Stored { command, samples } => format!(
                "{}: stored reference from `{command}` ({samples} samples per value); its variance is subtracted from the MSE",
                b.label()
            ),
        });
    }
    let reproducible = sweep.budgets.iter().all(|b| b.kind != BudgetKind::Micros);
    if !reproducible {
        notes.push(
            "time budgets (micros) become a sample count calibrated by a CPU-time pilot on this machine: results are not bit-reproducible across runs or machines".into(),
        );
    }
    let threads = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map(|p| p.current_num_threads())
        .unwrap_or(1);
    let mut report = RunReport {
        meta: Meta {
            experiment: sweep.experiment.clone(),
            seed: sweep.seed,
            git_commit: git_commit(),
            threads,
            cpu: cpu_model(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            mode: sweep.mode.name().to_string(),
            reps: sweep.reps,
            wall_seconds: 0.0,
            notes,
            run_id: run_id.clone(),
            reproducible,
            cost_model: sweep.cost_model,
        },
        fits,
        tests,
        paper: Vec::new(),
        speedups,
        skipped: plan.skipped.clone(),
        unavailable: Vec::new(),
        counts: rows.iter().map(Into::into).collect(),
        rows,
        labels: plan.estimators.iter().map(|e| (e.name.clone(), e.entry.label.to_string())).collect(),
        diagnostics,
        beds: plan.beds.iter().map(crate::compare::fingerprint::BedPrint::of).collect(),
    };
    if let Some(claims) = def.and_then(|d| d.claims) {
        report.paper = claims(&report);
    }
    let declared: Vec<_> = sweep.claims.iter().map(|c| c.judge(&report)).collect();
    report.paper.extend(declared);
    let mut extra_plots = Vec::new();
    if let Some(post) = def.and_then(|d| d.post) {
        extra_plots = post(crate::registry::PostContext {
            plan,
            results: run,
            report: &mut report,
            out: &results,
            plots: opts.plots.then_some(plots_dir.as_path()),
            registry: opts.registry,
        })?;
    }
    report.meta.wall_seconds = started.elapsed().as_secs_f64();
    drop(analysis);
    let _output = crate::run::phases::enter(crate::run::phases::Phase::Output);
    output::write_summary_csv(&results, &report.rows)?;
    crate::output::integrals::write(&results, &integrals, opts.integrals)?;
    output::write_summary_json(&results, &report)?;
    crate::output::report::write_tables(&results, &report)?;
    results.commit(&run_id, None)?;
    if opts.plots {
        draw_with(&report, &plots_dir, &results_dir, extra_plots, &integrals, &opts.registry.display_names())?;
    }
    Ok(Outcome { report, results_dir, plots_dir })
}

/// The gate of a cell's unbiasedness tests from the same pair at the previous budget of the sweep
/// (independent streams), its spread scaled by `sqrt(previous budget / budget)`; `None` for a
/// one-budget sweep.
fn previous_budget_gate(run: &RunResults, bi: usize, ei: usize, cell: &CellResult) -> Option<analysis::Gate> {
    let same = |c: &CellResult| c.key.budget.kind == cell.key.budget.kind;
    let mine = || run.cells.iter().filter(|(b, e, c)| (*b, *e) == (bi, ei) && same(c));
    let (source, other) = match mine()
        .filter(|(_, _, c)| c.key.budget.amount < cell.key.budget.amount)
        .max_by_key(|(_, _, c)| c.key.budget.amount)
    {
        Some(p) => ("previous budget", p),
        // The first budget is gated by the next one (its streams are independent too).
        None => (
            "next budget",
            mine()
                .filter(|(_, _, c)| c.key.budget.amount > cell.key.budget.amount)
                .min_by_key(|(_, _, c)| c.key.budget.amount)?,
        ),
    };
    let scale = (other.2.key.budget.amount as f64 / cell.key.budget.amount as f64).sqrt();
    Some(analysis::Gate::from_cell(&other.2, source, scale))
}

/// Draws the plots, `report.md` and `index.html` of a finished run into `plots_dir` (the per-pixel
/// maps from the results folder's `integrals.csv`), commits them, and rewrites the plots root's
/// `index.html`; `names` names estimators and test beds in legends and titles.
pub fn draw(report: &RunReport, plots_dir: &Path, results_dir: &Path, names: &DisplayNames) -> Result<()> {
    let integrals = crate::output::html::read_integrals(results_dir)?;
    draw_with(report, plots_dir, results_dir, Vec::new(), &integrals, names)
}

fn draw_with(
    report: &RunReport,
    plots_dir: &Path,
    results_dir: &Path,
    extra: Vec<PathBuf>,
    integrals: &[IntegralRow],
    names: &DisplayNames,
) -> Result<()> {
    let plots = OutputDir::new(plots_dir);
    let mut files = crate::output::plot::write_plots_named(report, plots_dir, names)?;
    files.extend(extra);
    for f in &files {
        plots.record(f)?;
    }
    // The summary and the page show every figure in the folder (an experiment's own figures too).
    let listed = crate::output::report::digest::list_files(plots_dir);
    let md = crate::output::report::render_report(report, &listed, plots_dir, results_dir);
    plots.write("report.md", md.as_bytes())?;
    crate::output::html::write_page(report, &plots, results_dir, integrals)?;
    plots.commit(&crate::store::folder::run_id(&report.meta.experiment), Some(&report.meta.run_id))?;
    let root = plots_dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    crate::output::html::write_root_index(root).map(|_| ())
}

fn integral_rows(cell: &CellResult, prepared: &PreparedBed, est: &PreparedEstimator) -> Vec<IntegralRow> {
    let bed = prepared.bed.as_ref();
    let (w, h) = bed.resolution();
    // Integrals per pixel (frames of paper 004); 1 when a sequence spans pixels (gradient-box).
    let frames = (bed.integrals() / (w * h).max(1)).max(1);
    let reference = bed.reference();
    let mut out = Vec::with_capacity(cell.moments.len() * 3);
    for (i, m) in cell.moments.iter().enumerate() {
        let geometry = bed.geometry(i);
        for (c, mc) in m.iter().enumerate() {
            out.push(IntegralRow {
                testbed: cell.key.testbed.clone(),
                variant: cell.key.variant.clone(),
                estimator: cell.key.estimator.clone(),
                integral: i,
                px: (i / frames) % w,
                py: (i / frames) / w,
                channel: c,
                reference: reference.value[i][c],
                reference_se: reference.std_err[i][c],
                mean: mc.mean(),
                std_err: mc.std_err(),
                geometry: geometry.clone(),
                estimator_id: est.spec.id.clone(),
            });
        }
    }
    out
}

fn git_commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

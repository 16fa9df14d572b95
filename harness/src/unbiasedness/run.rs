//! The analysis of `unbiasedness`: runs the parts after the first (the first is the experiment's
//! own sweep, already run by the harness) into the same results folder (resumable cells), adds their
//! summary rows, tests and skipped pairs to the report, builds the table of every part, writes
//! `unbiasedness.csv` and `unbiasedness.md`, and adds the per-row and per-control claims.
//!
//! Overrides: `--seed` applies to every part; `--reps R` (which sets the first part's repetitions)
//! applies to every part when it differs from the first part's default; `--config` changes the
//! first part only. `--threads` is honoured through the run's thread count (`meta.threads`).

use super::reps::pooled_over_repetitions;
use super::table;
use super::{parts, Row};
use crate::config::Sweep;
use crate::error::Result;
use crate::folder::OutputDir;
use crate::output::RunReport;
use crate::plan::Plan;
use crate::progress::Progress;
use crate::registry::Registry;
use crate::runner::{self, RunOptions, RunResults};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The rows of a finished plan's cells (and their tests, when `with_tests`: the harness already
/// added the first part's). Whole-image sequences also get `pooled_z_rep`
/// ([`crate::unbiasedness_reps`]), recomputed on `threads` threads.
fn rows_of(
    plan: &Plan,
    run: &RunResults,
    report: &mut RunReport,
    with_tests: bool,
    registry: &Registry,
) -> Result<Vec<Row>> {
    let threads = report.meta.threads;
    let mut rows = Vec::new();
    for (bi, ei, cell) in &run.cells {
        let bed = plan.beds[*bi].bed.as_ref();
        let reference = bed.reference();
        let bias = plan.estimators[*ei].entry.bias;
        let mut tests = table::tests_of(cell, reference, bias, bed.sequence_length());
        if let Some(template) = tests.iter().find(|t| t.test == "pooled_z").cloned() {
            if let Some(mut t) = pooled_over_repetitions(plan, *bi, *ei, threads, &template)? {
                table::set_claim(&mut t, bias);
                tests.push(t);
            }
        }
        let exempt = exemption(registry, &plan.estimators[*ei].spec.id, &cell.key.testbed, &cell.key.variant);
        rows.push(table::row_from_tests(cell, reference, bias, &tests, exempt));
        if with_tests {
            report.rows.push(plan.summary_row(*bi, *ei, cell));
            report.tests.extend(tests);
        }
    }
    Ok(rows)
}

/// Why a biased control `id` is not required to be flagged on `testbed/variant`, if its registry
/// entry says so.
pub fn exemption(registry: &Registry, id: &str, testbed: &str, variant: &str) -> Option<&'static str> {
    let entry = registry.estimator(id).ok()?;
    entry.checks.exempt.iter().find(|e| e.covers(testbed, variant)).map(|e| e.reason)
}

/// The plans of a part's sweep. A pair whose configuration is invalid on a test bed (the terminating
/// single-particle model where `r > 2/(a+1)`: [`estimators::estimator::Estimator::validate`]) makes
/// the whole sweep bad input; here it becomes a `not-run` row with the reason, and the rest runs:
/// the sweep is split per test bed, and a failing test bed per estimator (streams do not depend on
/// how a sweep is split, so the cells are the same).
fn prepare_valid(sweep: Sweep, registry: &Registry) -> Result<(Vec<Plan>, Vec<Row>)> {
    if let Ok(p) = Plan::prepare(sweep.clone(), registry) {
        return Ok((vec![p], Vec::new()));
    }
    let (mut plans, mut rows) = (Vec::new(), Vec::new());
    for bed in &sweep.testbeds {
        let one = Sweep { testbeds: vec![bed.clone()], ..sweep.clone() };
        if let Ok(p) = Plan::prepare(one.clone(), registry) {
            plans.push(p);
            continue;
        }
        for est in &sweep.estimators {
            match Plan::prepare(Sweep { estimators: vec![est.clone()], ..one.clone() }, registry) {
                Ok(p) => plans.push(p),
                Err(e) => {
                    let entry = registry.estimator(&est.id)?;
                    let variant = bed.variant.clone().unwrap_or_default();
                    let exempt = exemption(registry, &est.id, &bed.id, &variant);
                    rows.push(table::not_run(&est.name(), &bed.id, &variant, entry.bias, &e.to_string(), exempt));
                }
            }
        }
    }
    Ok((plans, rows))
}

/// The parts after the first as they run after `first` (the experiment's sweep as it ran): with
/// its seed, and with its repetitions when they differ from the first part's default; each with a
/// label for the notes.
fn other_parts(registry: &Registry, first: &Sweep) -> Vec<(String, Sweep)> {
    let all = parts(registry, first.mode);
    let Some(default_reps) = all.first().map(|p| p.sweep.reps) else { return Vec::new() };
    let reps_override = (first.reps != default_reps).then_some(first.reps);
    all.into_iter()
        .skip(1)
        .map(|part| {
            let mut sweep = part.sweep;
            sweep.seed = first.seed;
            if let Some(r) = reps_override {
                sweep.reps = r;
            }
            let bed = sweep.testbeds.first().map(|t| t.id.clone()).unwrap_or_default();
            (format!("part {bed}... ({} spp, {} reps)", part.samples, sweep.reps), sweep)
        })
        .collect()
}

/// Checks, before the run writes anything, every stored cell the other parts will read back.
pub fn preflight(registry: &Registry, first: &Sweep, cells: &Path) -> Result<()> {
    for (_, sweep) in other_parts(registry, first) {
        let (plans, _) = prepare_valid(sweep, registry)?;
        for p in &plans {
            runner::preload(p, Some(cells))?;
        }
    }
    Ok(())
}

/// Runs the other parts and writes the table (see the module docs).
pub fn post(
    plan: &Plan,
    run: &RunResults,
    report: &mut RunReport,
    results: &OutputDir,
    _plots: Option<&Path>,
    registry: &Registry,
) -> Result<Vec<PathBuf>> {
    let mut rows = rows_of(plan, run, report, false, registry)?;
    let first_bed = plan.sweep.testbeds.first().map(|t| t.id.clone()).unwrap_or_default();
    let mut notes = vec![format!("part {first_bed}... ({} reps)", plan.sweep.reps)];
    for (label, sweep) in other_parts(registry, &plan.sweep) {
        let t0 = Instant::now();
        let (plans, invalid) = prepare_valid(sweep, registry)?;
        rows.extend(invalid);
        for p in plans {
            let progress = Progress::default();
            let opts = RunOptions {
                threads: Some(report.meta.threads),
                cell_dir: Some(results.join("cells")),
                observer: &progress,
            };
            let r = runner::run(&p, &opts)?;
            progress.finish();
            rows.extend(rows_of(&p, &r, report, true, registry)?);
            report.skipped.extend(p.skipped.iter().cloned());
            for e in &p.estimators {
                if !report.labels.iter().any(|(n, _)| n == &e.name) {
                    report.labels.push((e.name.clone(), e.entry.label.to_string()));
                }
            }
        }
        notes.push(format!("{label} {:.1} s", t0.elapsed().as_secs_f64()));
    }
    report.meta.notes.push(format!("unbiasedness parts: {}", notes.join(", ")));
    table::write_csv(results, "unbiasedness.csv", &rows)?;
    let md = table::markdown(&rows);
    results.write("unbiasedness.md", md.as_bytes())?;
    report.paper.extend(table::claims(&rows));
    Ok(Vec::new())
}

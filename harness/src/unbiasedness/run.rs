//! The analysis of `unbiasedness`: runs the parts after the first (the first is the experiment's
//! own sweep, already run by the harness) into the same results folder (resumable cells), adds their
//! summary rows, tests and skipped pairs to the report, builds the table of every part, writes
//! `unbiasedness.csv` and `unbiasedness.md`, and adds the per-row and per-control claims.
//!
//! Overrides: `--seed` applies to every part; `--reps R` (which sets the first part's repetitions)
//! applies to every part when it differs from the first part's default; `--config` changes the
//! first part only. `--threads` is honoured through the run's thread count (`meta.threads`).

use super::table;
use super::{parts, Row};
use crate::config::Sweep;
use crate::error::Result;
use crate::output::RunReport;
use crate::plan::Plan;
use crate::registry::PostContext;
use crate::registry::Registry;
use crate::run::runner::{self, RunResults};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The seed of a part's pilot: independent streams for the same pairs, cells and repetitions.
pub fn pilot_seed(seed: u64) -> u64 {
    seed ^ 0x5049_4c4f_545f_5345
}

/// The rows of a finished plan's cells, each tested behind the gate of its pilot cell (the same
/// pair on [`pilot_seed`]), and the tests (added to the report when `with_tests`; the harness
/// already added the first part's, gated by nothing, and they are replaced here).
fn rows_of(plan: &Plan, run: &RunResults, pilot: &RunResults, report: &mut RunReport, registry: &Registry) -> Vec<Row> {
    let mut rows = Vec::new();
    for ((bi, ei, cell), (_, _, pilot_cell)) in run.cells.iter().zip(&pilot.cells) {
        let bed = plan.beds[*bi].bed.as_ref();
        let bias = plan.estimators[*ei].entry.bias;
        let group = crate::analysis::Gate::group_of(plan.estimators[*ei].estimator.as_ref(), bed);
        let gate = crate::analysis::Gate::from_cell(pilot_cell, "pilot", 1.0).with_group(group);
        let mut tests = crate::analysis::unbiasedness(cell, bed.reference(), bias, Some(&gate), plan.sweep.tolerance());
        if let mcbench_core::testbed::ReferenceKind::Stored { command, .. } = &bed.reference().kind {
            if made_by(command, &plan.estimators[*ei].spec.id) {
                judged_against_itself(&mut tests, command);
            }
        }
        let exempt = exemption(registry, &plan.estimators[*ei].spec.id, &cell.key.testbed, &cell.key.variant);
        rows.push(table::row_from_tests(cell, bias, &tests, exempt));
        report.tests.retain(|t| {
            !(t.estimator == cell.key.estimator
                && t.testbed == cell.key.testbed
                && t.variant == cell.key.variant
                && t.budget == cell.key.budget.amount)
        });
        report.tests.extend(tests);
    }
    rows
}

/// Whether a stored reference's command names `id` (underscores read as spaces) as what made it:
/// the row would judge the estimator against its own sampling code.
pub fn made_by(command: &str, id: &str) -> bool {
    let norm = |s: &str| s.to_lowercase().replace('_', " ");
    norm(command).contains(&norm(id))
}

/// A row judged against a reference made by the estimator itself: a bias shared by both cannot
/// show, so it can be flagged but never pass.
fn judged_against_itself(tests: &mut [crate::analysis::TestRow], command: &str) {
    for t in tests.iter_mut().filter(|t| t.verdict == "pass") {
        t.verdict = "inconclusive".into();
        t.agrees = false;
        t.reason = format!("the stored reference is made by this estimator's own sampling (`{command}`): a shared bias cannot show, so it cannot pass");
    }
}

/// A part's sweep on its pilot seed.
fn pilot_of(sweep: &Sweep) -> Sweep {
    Sweep { seed: pilot_seed(sweep.seed), ..sweep.clone() }
}

/// Why a biased control `id` is not required to be flagged on `testbed/variant`, if its registry
/// entry or the registry says so ([`Registry::exemption`]).
pub fn exemption(registry: &Registry, id: &str, testbed: &str, variant: &str) -> Option<&'static str> {
    registry.exemption(id, testbed, variant)
}

/// The plans of a part's sweep. A pair whose configuration is invalid on a test bed (the terminating
/// single-particle model where `r > 2/(a+1)`: [`mcbench_core::estimator::Estimator::validate`]) makes
/// the whole sweep bad input; here it becomes a `not-run` row with the reason, and the rest runs:
/// the sweep is split per test bed, and a failing test bed per estimator (streams do not depend on
/// how a sweep is split, so the cells are the same).
pub(crate) fn prepare_valid(sweep: Sweep, registry: &Registry) -> Result<(Vec<Plan>, Vec<Row>)> {
    if let Ok(p) = Plan::prepare(sweep.clone(), registry) {
        return Ok((vec![p], Vec::new()));
    }
    let (mut plans, mut rows) = (Vec::new(), Vec::new());
    // The claims are judged on the whole run, not on its pieces (a piece lacks their other cells).
    let sweep = Sweep { claims: Vec::new(), ..sweep };
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
    let store = crate::store::Store::open(cells)?;
    let parts = other_parts(registry, first).into_iter().map(|(_, s)| s);
    for sweep in std::iter::once(first.clone()).chain(parts) {
        for s in [pilot_of(&sweep), sweep] {
            let (plans, _) = prepare_valid(s, registry)?;
            for p in &plans {
                runner::preload_from(p, Some(&store))?;
            }
        }
    }
    Ok(())
}

/// Runs the pilots, the other parts and writes the table (see the module docs).
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { plan, results: run, report, out: results, registry, .. } = cx;
    let threads = report.meta.threads;
    let first_pilot = runner::run_stored(
        &Plan::prepare(pilot_of(&plan.sweep), registry)?,
        results.join(crate::store::CELLS),
        threads,
    )?;
    let mut rows = rows_of(plan, run, &first_pilot, report, registry);
    let first_bed = plan.sweep.testbeds.first().map(|t| t.id.clone()).unwrap_or_default();
    let mut notes = vec![format!("part {first_bed}... ({} reps)", plan.sweep.reps)];
    for (label, sweep) in other_parts(registry, &plan.sweep) {
        let t0 = Instant::now();
        let (plans, invalid) = prepare_valid(sweep, registry)?;
        rows.extend(invalid);
        for p in plans {
            let pilot = runner::run_stored(
                &Plan::prepare(pilot_of(&p.sweep), registry)?,
                results.join(crate::store::CELLS),
                threads,
            )?;
            let r = runner::run_stored(&p, results.join(crate::store::CELLS), threads)?;
            for (bi, ei, cell) in &r.cells {
                report.rows.push(p.summary_row(*bi, *ei, cell));
            }
            rows.extend(rows_of(&p, &r, &pilot, report, registry));
            report.skipped.extend(p.skipped.iter().cloned());
            for e in &p.estimators {
                if !report.labels.iter().any(|(n, _)| n == &e.name) {
                    report.labels.push((e.name.clone(), e.entry.label.to_string()));
                }
            }
        }
        notes.push(format!("{label} {:.1} s", t0.elapsed().as_secs_f64()));
    }
    report.meta.notes.push(format!(
        "unbiasedness parts (each with a pilot of as many repetitions on seed {}): {}",
        pilot_seed(plan.sweep.seed),
        notes.join(", ")
    ));
    table::write_csv(results, "unbiasedness.csv", &rows)?;
    let md = table::markdown(&rows);
    results.write("unbiasedness.md", md.as_bytes())?;
    report.paper.extend(table::claims(&rows));
    Ok(Vec::new())
}

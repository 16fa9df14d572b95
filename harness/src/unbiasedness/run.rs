//! The analysis of `unbiasedness`: runs the parts after the first (the first is the experiment's
//! own sweep, already run by the harness) into the same results folder (resumable cells), adds their
//! summary rows, tests and skipped pairs to the report, builds the table of every part, writes
//! `unbiasedness.csv` and `unbiasedness.md`, and adds the per-row and per-control claims.
//!
//! Overrides: `--seed` applies to every part; `--reps R` (which sets the first part's repetitions)
//! applies to every part when it differs from the first part's default; `--config` changes the
//! first part only. `--threads` is honoured through the run's thread count (`meta.threads`).

use super::rounds::{self, Entry};
use super::table;
use super::{parts, Row};
use crate::analysis::{TestRow, UNBIASEDNESS_ALPHA};
use crate::config::{Repetitions, Sweep};
use crate::error::Result;
use crate::output::RunReport;
use crate::plan::Plan;
use crate::registry::PostContext;
use crate::registry::Registry;
use crate::run::cell::CellResult;
use crate::run::runner::{self, RunResults};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The seed of a part's pilot: independent streams for the same pairs, cells and repetitions.
pub fn pilot_seed(seed: u64) -> u64 {
    seed ^ 0x5049_4c4f_545f_5345
}

/// The tests of one cell at the family-wise level `alpha`, behind the gate of its pilot cell (the
/// same pair on [`pilot_seed`]), with the row's exemption and whether it can pass at all (not when
/// judged against a stored reference made by its own sampling).
pub(crate) fn judge_cell(
    plan: &Plan,
    (bi, ei): (usize, usize),
    cell: &CellResult,
    pilot_cell: &CellResult,
    registry: &Registry,
    alpha: f64,
) -> (Vec<TestRow>, Option<&'static str>, bool) {
    let bed = plan.beds[bi].bed.as_ref();
    let bias = plan.estimators[ei].bias();
    let group = crate::analysis::Gate::group_of(plan.estimators[ei].estimator.as_ref(), bed);
    let gate = crate::analysis::Gate::from_cell(pilot_cell, "pilot", 1.0).with_group(group);
    let mut tests =
        crate::analysis::unbiasedness_at(cell, bed.reference(), bias, Some(&gate), plan.sweep.tolerance(), alpha);
    let mut can_pass = true;
    if let mcbench_core::testbed::ReferenceKind::Stored { command, .. } = &bed.reference().kind {
        if made_by(command, &plan.estimators[ei].spec.id) {
            judged_against_itself(&mut tests, command);
            can_pass = false;
        }
    }
    let exempt = exemption(registry, &plan.estimators[ei].spec.id, &cell.key.testbed, &cell.key.variant);
    (tests, exempt, can_pass)
}

/// Replaces a cell's tests in the report (the harness already added the first part's, gated by
/// nothing) with `tests`.
fn replace_tests(report: &mut RunReport, cell: &CellResult, tests: Vec<TestRow>) {
    report.tests.retain(|t| {
        !(t.estimator == cell.key.estimator
            && t.testbed == cell.key.testbed
            && t.variant == cell.key.variant
            && t.budget == cell.key.budget.amount)
    });
    report.tests.extend(tests);
}

/// The rows of a finished plan's cells, each tested behind the gate of its pilot cell, and their
/// tests added to the report.
fn rows_of(plan: &Plan, run: &RunResults, pilot: &RunResults, report: &mut RunReport, registry: &Registry) -> Vec<Row> {
    let mut rows = Vec::new();
    for ((bi, ei, cell), (_, _, pilot_cell)) in run.cells.iter().zip(&pilot.cells) {
        let (tests, exempt, _) = judge_cell(plan, (*bi, *ei), cell, pilot_cell, registry, UNBIASEDNESS_ALPHA);
        rows.push(table::row_from_tests(cell, plan.estimators[*ei].bias(), &tests, exempt));
        replace_tests(report, cell, tests);
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
/// label for the notes and its fixed-mode repetitions. In the rounds mode (`first.repetitions`)
/// the first part's fixed-mode repetitions are the ones its mode records, and every part runs
/// its first round ([`rounds::first_round`]).
fn other_parts(registry: &Registry, first: &Sweep) -> Vec<(String, Sweep, usize)> {
    let all = parts(registry, first.mode);
    let Some(default_reps) = all.first().map(|p| p.sweep.reps) else { return Vec::new() };
    let first_fixed = match first.repetitions {
        Repetitions::Fixed => first.reps,
        Repetitions::Rounds { fixed_reps, .. } => fixed_reps,
    };
    let reps_override = (first_fixed != default_reps).then_some(first_fixed);
    all.into_iter()
        .skip(1)
        .map(|part| {
            let mut sweep = part.sweep;
            sweep.seed = first.seed;
            sweep.repetitions = first.repetitions;
            if let Some(r) = reps_override {
                sweep.reps = r;
            }
            let fixed = sweep.reps;
            if !first.repetitions.is_fixed() {
                sweep.reps = rounds::first_round(fixed);
            }
            let bed = sweep.testbeds.first().map(|t| t.id.clone()).unwrap_or_default();
            (format!("part {bed}... ({} spp, {} reps)", part.samples, sweep.reps), sweep, fixed)
        })
        .collect()
}

/// Checks, before the run writes anything, every stored cell the other parts will read back.
pub fn preflight(registry: &Registry, first: &Sweep, cells: &Path) -> Result<()> {
    let store = crate::store::Store::open(cells)?;
    let parts = other_parts(registry, first).into_iter().map(|(_, s, _)| s);
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

/// One plan of a part as it ran: its plan, its cells, its pilot cells (the plan on the pilot
/// seed) and the part's fixed-mode repetitions.
struct Ran {
    plan: Plan,
    run: RunResults,
    pilot: RunResults,
    fixed: usize,
}

/// A part after the first: the rows of its pairs that could not run, and its plans as they ran.
type PartRun = (Vec<Row>, Vec<Ran>);

/// Runs the pilots, the other parts and writes the table (see the module docs).
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { plan, results: run, report, out: results, registry, .. } = cx;
    let threads = report.meta.threads;
    let cells = || results.join(crate::store::CELLS);
    let first_pilot_plan = Plan::prepare(pilot_of(&plan.sweep), registry)?;
    let first_pilot = runner::run_stored(&first_pilot_plan, cells(), threads)?;
    let first_bed = plan.sweep.testbeds.first().map(|t| t.id.clone()).unwrap_or_default();
    let mut notes = vec![format!("part {first_bed}... ({} reps)", plan.sweep.reps)];
    let mut others: Vec<PartRun> = Vec::new();
    for (label, sweep, fixed) in other_parts(registry, &plan.sweep) {
        let t0 = Instant::now();
        let (plans, invalid) = prepare_valid(sweep, registry)?;
        let mut ran = Vec::new();
        for p in plans {
            let pilot_plan = Plan::prepare(pilot_of(&p.sweep), registry)?;
            let pilot = runner::run_stored(&pilot_plan, cells(), threads)?;
            let r = runner::run_stored(&p, cells(), threads)?;
            report.skipped.extend(p.skipped.iter().cloned());
            for e in &p.estimators {
                if !report.labels.iter().any(|(n, _)| n == &e.name) {
                    report.labels.push((e.name.clone(), e.entry.label.to_string()));
                }
            }
            ran.push(Ran { plan: p, run: r, pilot, fixed });
        }
        others.push((invalid, ran));
        notes.push(format!("{label} {:.1} s", t0.elapsed().as_secs_f64()));
    }
    let rows = match plan.sweep.repetitions {
        Repetitions::Fixed => {
            let mut all = rows_of(plan, run, &first_pilot, report, registry);
            for (invalid, ran) in others {
                all.extend(invalid);
                for r in &ran {
                    for (bi, ei, cell) in &r.run.cells {
                        report.rows.push(r.plan.summary_row(*bi, *ei, cell));
                    }
                    all.extend(rows_of(&r.plan, &r.run, &r.pilot, report, registry));
                }
            }
            all
        }
        Repetitions::Rounds { fixed_reps, .. } => {
            let first = (&first_pilot, fixed_reps);
            in_rounds(plan, run, first, others, report, registry, &mut notes)?
        }
    };
    let pilot_size =
        if plan.sweep.repetitions.is_fixed() { "as many repetitions" } else { "its first round's repetitions" };
    report.meta.notes.push(format!(
        "unbiasedness parts (each with a pilot of {pilot_size} on seed {}): {}",
        pilot_seed(plan.sweep.seed),
        notes.join(", ")
    ));
    let left_out = super::full_only(registry);
    if plan.sweep.mode == crate::config::Mode::Quick && !left_out.is_empty() {
        report.meta.notes.push(format!(
            "unbiasedness cases in the full mode only (no row of them decides at a quick size; book: unbiasedness.md): {}",
            left_out.join(", ")
        ));
    }
    table::write_csv(results, "unbiasedness.csv", &rows)?;
    let md = table::markdown(&rows);
    results.write("unbiasedness.md", md.as_bytes())?;
    report.paper.extend(table::claims(&rows));
    Ok(Vec::new())
}

/// The rounds mode ([`rounds`]): every row of every part from its first round (`first`: the first
/// part's pilot cells and fixed-mode repetitions), grown until decided or the budget (the sweep's
/// share of the fixed mode's work, [`rounds::budget`]) is spent; the table in the fixed mode's
/// order, the report's summary rows and tests the rows' last looks.
fn in_rounds(
    plan: &Plan,
    run: &RunResults,
    first: (&RunResults, usize),
    others: Vec<PartRun>,
    report: &mut RunReport,
    registry: &Registry,
    notes: &mut Vec<String>,
) -> Result<Vec<Row>> {
    let alpha = rounds::look_alpha();
    let (first_pilot, first_fixed) = first;
    let mut entries = Vec::new();
    push_entries(&mut entries, plan, &run.cells, &first_pilot.cells, first_fixed);
    let mut others = others;
    let invalids: Vec<Vec<Row>> = others.iter_mut().map(|(invalid, _)| std::mem::take(invalid)).collect();
    // Each part's rows that could not run go before the entry at this index, as in the fixed mode.
    let mut invalid_before: Vec<(usize, Vec<Row>)> = Vec::new();
    for ((_, ran), invalid) in others.iter().zip(invalids) {
        invalid_before.push((entries.len(), invalid));
        for r in ran {
            push_entries(&mut entries, &r.plan, &r.run.cells, &r.pilot.cells, r.fixed);
        }
    }
    // A look: the entry's tests at the level of a look, whether it stays open, what it needs.
    let look = |e: &mut Entry<'_>| {
        let (tests, exempt, can_pass) = judge_cell(e.plan, (e.bi, e.ei), &e.cell, &e.pilot, registry, alpha);
        e.control = e.plan.estimators[e.ei].bias() == mcbench_core::estimator::Bias::Biased && exempt.is_none();
        e.open = rounds::stays_open(&tests, e.cell.key.reps, e.looks, can_pass, e.control);
        e.needed = rounds::needed(&tests);
    };
    entries.iter_mut().for_each(&look);
    let fixed_work: u64 = entries.iter().map(Entry::fixed_cost).sum();
    let share = plan.sweep.repetitions.budget_share();
    let budget = rounds::budget(fixed_work, share);
    let t0 = Instant::now();
    let extra = rounds::grow(&mut entries, budget, report.meta.threads, |e| {
        look(e);
        Ok(())
    })?;
    let spent: u64 = entries.iter().map(Entry::spent).sum();
    let of = if share == 1.0 {
        format!("of the fixed mode's {budget}")
    } else {
        format!("of the budget {budget} (share {share} of the fixed mode's {fixed_work})")
    };
    notes.push(format!(
        "rounds: {extra} after the first, {:.1} s, work {spent} {of} (repetitions x integrals x samples, cells and pilots)",
        t0.elapsed().as_secs_f64()
    ));
    let mut rows = Vec::new();
    let mut invalid_before = invalid_before.into_iter().peekable();
    for (i, e) in entries.iter().enumerate() {
        while let Some((_, invalid)) = invalid_before.next_if(|(at, _)| *at == i) {
            rows.extend(invalid);
        }
        let (tests, exempt, _) = judge_cell(e.plan, (e.bi, e.ei), &e.cell, &e.pilot, registry, alpha);
        let mut row = table::row_from_tests(&e.cell, e.plan.estimators[e.ei].bias(), &tests, exempt);
        row.repetitions = "rounds".into();
        row.rounds = e.looks;
        rows.push(row);
        replace_tests(report, &e.cell, tests);
        let summary = e.plan.summary_row(e.bi, e.ei, &e.cell);
        let same = |s: &crate::analysis::metrics::SummaryRow| {
            s.estimator == summary.estimator
                && s.testbed == summary.testbed
                && s.variant == summary.variant
                && s.budget == summary.budget
        };
        match report.rows.iter_mut().find(|s| same(s)) {
            Some(slot) => *slot = summary,
            None => report.rows.push(summary),
        }
    }
    for (_, invalid) in invalid_before {
        rows.extend(invalid);
    }
    Ok(rows)
}

/// The entries of one plan's cells and their pilots, at their first round.
fn push_entries<'p>(
    entries: &mut Vec<Entry<'p>>,
    plan: &'p Plan,
    cells: &[(usize, usize, CellResult)],
    pilots: &[(usize, usize, CellResult)],
    fixed: usize,
) {
    for ((bi, ei, cell), (_, _, pilot)) in cells.iter().zip(pilots) {
        entries.push(Entry {
            plan,
            bi: *bi,
            ei: *ei,
            fixed,
            cell: cell.clone(),
            pilot: pilot.clone(),
            looks: 1,
            open: false,
            needed: None,
            control: false,
        });
    }
}

//! Executing a [`Plan`]: every cell's repetitions in parallel (rayon) in fixed batches, each
//! estimate on its own counter-derived stream, reduced in index order so results are bit-identical
//! whatever the thread count; the cells of one (test bed, budget) run interleaved
//! ([`crate::run::interleave`]) so that machine load falls on the estimators they compare alike; each
//! estimate's wall and CPU time are measured ([`crate::run::cputime`]); finished cells are stored and read back on a re-run
//! (resume).

use crate::error::{HarnessError, Result};
use crate::plan::Plan;
use crate::run::cell::{add_diagnostics, CellKey, CellResult, TimeStats};
use crate::run::interleave::empty_cell;
pub use crate::run::interleave::{run_group_at, run_group_with, GroupCell};
pub use crate::run::resume::{preload, preload_from};
use crate::store::StoreWriter;
use mcbench_core::budget::{Budget, BudgetKind};
use mcbench_core::error::EstimateError;
use mcbench_core::math::Rgb;
use mcbench_core::rng::StreamKey;
use mcbench_core::task::{Costs, Task};
use std::path::PathBuf;
use std::time::Instant;

/// Receives progress (no-op by default): the CLI draws bars from it.
///
/// ```
/// use mcbench::run::runner::Observer;
/// use std::sync::atomic::{AtomicUsize, Ordering};
///
/// /// Counts the cells a run computed (not the ones it read back).
/// #[derive(Default)]
/// struct Computed(AtomicUsize);
/// impl Observer for Computed {
///     fn cell_done(&self, _done: usize, _total: usize, _label: &str, resumed: bool) {
///         if !resumed {
///             self.0.fetch_add(1, Ordering::Relaxed);
///         }
///     }
/// }
///
/// let seen = Computed::default();
/// seen.cell_done(1, 2, "gradient-plane/default is0_cv0 samples=4", false);
/// seen.cell_done(2, 2, "gradient-plane/default is0_cv0 samples=16", true);
/// assert_eq!(seen.0.load(Ordering::Relaxed), 1);
/// ```
pub trait Observer: Sync {
    /// A cell finished (`resumed` when it was read back from disk).
    fn cell_done(&self, _done: usize, _total: usize, _label: &str, _resumed: bool) {}
}

/// The silent observer.
pub struct Silent;
impl Observer for Silent {}

/// Run options.
pub struct RunOptions<'a> {
    /// Worker threads (None: rayon's default).
    pub threads: Option<usize>,
    /// The cell store finished cells are read back from and appended to for resume
    /// (`<results>/<experiment>/cells.store`, [`crate::store`]; None: no resume store).
    pub store: Option<PathBuf>,
    /// Progress receiver.
    pub observer: &'a dyn Observer,
}

/// The finished cells of a plan, in (pair, budget) order.
pub struct RunResults {
    /// Cells with their (bed index, estimator index).
    pub cells: Vec<(usize, usize, CellResult)>,
}

/// What one work item (one or more sequences of one repetition) produced.
#[derive(Default)]
pub(crate) struct Item {
    pub(crate) values: Vec<Rgb>,
    pub(crate) costs: Costs,
    /// Wall-clock seconds per estimate.
    pub(crate) time: TimeStats,
    /// The estimating thread's CPU seconds per estimate, filled by [`Item::settle`].
    pub(crate) cpu_time: TimeStats,
    pub(crate) diagnostics: Vec<(String, f64)>,
    /// Each sequence's wall-clock seconds per estimate and its estimates, until the item's CPU
    /// fraction is known.
    unsettled: Vec<(f64, usize)>,
}

impl Item {
    /// Charges each estimate run since the last call its wall-clock seconds times `cpu_fraction`
    /// (the item's CPU seconds over its wall-clock seconds, [`crate::run::cputime`]) as CPU time.
    pub(crate) fn settle(&mut self, cpu_fraction: f64) {
        for (seconds, n) in self.unsettled.drain(..) {
            for _ in 0..n {
                self.cpu_time.push(seconds * cpu_fraction);
            }
        }
    }
}

/// Runs the sequences `sequences` (each `frames` integrals) of repetition `rep` as one work item:
/// [`run_sequence`] for each, with the thread CPU clock read once at each end of the item and its
/// CPU time apportioned over the estimates by their wall-clock times ([`crate::run::cputime`]).
pub(crate) fn run_item(cell: &CellRun<'_>, rep: u64, sequences: std::ops::Range<usize>, frames: usize) -> Result<Item> {
    let mut out = Item::default();
    let clock = crate::run::cputime::ItemClock::start();
    for s in sequences {
        run_sequence(cell, rep, s * frames, &mut out)?;
    }
    out.settle(clock.cpu_fraction());
    Ok(out)
}

/// Repetition index of the pilot stream that calibrates fetch budgets (never a real repetition).
pub(crate) const PILOT_REP: u64 = u64::MAX;

/// The seed of the pilot stream, whatever the run's seed (the suite's default seed, so that runs
/// at the default seed are what they were before the pilot had a seed of its own). The sample
/// count a fetch budget buys is part of the experiment's design: drawn from the run's seed, it
/// changed from seed to seed (delta tracking on the Eq. 21 image at 10 fetches took a mean of 1.81
/// samples per pixel in 29 of 32 seeds and 1.0 in the other three, doubling its MSE there), so runs at different
/// seeds measured different designs and no interval from one run's repetitions could cover that.
pub(crate) const PILOT_SEED: u64 = 1;

/// One cell's fixed inputs: which pair, which budget, and the sample count a fetch budget became.
pub(crate) struct CellRun<'a> {
    pub(crate) plan: &'a Plan,
    /// The test bed's label (stream key and error messages), formatted once per cell rather than
    /// once per sequence (it was a third of the harness's own work per estimate).
    pub(crate) label: &'a str,
    pub(crate) bi: usize,
    pub(crate) ei: usize,
    pub(crate) budget: Budget,
    /// A fetch budget converted into a fixed sample count ([`Task::with_samples`]).
    pub(crate) samples: Option<u64>,
}

/// One sequence of integrals (`frames` long, from integral `first`) estimated on its own stream;
/// its wall-clock time is split evenly over its estimates, and so is its CPU time once the item's
/// CPU fraction is known ([`Item::settle`]; the thread CPU clock does not advance while the thread
/// waits for a core or sleeps).
pub(crate) fn run_sequence(cell: &CellRun<'_>, rep: u64, first: usize, out: &mut Item) -> Result<()> {
    let CellRun { plan, label, bi, ei, budget, samples } = *cell;
    let (b, e) = (&plan.beds[bi], &plan.estimators[ei]);
    let frames = b.bed.sequence_length().max(1);
    let key = StreamKey {
        seed: if rep == PILOT_REP { PILOT_SEED } else { plan.sweep.seed },
        testbed: label,
        estimator: &e.name,
        budget: budget.amount,
        rep,
        integral: first as u64,
    };
    let mut rng = key.rng();
    let task = |i| match samples {
        Some(n) => Task::with_samples(b.bed.as_ref(), i, budget, n),
        None => Task::new(b.bed.as_ref(), i, budget),
    };
    let tasks: Vec<Task<'_>> = (first..first + frames).map(task).collect();
    let t0 = Instant::now();
    let values = e.estimator.estimate_sequence(&tasks, &mut rng);
    let seconds = t0.elapsed().as_secs_f64() / frames as f64;
    let wrap = |source| HarnessError::Estimate { estimator: e.name.clone(), testbed: label.to_string(), source };
    let values = values.map_err(wrap)?;
    if values.len() != frames {
        let msg = format!("estimate_sequence returned {} values for {frames} integrals", values.len());
        return Err(wrap(EstimateError::Refused(msg)));
    }
    for (k, (v, task)) in values.into_iter().zip(&tasks).enumerate() {
        if !v.is_finite() {
            return Err(wrap(EstimateError::NonFinite { integral: first + k, value: v.0 }));
        }
        if let Some(n) = samples {
            task.note("samples_per_estimate", n as f64);
        }
        out.time.push(seconds);
        out.costs += task.costs();
        add_diagnostics(&mut out.diagnostics, &task.diagnostics());
        out.values.push(v);
    }
    out.unsettled.push((seconds, frames));
    Ok(())
}

/// The estimates of repetition `rep` for the sequence starting at integral `first`, exactly as a
/// run of a sample-budget cell computes them (same stream, same tasks): for analyses that need
/// per-repetition values the cells do not keep (the per-seed estimates of the `calibration`
/// experiment, [`crate::calibration`]).
pub fn sequence_estimates(
    plan: &Plan,
    bi: usize,
    ei: usize,
    budget: Budget,
    rep: u64,
    first: usize,
) -> Result<Vec<Rgb>> {
    let label = plan.beds[bi].label();
    let cell = CellRun { plan, label: &label, bi, ei, budget, samples: None };
    let mut out = Item::default();
    run_sequence(&cell, rep, first, &mut out)?;
    Ok(out.values)
}

/// Repetitions per block. A cell's repetitions are reduced block by block (Welford pushes in
/// repetition order inside a block, [`Moments::merge`](mcbench_core::stats::Moments::merge) of the
/// blocks in block order), so the block is the unit a shard (`--shard i/n`) can own: the split is
/// fixed by the sweep's `reps` alone, never by the thread or shard count, and a merge of shards
/// reproduces a single run bit for bit.
/// A cell of at most `REP_BLOCK` repetitions is one block, reduced exactly as before blocks existed.
pub const REP_BLOCK: usize = 16;

/// The number of repetition blocks of a sweep with `reps` repetitions.
pub fn rep_blocks(reps: usize) -> usize {
    reps.div_ceil(REP_BLOCK)
}

/// Runs one cell (no resume logic): every repetition block, merged in block order as it finishes.
pub fn run_cell(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<CellResult> {
    let blocks: Vec<usize> = (0..rep_blocks(plan.sweep.reps)).collect();
    let key = cell_key(plan, bi, ei, budget);
    let mut out = empty_cell(key, plan.beds[bi].bed.integrals());
    run_blocks_with(plan, bi, ei, budget, &blocks, |_, part| {
        merge_into(&mut out, &part);
        Ok(())
    })?;
    Ok(out)
}

/// Runs the given repetition blocks of one cell and returns each block's sufficient statistics
/// (see [`run_blocks_with`]), in the order given.
pub fn run_blocks(plan: &Plan, bi: usize, ei: usize, budget: Budget, blocks: &[usize]) -> Result<Vec<CellResult>> {
    let mut parts = Vec::with_capacity(blocks.len());
    run_blocks_with(plan, bi, ei, budget, blocks, |_, part| {
        parts.push(part);
        Ok(())
    })?;
    Ok(parts)
}

/// The sample count a budget becomes before a cell runs: a fetch or time budget is calibrated
/// by a pilot ([`crate::plan::budget_pilot`]); a sample budget is used
/// as it is (`None`).
pub(crate) fn calibrated_samples(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<Option<u64>> {
    Ok(match budget.kind {
        BudgetKind::Fetches => Some(crate::plan::budget_pilot::samples_for_fetch_budget(plan, bi, ei, budget)?),
        BudgetKind::Micros => Some(crate::plan::budget_pilot::samples_for_time_budget(plan, bi, ei, budget)?),
        BudgetKind::Samples => None,
    })
}

/// Runs the given repetition blocks of one cell and hands each block's sufficient statistics
/// (a [`CellResult`] over that block's repetitions, keyed by the whole cell) to `sink` with its
/// position in `blocks`, in that order, as soon as it is reduced: [`run_group_with`] with this one
/// cell.
pub fn run_blocks_with(
    plan: &Plan,
    bi: usize,
    ei: usize,
    budget: Budget,
    blocks: &[usize],
    mut sink: impl FnMut(usize, CellResult) -> Result<()>,
) -> Result<()> {
    run_group_with(plan, bi, budget, &[GroupCell { ei, blocks }], |_, pos, part| sink(pos, part))
}

/// Adds one block's statistics into a cell's (blocks must come in block order for a
/// bit-reproducible result).
fn merge_into(out: &mut CellResult, p: &CellResult) {
    if out.moments.is_empty() {
        out.moments = p.moments.iter().map(|_| Default::default()).collect();
    }
    for (m, pm) in out.moments.iter_mut().zip(&p.moments) {
        for c in 0..3 {
            m[c].merge(&pm[c]);
        }
    }
    out.estimates += p.estimates;
    out.costs += p.costs;
    out.time.merge(&p.time);
    out.merge_cpu_time(p);
    add_diagnostics(&mut out.diagnostics, &p.diagnostics);
    out.rep_dev.merge(&p.rep_dev);
    out.rep_sq.merge(&p.rep_sq);
    out.merge_blocks(p);
}

/// Merges the blocks of one cell, in the order given (block order for a bit-reproducible result),
/// into the cell's statistics under `key`.
pub fn merge_blocks(key: CellKey, parts: &[CellResult]) -> CellResult {
    let n = parts.first().map_or(0, |p| p.moments.len());
    let mut out = empty_cell(key, n);
    for p in parts {
        merge_into(&mut out, p);
    }
    out
}

/// The key of a cell.
pub fn cell_key(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> CellKey {
    let b = &plan.beds[bi];
    CellKey {
        testbed: b.spec.id.clone(),
        variant: b.variant.clone(),
        testbed_params: serde_json::to_string(&b.spec.params).unwrap_or_default(),
        estimator: plan.estimators[ei].name.clone(),
        budget,
        reps: plan.sweep.reps,
        seed: plan.sweep.seed,
        version: env!("CARGO_PKG_VERSION").to_string(),
    }
}

/// Runs `plan`'s cells on `threads` threads with progress on a terminal, reading back and storing
/// cells in the cell store `store`: the further sweeps an experiment's analysis runs into its
/// results folder (whose lock the caller holds).
pub fn run_stored(plan: &Plan, store: PathBuf, threads: usize) -> Result<RunResults> {
    let progress = crate::run::progress::Progress::default();
    let r = run(plan, &RunOptions { threads: Some(threads), store: Some(store), observer: &progress });
    progress.finish();
    r
}

/// Runs every cell of the plan, reading back stored cells (checked first, [`preload`]) and
/// storing new ones.
pub fn run(plan: &Plan, opts: &RunOptions<'_>) -> Result<RunResults> {
    let stored = preload(plan, opts.store.as_deref())?;
    run_preloaded(plan, opts, stored)
}

/// [`run`] with the stored cells already read by [`preload`]. The missing cells of one (test bed,
/// budget) run together, interleaved ([`run_group_with`]); each is appended to the store as soon as
/// its group has finished (the store is opened for writing at the first cell to store, so a run
/// that computes nothing leaves it untouched), and the observer hears of a group's cells (in plan
/// order) when the group is done.
pub fn run_preloaded(plan: &Plan, opts: &RunOptions<'_>, stored: Vec<Option<CellResult>>) -> Result<RunResults> {
    let _phase = crate::run::phases::enter(crate::run::phases::Phase::Cells);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| HarnessError::write("thread pool", e))?;
    let budgets = plan.sweep.budgets.len();
    let total = plan.pairs.len() * budgets;
    let mut slots: Vec<Option<CellResult>> = stored;
    slots.resize_with(total, || None);
    let resumed: Vec<bool> = slots.iter().map(Option::is_some).collect();
    let all_blocks: Vec<usize> = (0..rep_blocks(plan.sweep.reps)).collect();
    let mut beds: Vec<usize> = Vec::new();
    for &(bi, _) in &plan.pairs {
        if !beds.contains(&bi) {
            beds.push(bi);
        }
    }
    let mut done = 0;
    let mut writer: Option<StoreWriter> = None;
    for &bi in &beds {
        let pairs: Vec<usize> = (0..plan.pairs.len()).filter(|&p| plan.pairs[p].0 == bi).collect();
        for (bu, &budget) in plan.sweep.budgets.iter().enumerate() {
            let missing: Vec<usize> = pairs.iter().copied().filter(|&p| slots[p * budgets + bu].is_none()).collect();
            let group: Vec<GroupCell<'_>> =
                missing.iter().map(|&p| GroupCell { ei: plan.pairs[p].1, blocks: &all_blocks }).collect();
            let mut outs: Vec<CellResult> = missing
                .iter()
                .map(|&p| empty_cell(cell_key(plan, bi, plan.pairs[p].1, budget), plan.beds[bi].bed.integrals()))
                .collect();
            pool.install(|| {
                run_group_with(plan, bi, budget, &group, |k, _, part| {
                    merge_into(&mut outs[k], &part);
                    Ok(())
                })
            })?;
            for (&p, c) in missing.iter().zip(outs) {
                if let Some(path) = &opts.store {
                    if writer.is_none() {
                        writer = Some(StoreWriter::open(path)?);
                    }
                    if let Some(w) = writer.as_mut() {
                        w.append(&c.key.name(), &crate::store::packed::encode_cell(&c))?;
                    }
                }
                slots[p * budgets + bu] = Some(c);
            }
            for &p in &pairs {
                let label = format!(
                    "{} {} {}={}",
                    plan.beds[bi].label(),
                    plan.estimators[plan.pairs[p].1].name,
                    budget.kind.name(),
                    budget.amount
                );
                done += 1;
                opts.observer.cell_done(done, total, &label, resumed[p * budgets + bu]);
            }
        }
    }
    let mut cells = Vec::with_capacity(total);
    for (c, slot) in slots.into_iter().enumerate() {
        let (bi, ei) = plan.pairs[c / budgets];
        let cell = slot.ok_or_else(|| HarnessError::Failed("a cell of the plan was not run".into()))?;
        cells.push((bi, ei, cell));
    }
    Ok(RunResults { cells })
}

//! Executing a [`Plan`]: every cell's repetitions in parallel (rayon) in fixed batches, each
//! estimate on its own counter-derived stream, reduced in index order so results are bit-identical
//! whatever the thread count; finished cells are stored and read back on a re-run (resume).

use crate::cell::{add_diagnostics, CellKey, CellResult, TimeStats};
use crate::error::{HarnessError, Result};
use crate::output::write_atomic;
use crate::plan::Plan;
use estimators::budget::{Budget, BudgetKind};
use estimators::error::EstimateError;
use estimators::math::Rgb;
use estimators::rng::StreamKey;
use estimators::stats::Moments;
use estimators::task::{Costs, Task, FETCH_BUDGET_SAMPLE_CAP};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Integrals per work item: small enough to balance, large enough to amortise scheduling.
const BATCH: usize = 16;

/// Receives progress (no-op by default): the CLI draws bars from it.
///
/// ```
/// use mcbench::runner::Observer;
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
    /// Where finished cells are stored for resume (None: no resume store).
    pub cell_dir: Option<PathBuf>,
    /// Progress receiver.
    pub observer: &'a dyn Observer,
}

/// The finished cells of a plan, in (pair, budget) order.
pub struct RunResults {
    /// Cells with their (bed index, estimator index).
    pub cells: Vec<(usize, usize, CellResult)>,
}

#[derive(Default)]
struct Item {
    values: Vec<Rgb>,
    costs: Costs,
    /// Wall-clock seconds per estimate.
    time: TimeStats,
    /// The estimating thread's CPU seconds per estimate.
    cpu_time: TimeStats,
    diagnostics: Vec<(String, f64)>,
}

fn add(a: &mut Costs, b: &Costs) {
    a.samples += b.samples;
    a.fetches += b.fetches;
    a.cheap_fetches += b.cheap_fetches;
    a.rays += b.rays;
}

/// Repetition index of the pilot stream that calibrates fetch budgets (never a real repetition).
const PILOT_REP: u64 = u64::MAX;
/// At most this many sequences (spread evenly over the test bed) run in a fetch-budget pilot.
const PILOT_SEQUENCES: usize = 64;

/// One cell's fixed inputs: which pair, which budget, and the sample count a fetch budget became.
struct CellRun<'a> {
    plan: &'a Plan,
    /// The test bed's label (stream key and error messages), formatted once per cell rather than
    /// once per sequence (it was a third of the harness's own work per estimate).
    label: &'a str,
    bi: usize,
    ei: usize,
    budget: Budget,
    /// A fetch budget converted into a fixed sample count ([`Task::with_samples`]).
    samples: Option<u64>,
}

/// One sequence of integrals (`frames` long, from integral `first`) estimated on its own stream;
/// its wall-clock and CPU time (the calling thread's clock, which does not advance while the thread
/// waits for a core or sleeps) are split evenly over its estimates.
fn run_sequence(cell: &CellRun<'_>, rep: u64, first: usize, out: &mut Item) -> Result<()> {
    let CellRun { plan, label, bi, ei, budget, samples } = *cell;
    let (b, e) = (&plan.beds[bi], &plan.estimators[ei]);
    let frames = b.bed.sequence_length().max(1);
    let key = StreamKey {
        seed: plan.sweep.seed,
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
    let (t0, c0) = (Instant::now(), crate::cputime::thread_seconds());
    let values = e.estimator.estimate_sequence(&tasks, &mut rng);
    let seconds = t0.elapsed().as_secs_f64() / frames as f64;
    let cpu_seconds = (crate::cputime::thread_seconds() - c0).max(0.0) / frames as f64;
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
        out.cpu_time.push(cpu_seconds);
        add(&mut out.costs, &task.costs());
        add_diagnostics(&mut out.diagnostics, &task.diagnostics());
        out.values.push(v);
    }
    Ok(())
}

/// The estimates of repetition `rep` for the sequence starting at integral `first`, exactly as a
/// run of a sample-budget cell computes them (same stream, same tasks): for analyses that need
/// per-repetition values the cells do not keep (`suite::unbiasedness_reps`).
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

/// The fixed number of samples per estimate that a fetch budget buys (paper 002 compares
/// estimators at equal fetches per pixel). Stopping each estimate when its fetches run out would
/// bias it ([`Task::with_samples`]), so a pilot pass on its own stream (repetition [`PILOT_REP`],
/// up to [`PILOT_SEQUENCES`] sequences spread over the test bed) runs with that stopping rule, and
/// `n = round(budget x pilot samples / pilot fetches)` over the pilot sequences that fetched at all,
/// the same for every integral and repetition, as a renderer sets one spp for the whole image. The
/// reported costs are the fetches the estimates really spent (pixels whose rays miss the medium
/// spend none, so the image's mean is below the budget).
fn samples_for_fetch_budget(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<u64> {
    let b = &plan.beds[bi];
    let frames = b.bed.sequence_length().max(1);
    let sequences = b.bed.integrals() / frames;
    let picks = sequences.min(PILOT_SEQUENCES);
    let label = b.label();
    let pilot = CellRun { plan, label: &label, bi, ei, budget, samples: None };
    let pilots: Vec<Result<Item>> = (0..picks)
        .into_par_iter()
        .map(|k| {
            let mut out = Item::default();
            run_sequence(&pilot, PILOT_REP, k * sequences / picks * frames, &mut out)?;
            Ok(out)
        })
        .collect();
    // Sequences that fetch nothing (their rays miss the medium) ran into the sample cap; they say
    // nothing about what a fetch costs in samples, and every estimate there is free anyway.
    let mut costs = Costs::default();
    for p in pilots {
        let p = p?;
        if p.costs.fetches > 0 {
            add(&mut costs, &p.costs);
        }
    }
    let cap = budget.amount.saturating_mul(FETCH_BUDGET_SAMPLE_CAP);
    if costs.fetches == 0 {
        return Ok(cap);
    }
    let n = (budget.amount as f64 * costs.samples as f64 / costs.fetches as f64).round();
    Ok((n as u64).clamp(1, cap))
}

/// The fixed number of samples per estimate that a time budget buys: a pilot on its own stream
/// (as for fetch budgets) runs the estimator until each pilot estimate's time is up, and
/// `n = budget x pilot samples / pilot CPU microseconds`. Stopping each real estimate when its time
/// runs out would make its sample count depend on the values drawn (slow paths and their values go
/// together); a count fixed in advance does not. The count depends on the machine, so a time budget
/// is the one setting whose results are not bit-reproducible (`meta.reproducible` says so).
fn samples_for_time_budget(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<u64> {
    let b = &plan.beds[bi];
    let frames = b.bed.sequence_length().max(1);
    let sequences = b.bed.integrals() / frames;
    let picks = sequences.min(PILOT_SEQUENCES);
    let label = b.label();
    let pilot = CellRun { plan, label: &label, bi, ei, budget, samples: None };
    let pilots: Vec<Result<(u64, f64)>> = (0..picks)
        .into_par_iter()
        .map(|k| {
            let mut out = Item::default();
            let t0 = crate::cputime::thread_seconds();
            run_sequence(&pilot, PILOT_REP, k * sequences / picks * frames, &mut out)?;
            Ok((out.costs.samples, crate::cputime::thread_seconds() - t0))
        })
        .collect();
    let (mut samples, mut seconds) = (0u64, 0.0f64);
    for p in pilots {
        let (n, s) = p?;
        samples += n;
        seconds += s;
    }
    let micros = (seconds * 1e6).max(1.0);
    let n = (budget.amount as f64 * samples as f64 / micros).round();
    Ok((n as u64).clamp(1, crate::limits::MAX_SAMPLES))
}

/// Repetitions per block. A cell's repetitions are reduced block by block (Welford pushes in
/// repetition order inside a block, [`Moments::merge`] of the blocks in block order), so the block
/// is the unit a shard (`--shard i/n`) can own: the split is fixed by the sweep's `reps` alone,
/// never by the thread or shard count, and a merge of shards reproduces a single run bit for bit.
/// A cell of at most `REP_BLOCK` repetitions is one block, reduced exactly as before blocks existed.
pub const REP_BLOCK: usize = 16;

/// At most this many work items (one repetition of one batch of integrals) are in flight at once:
/// blocks run a chunk at a time, so memory does not grow with the repetition count.
const MAX_ITEMS: usize = 8192;

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
/// by a pilot ([`samples_for_fetch_budget`], [`samples_for_time_budget`]); a sample budget is used
/// as it is (`None`).
fn calibrated_samples(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<Option<u64>> {
    Ok(match budget.kind {
        BudgetKind::Fetches => Some(samples_for_fetch_budget(plan, bi, ei, budget)?),
        BudgetKind::Micros => Some(samples_for_time_budget(plan, bi, ei, budget)?),
        BudgetKind::Samples => None,
    })
}

/// Runs the given repetition blocks of one cell and hands each block's sufficient statistics
/// (a [`CellResult`] over that block's repetitions, keyed by the whole cell) to `sink` with its
/// position in `blocks`, in that order, as soon as it is reduced; blocks run a chunk at a time so
/// that memory stays bounded whatever the repetition count.
/// Work items are whole sequences (test beds whose integrals come in frames,
/// [`estimators::testbed::TestBed::sequence_length`]), batched to about `BATCH` integrals; each
/// sequence draws from the stream of its first integral, so a static test bed (sequence length 1)
/// keeps exactly the per-integral streams and batches it always had. A fetch budget first becomes a
/// fixed sample count (`samples_for_fetch_budget`; its pilot is deterministic, so every shard
/// owning a block of the cell computes the same count).
pub fn run_blocks_with(
    plan: &Plan,
    bi: usize,
    ei: usize,
    budget: Budget,
    blocks: &[usize],
    mut sink: impl FnMut(usize, CellResult) -> Result<()>,
) -> Result<()> {
    let b = &plan.beds[bi];
    let n = b.bed.integrals();
    let frames = b.bed.sequence_length().max(1);
    let sequences = n / frames;
    let per_item = BATCH.div_ceil(frames);
    let reps = plan.sweep.reps;
    let batches = sequences.div_ceil(per_item);
    if blocks.is_empty() {
        return Ok(());
    }
    let samples = calibrated_samples(plan, bi, ei, budget)?;
    let label = b.label();
    let cell = CellRun { plan, label: &label, bi, ei, budget, samples };
    let key = cell_key(plan, bi, ei, budget);
    let per_chunk = (MAX_ITEMS / (REP_BLOCK * batches).max(1)).max(1);
    for (c, chunk) in blocks.chunks(per_chunk).enumerate() {
        // (position in `chunk`, repetition, batch), repetition-major inside each block.
        let work: Vec<(usize, usize, usize)> = chunk
            .iter()
            .enumerate()
            .flat_map(|(pos, &blk)| {
                (blk * REP_BLOCK..((blk + 1) * REP_BLOCK).min(reps))
                    .flat_map(move |rep| (0..batches).map(move |batch| (pos, rep, batch)))
            })
            .collect();
        let items: Vec<Result<Item>> = work
            .par_iter()
            .map(|&(_, rep, batch)| {
                let mut out = Item::default();
                for s in batch * per_item..((batch + 1) * per_item).min(sequences) {
                    run_sequence(&cell, rep as u64, s * frames, &mut out)?;
                }
                Ok(out)
            })
            .collect();
        let mut parts = vec![empty_cell(key.clone(), n); chunk.len()];
        let reference = &b.bed.reference().value;
        // Items come repetition by repetition (every batch of one repetition, then the next), so a
        // repetition's aggregates are complete when the next one starts.
        let mut rep_acc: Option<(usize, usize, RepAggregate)> = None;
        for (&(pos, rep, batch), r) in work.iter().zip(items) {
            let r = r?;
            if rep_acc.as_ref().is_some_and(|(p, q, _)| (*p, *q) != (pos, rep)) {
                if let Some((p, _, acc)) = rep_acc.take() {
                    acc.push_into(&mut parts[p]);
                }
            }
            let acc = &mut rep_acc.get_or_insert_with(|| (pos, rep, RepAggregate::default())).2;
            let part = &mut parts[pos];
            for (k, v) in r.values.iter().enumerate() {
                let i = batch * per_item * frames + k;
                for c in 0..3 {
                    part.moments[i][c].push(v[c]);
                    acc.add(v[c] - reference[i][c]);
                }
            }
            part.estimates += r.values.len() as u64;
            add(&mut part.costs, &r.costs);
            part.time.merge(&r.time);
            if let Some(t) = &mut part.cpu_time {
                t.merge(&r.cpu_time);
            }
            add_diagnostics(&mut part.diagnostics, &r.diagnostics);
        }
        if let Some((p, _, acc)) = rep_acc.take() {
            acc.push_into(&mut parts[p]);
        }
        for (k, part) in parts.into_iter().enumerate() {
            sink(c * per_chunk + k, part)?;
        }
    }
    Ok(())
}

/// One repetition's aggregates over every integral and channel, compensated: the summed deviation
/// from the reference and the sum of squared deviations.
#[derive(Default)]
struct RepAggregate {
    dev: estimators::stats::NeumaierSum,
    sq: estimators::stats::NeumaierSum,
    count: u64,
}

impl RepAggregate {
    fn add(&mut self, deviation: f64) {
        self.dev.add(deviation);
        self.sq.add(deviation * deviation);
        self.count += 1;
    }
    /// Adds the repetition to the cell's per-repetition statistics.
    fn push_into(self, cell: &mut CellResult) {
        cell.rep_dev.push(self.dev.value());
        cell.rep_sq.push(self.sq.value() / self.count.max(1) as f64);
    }
}

/// A cell of `n` integrals with no estimates yet.
fn empty_cell(key: CellKey, n: usize) -> CellResult {
    CellResult {
        key,
        moments: vec![[Moments::default(), Moments::default(), Moments::default()]; n],
        costs: Costs::default(),
        estimates: 0,
        time: TimeStats::default(),
        cpu_time: Some(TimeStats::default()),
        diagnostics: Vec::new(),
        rep_dev: Moments::default(),
        rep_sq: Moments::default(),
    }
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
    add(&mut out.costs, &p.costs);
    out.time.merge(&p.time);
    out.merge_cpu_time(p);
    add_diagnostics(&mut out.diagnostics, &p.diagnostics);
    out.rep_dev.merge(&p.rep_dev);
    out.rep_sq.merge(&p.rep_sq);
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

/// Reads a stored cell back: `None` when absent; a file that does not parse, holds another cell
/// or does not fit the plan (integrals, repetitions, finite statistics) is bad input naming the file.
pub(crate) fn read_cell(path: &Path, key: &CellKey, integrals: usize) -> Result<Option<CellResult>> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(HarnessError::bad_file(path, e)),
    };
    let refuse =
        |why: String| HarnessError::bad_file(path, format!("corrupt stored cell ({why}); delete it to recompute"));
    let cell: CellResult = serde_json::from_str(&text).map_err(|e| refuse(e.to_string()))?;
    if cell.key != *key {
        return Err(refuse("it holds another cell than its name says".into()));
    }
    cell.check_shape(integrals, key.reps).map_err(refuse)?;
    Ok(Some(cell))
}

/// The stored cells of a plan, in (pair, budget) order, read and checked before anything runs:
/// a corrupt cell is refused before any other cell is recomputed or written.
pub fn preload(plan: &Plan, cell_dir: Option<&Path>) -> Result<Vec<Option<CellResult>>> {
    let mut out = Vec::with_capacity(plan.pairs.len() * plan.sweep.budgets.len());
    for &(bi, ei) in &plan.pairs {
        for &budget in &plan.sweep.budgets {
            let key = cell_key(plan, bi, ei, budget);
            out.push(match cell_dir {
                Some(d) => read_cell(&d.join(key.file_name()), &key, plan.beds[bi].bed.integrals())?,
                None => None,
            });
        }
    }
    Ok(out)
}

/// Runs every cell of the plan, reading back stored cells (checked first, [`preload`]) and
/// storing new ones.
pub fn run(plan: &Plan, opts: &RunOptions<'_>) -> Result<RunResults> {
    let stored = preload(plan, opts.cell_dir.as_deref())?;
    run_preloaded(plan, opts, stored)
}

/// [`run`] with the stored cells already read by [`preload`].
pub fn run_preloaded(plan: &Plan, opts: &RunOptions<'_>, stored: Vec<Option<CellResult>>) -> Result<RunResults> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| HarnessError::write("thread pool", e))?;
    let total = plan.pairs.len() * plan.sweep.budgets.len();
    let mut cells = Vec::with_capacity(total);
    let mut stored = stored.into_iter();
    for &(bi, ei) in &plan.pairs {
        for &budget in &plan.sweep.budgets {
            let key = cell_key(plan, bi, ei, budget);
            let path = opts.cell_dir.as_ref().map(|d| d.join(key.file_name()));
            let found = stored.next().flatten();
            let resumed = found.is_some();
            let cell = match found {
                Some(c) => c,
                None => {
                    let c = pool.install(|| run_cell(plan, bi, ei, budget))?;
                    if let Some(p) = &path {
                        let text = serde_json::to_string(&c).map_err(|e| HarnessError::write(p, e))?;
                        write_atomic(p, text.as_bytes())?;
                    }
                    c
                }
            };
            let label = format!(
                "{} {} {}={}",
                plan.beds[bi].label(),
                plan.estimators[ei].name,
                budget.kind.name(),
                budget.amount
            );
            opts.observer.cell_done(cells.len() + 1, total, &label, resumed);
            cells.push((bi, ei, cell));
        }
    }
    Ok(RunResults { cells })
}

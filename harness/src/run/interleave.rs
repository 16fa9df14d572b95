//! Running the repetition blocks of the cells of one (test bed, budget) interleaved: the work items
//! of every estimator (one repetition of one batch of integrals each) are ordered repetition by
//! repetition and, inside a repetition and batch, estimator by estimator, and go to the thread pool
//! as one list. Load from other processes that changes during a run then falls on the baseline and
//! its contenders alike, instead of on whichever cell happened to run at that moment.
//!
//! Only the scheduling is shared: every estimate draws from its own stream (seed, test bed,
//! estimator, budget, repetition, integral), and each cell's items are reduced in that cell's own
//! fixed order (repetition-major inside a block, blocks in the order given), so a cell's statistics
//! are bit-identical to a run of that cell alone, whatever the thread count or the other cells.

use crate::error::Result;
use crate::plan::Plan;
use crate::run::cell::{add_diagnostics, rep_block_count, rep_block_size, CellKey, CellResult, RepBlock, TimeStats};
use crate::run::runner::{calibrated_samples, cell_key, run_item, CellRun, Item, REP_BLOCK};
use mcbench_core::budget::Budget;
use mcbench_core::stats::{Moments, NeumaierSum};
use mcbench_core::task::Costs;
use rayon::prelude::*;

/// Integrals per work item: small enough to balance, large enough to amortise scheduling.
const BATCH: usize = 16;

/// At most this many work items (one repetition of one batch of integrals of one cell) are in
/// flight at once: blocks run a chunk at a time, so memory does not grow with the repetition count.
const MAX_ITEMS: usize = 8192;

/// One cell of an interleaved group: its estimator and the repetition blocks to run.
#[derive(Clone, Copy, Debug)]
pub struct GroupCell<'a> {
    /// Index into [`Plan::estimators`].
    pub ei: usize,
    /// Repetition blocks to run, in the order their statistics are handed on.
    pub blocks: &'a [usize],
}

/// Runs the given repetition blocks of the cells `cells` (estimators of test bed `bi` at `budget`)
/// interleaved, and hands each block's sufficient statistics (a [`CellResult`] over that block's
/// repetitions, keyed by the whole cell) to `sink` with the cell's index in `cells` and the block's
/// position in its `blocks`; a cell's blocks come in that order. Blocks run a chunk of positions
/// at a time so that memory stays bounded whatever the repetition count.
///
/// Work items are whole sequences (test beds whose integrals come in frames,
/// [`mcbench_core::testbed::TestBed::sequence_length`]), batched to about `BATCH` integrals; each
/// sequence draws from the stream of its first integral, so a static test bed (sequence length 1)
/// keeps exactly the per-integral streams and batches it always had. A fetch or time budget first
/// becomes a fixed sample count per cell (its pilot is deterministic for fetch budgets, so every
/// shard owning a block of the cell computes the same count).
pub fn run_group_with(
    plan: &Plan,
    bi: usize,
    budget: Budget,
    cells: &[GroupCell<'_>],
    sink: impl FnMut(usize, usize, CellResult) -> Result<()>,
) -> Result<()> {
    run_group_at(plan, bi, budget, plan.sweep.reps, cells, sink)
}

/// [`run_group_with`] for cells of `reps` repetitions instead of the sweep's (their keys say
/// `reps`): the round-based repetitions of `unbiasedness` ([`crate::unbiasedness::rounds`]) run a
/// cell's later blocks at a larger count than its sweep's. A block's repetitions and streams do
/// not depend on `reps` when the block is full, so the blocks of a cell grown this way are the
/// blocks of a cell run at `reps` from the start.
pub fn run_group_at(
    plan: &Plan,
    bi: usize,
    budget: Budget,
    reps: usize,
    cells: &[GroupCell<'_>],
    mut sink: impl FnMut(usize, usize, CellResult) -> Result<()>,
) -> Result<()> {
    let b = &plan.beds[bi];
    let n = b.bed.integrals();
    let frames = b.bed.sequence_length().max(1);
    let sequences = n / frames;
    let per_item = BATCH.div_ceil(frames);
    let batches = sequences.div_ceil(per_item);
    let longest = cells.iter().map(|c| c.blocks.len()).max().unwrap_or(0);
    if longest == 0 {
        return Ok(());
    }
    let label = b.label();
    let mut runs = Vec::with_capacity(cells.len());
    for c in cells {
        let samples = if c.blocks.is_empty() { None } else { calibrated_samples(plan, bi, c.ei, budget)? };
        runs.push(CellRun { plan, label: &label, bi, ei: c.ei, budget, samples });
    }
    let keys: Vec<CellKey> = cells.iter().map(|c| CellKey { reps, ..cell_key(plan, bi, c.ei, budget) }).collect();
    let reference = &b.bed.reference().value;
    // Paper 003's per-integral weight 1 / tvi(L_ref), for each repetition's `Err`.
    let inv_tvi: Vec<f64> = reference
        .iter()
        .map(|v| 1.0 / mcbench_core::perception::tvi(mcbench_core::perception::luminance(*v)))
        .collect();
    let block_size = rep_block_size(reps);
    let per_chunk = (MAX_ITEMS / (REP_BLOCK * batches * cells.len()).max(1)).max(1);
    for start in (0..longest).step_by(per_chunk) {
        let end = (start + per_chunk).min(longest);
        // (cell, position, repetition, batch): position by position, repetition by repetition,
        // batch by batch, cell by cell; each cell's own items stay repetition-major.
        let mut work: Vec<(usize, usize, usize, usize)> = Vec::new();
        for pos in start..end {
            for r in 0..REP_BLOCK {
                for batch in 0..batches {
                    for (k, c) in cells.iter().enumerate() {
                        let Some(&blk) = c.blocks.get(pos) else { continue };
                        let rep = blk * REP_BLOCK + r;
                        if rep < reps {
                            work.push((k, pos, rep, batch));
                        }
                    }
                }
            }
        }
        let items: Vec<Result<Item>> = work
            .par_iter()
            .map(|&(k, _, rep, batch)| {
                run_item(&runs[k], rep as u64, batch * per_item..((batch + 1) * per_item).min(sequences), frames)
            })
            .collect();
        let mut parts: Vec<Vec<CellResult>> = cells
            .iter()
            .zip(&keys)
            .map(|(c, key)| vec![empty_cell(key.clone(), n); c.blocks.len().min(end).saturating_sub(start)])
            .collect();
        // A cell's items come repetition by repetition (every batch of one repetition, then the
        // next), so a repetition's aggregates are complete when that cell's next one starts.
        let mut rep_acc: Vec<Option<(usize, usize, RepAggregate)>> = (0..cells.len()).map(|_| None).collect();
        for (&(k, pos, rep, batch), r) in work.iter().zip(items) {
            let r = r?;
            let acc = &mut rep_acc[k];
            if acc.as_ref().is_some_and(|(p, q, _)| (*p, *q) != (pos, rep)) {
                if let Some((p, q, a)) = acc.take() {
                    a.push_into(&mut parts[k][p - start], q / block_size);
                }
            }
            let acc = &mut acc.get_or_insert_with(|| (pos, rep, RepAggregate::default())).2;
            let part = &mut parts[k][pos - start];
            for (j, v) in r.values.iter().enumerate() {
                let i = batch * per_item * frames + j;
                let mut sq = 0.0;
                for c in 0..3 {
                    part.moments[i][c].push(v[c]);
                    let d = v[c] - reference[i][c];
                    acc.add(d);
                    sq += d * d;
                    let shown = v[c].clamp(0.0, 1.0) - reference[i][c].clamp(0.0, 1.0);
                    acc.display.add(shown * shown);
                }
                acc.p_err.add(sq / 3.0 * inv_tvi[i]);
                acc.integrals += 1;
            }
            part.estimates += r.values.len() as u64;
            part.costs += r.costs;
            part.time.merge(&r.time);
            if let Some(t) = &mut part.cpu_time {
                t.merge(&r.cpu_time);
            }
            add_diagnostics(&mut part.diagnostics, &r.diagnostics);
            if let Some(blk) = part.blocks.get_mut(rep / block_size) {
                blk.cpu_seconds += r.cpu_time.total;
                blk.wall_seconds += r.time.total;
                blk.costs += r.costs;
            }
        }
        for (k, acc) in rep_acc.into_iter().enumerate() {
            if let Some((p, q, a)) = acc {
                a.push_into(&mut parts[k][p - start], q / block_size);
            }
        }
        for (k, cell_parts) in parts.into_iter().enumerate() {
            for (j, part) in cell_parts.into_iter().enumerate() {
                sink(k, start + j, part)?;
            }
        }
    }
    Ok(())
}

/// One repetition's aggregates over every integral and channel, compensated: the summed deviation
/// from the reference, the sum of squared deviations, and over integrals the channel-mean squared
/// deviation weighted by `1 / tvi` (paper 003's `Err`), and the sum of squared deviations of the
/// display-clamped values.
#[derive(Default)]
struct RepAggregate {
    dev: NeumaierSum,
    sq: NeumaierSum,
    p_err: NeumaierSum,
    display: NeumaierSum,
    count: u64,
    integrals: u64,
}

impl RepAggregate {
    fn add(&mut self, deviation: f64) {
        self.dev.add(deviation);
        self.sq.add(deviation * deviation);
        self.count += 1;
    }
    /// Adds the repetition to the cell's per-repetition statistics and to its repetition block
    /// `block`.
    fn push_into(self, cell: &mut CellResult, block: usize) {
        let sq = self.sq.value() / self.count.max(1) as f64;
        cell.rep_dev.push(self.dev.value());
        cell.rep_sq.push(sq);
        if let Some(b) = cell.blocks.get_mut(block) {
            b.reps += 1;
            b.sq += sq;
            b.p_err += self.p_err.value() / self.integrals.max(1) as f64;
            b.display_sq = Some(b.display_sq.unwrap_or(0.0) + self.display.value() / self.count.max(1) as f64);
        }
    }
}

/// A cell of `n` integrals with no estimates yet.
pub(crate) fn empty_cell(key: CellKey, n: usize) -> CellResult {
    let key_reps = key.reps;
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
        blocks: vec![RepBlock::default(); rep_block_count(key_reps)],
    }
}

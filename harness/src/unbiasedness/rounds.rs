//! Round-based repetitions of `unbiasedness` (`--repetitions rounds`, book: unbiasedness.md).
//!
//! Every row (a cell and its pilot, the gate) starts with a first round of a quarter of its part's
//! fixed-mode repetitions (at least [`MIN_FIRST_REPS`], a whole number of [`FIRST_ROUND_STEP`]);
//! the rows still open then double their repetitions, round by round, until each is decided, has
//! had [`LOOKS`] looks, or the next doubling no longer fits the experiment's budget. A control (a
//! row whose registry entry calls the estimator biased, with no exemption there) is not stopped
//! by a pass: it grows until flagged. A row without a valid test (the skewness gate) stays open
//! while looks remain.
//!
//! Validity under this optional stopping: a row is looked at most [`LOOKS`] times, a number fixed
//! before any outcome, and every look runs the fixed mode's tests
//! ([`crate::analysis::unbiasedness_at`]) at [`look_alpha`], the family-wise 1e-3 shared evenly
//! over the looks. By the union bound the chance that any look of a correct row flags it is at
//! most 1e-3 whatever rule chooses when to stop, so the rule may use the data and the registry
//! (decided rows stop, controls grow until flagged, the rows nearest a decision grow first). The
//! gate grows with the cell: at every look the pilot has as many repetitions as the cell, on its
//! own seed.
//!
//! The budget is deterministic: repetitions x integrals x samples per estimate, summed over every
//! cell and pilot, at most what the fixed mode spends (each part's repetitions for the cell and as
//! many for its pilot). Repetition `r` of a cell draws from the same stream in any round, and the
//! blocks of a grown cell are merged in block order, so a row stopped at `R` repetitions holds
//! exactly the moments of a fixed-mode cell of `R` repetitions, whatever the thread count; its
//! bootstrap blocks ([`rep_block_size`]) have the fixed-mode layout at `R` (adjacent blocks merge
//! when the repetitions double), their sums equal up to the order of the additions.

use crate::analysis::{TestRow, UNBIASEDNESS_ALPHA};
use crate::error::{HarnessError, Result};
use crate::plan::Plan;
use crate::run::cell::{rep_block_count, rep_block_size, CellResult, RepBlock, MAX_REP_BLOCKS};
use crate::run::runner::{merge_blocks, run_group_at, GroupCell, REP_BLOCK};

/// The most looks at one row: its repetitions run from the first round to 32 times it (8 times
/// the fixed mode's).
pub const LOOKS: usize = 6;

/// A first round is a whole number of these repetitions: whole repetition blocks of the run, and
/// as many as a cell has bootstrap blocks, so that every doubling merges adjacent bootstrap
/// blocks into the fixed mode's layout.
pub const FIRST_ROUND_STEP: usize = if REP_BLOCK > MAX_REP_BLOCKS { REP_BLOCK } else { MAX_REP_BLOCKS };

/// The fewest repetitions of a first round (four repetition blocks).
pub const MIN_FIRST_REPS: usize = 4 * REP_BLOCK;

/// The level of one look: the family-wise alpha shared over [`LOOKS`] looks.
pub fn look_alpha() -> f64 {
    UNBIASEDNESS_ALPHA / LOOKS as f64
}

/// The first round's repetitions for a part of `fixed` repetitions in the fixed mode: a quarter,
/// rounded up to a whole number of [`FIRST_ROUND_STEP`], at least [`MIN_FIRST_REPS`].
pub fn first_round(fixed: usize) -> usize {
    let step = FIRST_ROUND_STEP;
    fixed.div_ceil(4).div_ceil(step).max(1).saturating_mul(step).max(MIN_FIRST_REPS.next_multiple_of(step))
}

/// One row of the rounds: a cell and its pilot (the gate) with the tests of their last look.
pub struct Entry<'p> {
    /// The part's plan the cell belongs to.
    pub plan: &'p Plan,
    /// The same part on the pilot seed.
    pub pilot_plan: &'p Plan,
    /// Test bed index.
    pub bi: usize,
    /// Estimator index.
    pub ei: usize,
    /// The part's fixed-mode repetitions (what the budget counts).
    pub fixed: usize,
    /// The cell so far.
    pub cell: CellResult,
    /// Its pilot so far (as many repetitions).
    pub pilot: CellResult,
    /// Looks so far.
    pub looks: usize,
    /// Whether another round may decide it.
    pub open: bool,
    /// The repetitions its last look said would resolve it, if any (what orders the rounds).
    pub needed: Option<f64>,
    /// Whether it is a control that must be flagged (grown first, never stopped by a pass).
    pub control: bool,
}

impl Entry<'_> {
    /// Work per repetition of the cell (or of its pilot): integrals x samples per estimate.
    fn unit(&self) -> u64 {
        (self.cell.moments.len() as u64).saturating_mul(self.cell.key.budget.amount)
    }
    /// What the fixed mode spends on this row: the cell and its pilot at the part's repetitions.
    pub fn fixed_cost(&self) -> u64 {
        2u64.saturating_mul(self.fixed as u64).saturating_mul(self.unit())
    }
    /// What the row has spent so far.
    pub fn spent(&self) -> u64 {
        2u64.saturating_mul(self.cell.key.reps as u64).saturating_mul(self.unit())
    }
    /// Its place in a round (lowest first) and the work it claims there: controls (a doubling),
    /// then the rows whose needed repetitions some look reaches, by the work of the doublings to
    /// reach them (the nearest decisions first), then the others (a doubling).
    fn priority(&self) -> (u8, u64) {
        let reps = self.cell.key.reps.max(1) as f64;
        match self.needed.filter(|&n| n.is_finite()) {
            _ if self.control => (0, self.spent()),
            Some(n) if n <= reach(self.cell.key.reps, self.looks) => {
                let doublings = (n / reps).log2().ceil().max(1.0) as u32;
                (1, self.spent().saturating_mul((1u64 << doublings) - 1))
            }
            _ => (2, self.spent()),
        }
    }
}

/// The most repetitions the looks after look `looks` reach from `reps`.
fn reach(reps: usize, looks: usize) -> f64 {
    (reps as f64) * (1u64 << LOOKS.saturating_sub(looks)) as f64
}

/// Whether a row whose last look gave `tests` (at `reps` repetitions, look `looks`) stays open. No
/// row stays open after the last look or once flagged. A `control` (a row that must be flagged)
/// stays open otherwise, pass or not. Any other row stays open while inconclusive and able to
/// pass at all (`can_pass`: not judged against a reference of its own making), either without a
/// valid pooled test (more repetitions may bring its skewness under the gate's limit) or with
/// some repetitions within the remaining looks that would resolve it.
pub fn stays_open(tests: &[TestRow], reps: usize, looks: usize, can_pass: bool, control: bool) -> bool {
    let Some(d) = tests.iter().find(|t| t.test == "combined") else { return false };
    if looks >= LOOKS || d.verdict == "biased" {
        return false;
    }
    if control {
        return true;
    }
    let untested = tests.iter().any(|t| t.test == "pooled_t" && t.p_value.is_nan());
    d.verdict == "inconclusive" && can_pass && (untested || d.reps_needed.is_some_and(|r| r <= reach(reps, looks)))
}

/// The combined row's repetitions needed, for [`Entry::needed`].
pub fn needed(tests: &[TestRow]) -> Option<f64> {
    tests.iter().find(|t| t.test == "combined").and_then(|d| d.reps_needed)
}

/// Grows the open entries round by round (see the module docs) on `threads` threads; `judge`
/// gives a grown entry's tests and whether it stays open (and is called once per new look).
/// Returns the rounds run after the first.
pub fn grow(
    entries: &mut [Entry<'_>],
    budget: u64,
    threads: usize,
    mut judge: impl FnMut(&mut Entry<'_>) -> Result<()>,
) -> Result<usize> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| HarnessError::write("thread pool", e))?;
    let mut spent: u64 = entries.iter().map(Entry::spent).sum();
    let mut rounds = 0;
    loop {
        // In order of priority (entry order among equals). First the controls and the rows within
        // reach of a decision, each while the work it claims (its doublings up to its needed
        // repetitions) fits beside what the rows before it claimed: the budget goes to the
        // decisions it can complete. Only a round that grows none of them grows any open row
        // whose doubling fits; a row whose doubling does not fit then never will.
        let mut open: Vec<((u8, u64), usize)> =
            entries.iter().enumerate().filter(|(_, e)| e.open).map(|(i, e)| (e.priority(), i)).collect();
        open.sort();
        let left = budget.saturating_sub(spent);
        let mut claimed: u64 = 0;
        let mut chosen = Vec::new();
        for &((_, claim), i) in open.iter().filter(|((class, _), _)| *class < 2) {
            if claimed.saturating_add(claim) <= left {
                claimed += claim;
                chosen.push(i);
            }
        }
        if chosen.is_empty() {
            for &(_, i) in &open {
                let cost = entries[i].spent();
                if spent.saturating_add(cost) <= budget {
                    spent += cost;
                    chosen.push(i);
                } else {
                    entries[i].open = false;
                }
            }
        } else {
            spent += chosen.iter().map(|&i| entries[i].spent()).sum::<u64>();
        }
        chosen.sort_unstable();
        if chosen.is_empty() {
            return Ok(rounds);
        }
        rounds += 1;
        pool.install(|| double(entries, &chosen))?;
        for &i in &chosen {
            entries[i].looks += 1;
            judge(&mut entries[i])?;
        }
    }
}

/// Doubles the repetitions of the entries `chosen` and of their pilots: the new blocks of the
/// cells of one (plan, test bed, repetitions) run interleaved, then merge after the old ones.
fn double(entries: &mut [Entry<'_>], chosen: &[usize]) -> Result<()> {
    let mut done = vec![false; chosen.len()];
    for a in 0..chosen.len() {
        if done[a] {
            continue;
        }
        let first = &entries[chosen[a]];
        let same = |e: &Entry<'_>| {
            std::ptr::eq(e.plan, first.plan) && e.bi == first.bi && e.cell.key.reps == first.cell.key.reps
        };
        let group: Vec<usize> = (a..chosen.len()).filter(|&b| !done[b] && same(&entries[chosen[b]])).collect();
        let (reps, bi, budget) = (first.cell.key.reps, first.bi, first.cell.key.budget);
        let blocks: Vec<usize> = (reps / REP_BLOCK..2 * reps / REP_BLOCK).collect();
        let cells: Vec<GroupCell<'_>> =
            group.iter().map(|&b| GroupCell { ei: entries[chosen[b]].ei, blocks: &blocks }).collect();
        for pilot in [false, true] {
            let e0 = &entries[chosen[a]];
            let plan = if pilot { e0.pilot_plan } else { e0.plan };
            let mut parts: Vec<Vec<CellResult>> = vec![Vec::new(); group.len()];
            run_group_at(plan, bi, budget, 2 * reps, &cells, |k, _, part| {
                parts[k].push(part);
                Ok(())
            })?;
            for (k, new) in parts.into_iter().enumerate() {
                let e = &mut entries[chosen[group[k]]];
                let old = if pilot { &mut e.pilot } else { &mut e.cell };
                let key = crate::run::cell::CellKey { reps: 2 * reps, ..old.key.clone() };
                let mut head = old.clone();
                head.blocks = regroup(&old.blocks, reps, 2 * reps);
                let all: Vec<CellResult> = std::iter::once(head).chain(new).collect();
                *old = merge_blocks(key, &all);
            }
        }
        for b in group {
            done[b] = true;
        }
    }
    Ok(())
}

/// The bootstrap blocks of a cell of `from` repetitions in the layout of a cell of `to`
/// repetitions, the later ones empty: each block merged, in block order, into the block that holds
/// its repetitions. Empty (no bootstrap) when a block of `to` would split a block of `from`.
pub fn regroup(blocks: &[RepBlock], from: usize, to: usize) -> Vec<RepBlock> {
    let (size, new_size) = (rep_block_size(from), rep_block_size(to));
    if blocks.len() != rep_block_count(from) || !new_size.is_multiple_of(size) {
        return Vec::new();
    }
    let mut out = vec![RepBlock::default(); rep_block_count(to)];
    for (k, b) in blocks.iter().enumerate() {
        out[k * size / new_size].merge(b);
    }
    out
}

#[cfg(test)]
#[path = "rounds_tests.rs"]
mod tests;

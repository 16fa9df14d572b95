//! Round-based repetitions of `unbiasedness` (`--repetitions rounds`, book: unbiasedness.md).
//!
//! Every row (a cell and its pilot, the gate) starts with a first round of a quarter of its part's
//! fixed-mode repetitions (at least [`MIN_FIRST_REPS`], a whole number of repetition blocks); the
//! rows still open then double their repetitions, round by round, until each is decided, has had
//! [`LOOKS`] looks, or the next doubling no longer fits the experiment's budget.
//!
//! Validity under this optional stopping: a row is looked at most [`LOOKS`] times, a number fixed
//! before any outcome, and every look runs the fixed mode's tests
//! ([`crate::analysis::unbiasedness_at`]) at [`look_alpha`], the family-wise 1e-3 shared evenly
//! over the looks. By the union bound the chance that any look of a correct row flags it is at
//! most 1e-3 whatever rule chooses when to stop, so the rule may use the data (decided rows stop,
//! rows no look could resolve stop, the cheapest rows grow first). The gate grows with the cell:
//! at every look the pilot has as many repetitions as the cell, on its own seed.
//!
//! The budget is deterministic: repetitions x integrals x samples per estimate, summed over every
//! cell and pilot, at most what the fixed mode spends (each part's repetitions for the cell and as
//! many for its pilot). Repetition `r` of a cell draws from the same stream in any round, and the
//! blocks of a grown cell are merged in block order, so a row stopped at `R` repetitions holds
//! exactly the statistics of a fixed-mode cell of `R` repetitions, whatever the thread count.

use crate::analysis::{TestRow, UNBIASEDNESS_ALPHA};
use crate::error::{HarnessError, Result};
use crate::plan::Plan;
use crate::run::cell::CellResult;
use crate::run::runner::{merge_blocks, run_group_at, GroupCell, REP_BLOCK};

/// The most looks at one row: its repetitions run from the first round to 16 times it (4 times
/// the fixed mode's).
pub const LOOKS: usize = 5;

/// The fewest repetitions of a first round (four repetition blocks).
pub const MIN_FIRST_REPS: usize = 4 * REP_BLOCK;

/// The level of one look: the family-wise alpha shared over [`LOOKS`] looks.
pub fn look_alpha() -> f64 {
    UNBIASEDNESS_ALPHA / LOOKS as f64
}

/// The first round's repetitions for a part of `fixed` repetitions in the fixed mode: a quarter,
/// rounded up to whole repetition blocks, at least [`MIN_FIRST_REPS`].
pub fn first_round(fixed: usize) -> usize {
    fixed.div_ceil(4).div_ceil(REP_BLOCK).max(1).saturating_mul(REP_BLOCK).max(MIN_FIRST_REPS)
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
}

/// Whether a row whose last look gave `tests` (at `reps` repetitions, look `looks`) stays open: it
/// is inconclusive, another look is left, some repetitions within the last look's would resolve
/// it, and it can pass at all (`can_pass`: not judged against a reference of its own making).
pub fn stays_open(tests: &[TestRow], reps: usize, looks: usize, can_pass: bool) -> bool {
    let Some(d) = tests.iter().find(|t| t.test == "combined") else { return false };
    let max_reps = (reps as f64) * (1u64 << LOOKS.saturating_sub(looks)) as f64;
    d.verdict == "inconclusive" && looks < LOOKS && can_pass && d.reps_needed.is_some_and(|r| r <= max_reps)
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
        // The cheapest doublings first, in entry order among equals, while they fit the budget;
        // a row whose doubling does not fit now never will.
        let mut open: Vec<(u64, usize)> =
            entries.iter().enumerate().filter(|(_, e)| e.open).map(|(i, e)| (e.spent(), i)).collect();
        open.sort();
        let mut chosen = Vec::new();
        for (cost, i) in open {
            if spent.saturating_add(cost) <= budget {
                spent += cost;
                chosen.push(i);
            } else {
                entries[i].open = false;
            }
        }
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
                let all: Vec<CellResult> = std::iter::once(old.clone()).chain(new).collect();
                *old = merge_blocks(key, &all);
            }
        }
        for b in group {
            done[b] = true;
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "rounds_tests.rs"]
mod tests;

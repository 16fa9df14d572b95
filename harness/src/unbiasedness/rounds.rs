//! Round-based repetitions of `unbiasedness` (`--repetitions rounds`, book: unbiasedness.md).
//!
//! Every row (a cell and its pilot, the gate) starts with a first round of an eighth of its part's
//! fixed-mode repetitions (at least [`MIN_FIRST_REPS`], a whole number of [`FIRST_ROUND_STEP`]);
//! the cells of the rows still open then double their repetitions, round by round, until each is
//! decided, has had [`LOOKS`] looks, or the next doubling no longer fits the experiment's budget.
//! The pilot keeps its first round's repetitions at every look. A control (a row whose registry
//! entry calls the estimator biased, with no exemption there) is not stopped by a pass: it grows
//! until flagged. Any other row stays open while some look left could resolve it by its last
//! look's estimate, the repetitions that would bring a skewness beyond the gate's limit under it
//! included ([`stays_open`]).
//!
//! Validity under this optional stopping: a row is looked at most [`LOOKS`] times, a number fixed
//! before any outcome, and every look runs the fixed mode's tests
//! ([`crate::analysis::unbiasedness_at`]) at [`look_alpha`], the family-wise 1e-3 shared evenly
//! over the looks. By the union bound the chance that any look of a correct row flags it is at
//! most 1e-3 whatever rule chooses when to stop, so the rule may use the data and the registry
//! (decided rows stop, controls grow until flagged, the rows nearest a decision grow first). The
//! tests at a look are the fixed mode's tests behind a pilot of the first round's repetitions: the
//! pilot is the same pair on its own seed, independent of the cell at every look, and the tests
//! count its size (the spread, the mean of the cell's and the pilot's variance, has the
//! degrees of freedom of such a mean, [`crate::analysis::Gate::t_dof`]; the per-integral skewness
//! margin is that of the pilot's repetitions). Keeping the pilot fixed halves what a doubling costs.
//!
//! The budget is deterministic: repetitions x integrals x samples per estimate, summed over every
//! cell and pilot, at most what the fixed mode spends (each part's repetitions for the cell and as
//! many for its pilot), or a share of it ([`budget`]). The share does not enter the bound above:
//! a budget only decides when rows stop. Repetition `r` of a cell draws from the same stream in any round, and the
//! blocks of a grown cell are merged in block order, so a row stopped at `R` repetitions holds
//! exactly the moments of a fixed-mode cell of `R` repetitions, whatever the thread count; its
//! bootstrap blocks ([`rep_block_size`]) have the fixed-mode layout at `R` (adjacent blocks merge
//! when the repetitions double), their sums equal up to the order of the additions. Its pilot is
//! the fixed mode's pilot at the first round's repetitions.

use crate::analysis::{TestRow, UNBIASEDNESS_ALPHA};
use crate::error::{HarnessError, Result};
use crate::plan::Plan;
use crate::run::cell::{rep_block_count, rep_block_size, CellResult, RepBlock, MAX_REP_BLOCKS};
use crate::run::runner::{merge_blocks, run_group_at, GroupCell, REP_BLOCK};

/// The most looks at one row: its repetitions run from the first round to 128 times it (16 times
/// the fixed mode's).
pub const LOOKS: usize = 8;

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

/// The first round's repetitions for a part of `fixed` repetitions in the fixed mode: an eighth,
/// rounded up to a whole number of [`FIRST_ROUND_STEP`], at least [`MIN_FIRST_REPS`].
pub fn first_round(fixed: usize) -> usize {
    let step = FIRST_ROUND_STEP;
    fixed.div_ceil(8).div_ceil(step).max(1).saturating_mul(step).max(MIN_FIRST_REPS.next_multiple_of(step))
}

/// The budget of the rounds: `share` of `fixed_work` (the fixed mode's work, [`Entry::fixed_cost`]
/// summed), in whole millionths of it so that it is exact integer arithmetic; the whole of it at a
/// share of 1 (`--rounds-budget`). The first round is run whatever the budget: a budget under its
/// work grows no row.
pub fn budget(fixed_work: u64, share: f64) -> u64 {
    const MILLION: u64 = 1_000_000;
    let millionths = (share * MILLION as f64).round().clamp(0.0, MILLION as f64) as u64;
    (u128::from(fixed_work) * u128::from(millionths) / u128::from(MILLION)) as u64
}

/// One row of the rounds: a cell and its pilot (the gate) with the tests of their last look.
pub struct Entry<'p> {
    /// The part's plan the cell belongs to.
    pub plan: &'p Plan,
    /// Test bed index.
    pub bi: usize,
    /// Estimator index.
    pub ei: usize,
    /// The part's fixed-mode repetitions (what the budget counts).
    pub fixed: usize,
    /// The cell so far.
    pub cell: CellResult,
    /// Its pilot (the gate): the same pair on the pilot seed at the first round's repetitions,
    /// which it keeps at every look.
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
    /// What the row has spent so far: its cell and its pilot (which stays at the first round).
    pub fn spent(&self) -> u64 {
        (self.cell.key.reps as u64).saturating_add(self.pilot.key.reps as u64).saturating_mul(self.unit())
    }
    /// What its next doubling costs: as many repetitions of the cell again.
    pub fn doubling(&self) -> u64 {
        (self.cell.key.reps as u64).saturating_mul(self.unit())
    }
    /// Its place in a round (lowest first) and the work it claims there: controls (a doubling),
    /// then the rows whose needed repetitions some look reaches, by the work of the doublings to
    /// reach them (the nearest decisions first), then the others (a doubling).
    fn priority(&self) -> (u8, u64) {
        let reps = self.cell.key.reps.max(1) as f64;
        match self.needed.filter(|&n| n.is_finite()) {
            _ if self.control => (0, self.doubling()),
            Some(n) if n <= reach(self.cell.key.reps, self.looks) => {
                let doublings = (n / reps).log2().ceil().max(1.0) as u32;
                (1, self.doubling().saturating_mul((1u64 << doublings) - 1))
            }
            _ => (2, self.doubling()),
        }
    }
}

/// The most repetitions the looks after look `looks` reach from `reps`.
fn reach(reps: usize, looks: usize) -> f64 {
    (reps as f64) * (1u64 << LOOKS.saturating_sub(looks)) as f64
}

/// Whether a row whose last look gave `tests` (at `reps` repetitions, look `looks`) stays open. No
/// row stays open after the last look or once flagged. A `control` (a row that must be flagged)
/// stays open otherwise, pass or not. Any other row stays open while inconclusive, able to pass at
/// all (`can_pass`: not judged against a reference of its own making), and with some repetitions
/// within the remaining looks that would resolve it: for a row without a valid pooled test, the
/// repetitions that would bring its skewness under the gate's limit count too, so a row too
/// skewed for any look to test stops (it is inconclusive at those repetitions in the fixed mode
/// as well) and leaves the budget to the rows within reach.
pub fn stays_open(tests: &[TestRow], reps: usize, looks: usize, can_pass: bool, control: bool) -> bool {
    let Some(d) = tests.iter().find(|t| t.test == "combined") else { return false };
    if looks >= LOOKS || d.verdict == "biased" {
        return false;
    }
    if control {
        return true;
    }
    d.verdict == "inconclusive" && can_pass && d.reps_needed.is_some_and(|r| r <= reach(reps, looks))
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
                let cost = entries[i].doubling();
                if spent.saturating_add(cost) <= budget {
                    spent += cost;
                    chosen.push(i);
                } else {
                    entries[i].open = false;
                }
            }
        } else {
            spent += chosen.iter().map(|&i| entries[i].doubling()).sum::<u64>();
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

/// Doubles the repetitions of the cells of the entries `chosen` (their pilots stay as they are):
/// the new blocks of the cells of one (plan, test bed, repetitions) run interleaved, then merge
/// after the old ones.
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
        let (reps, bi, budget, plan) = (first.cell.key.reps, first.bi, first.cell.key.budget, first.plan);
        let blocks: Vec<usize> = (reps / REP_BLOCK..2 * reps / REP_BLOCK).collect();
        let cells: Vec<GroupCell<'_>> =
            group.iter().map(|&b| GroupCell { ei: entries[chosen[b]].ei, blocks: &blocks }).collect();
        let mut parts: Vec<Vec<CellResult>> = vec![Vec::new(); group.len()];
        run_group_at(plan, bi, budget, 2 * reps, &cells, |k, _, part| {
            parts[k].push(part);
            Ok(())
        })?;
        for (k, new) in parts.into_iter().enumerate() {
            let old = &mut entries[chosen[group[k]]].cell;
            let key = crate::run::cell::CellKey { reps: 2 * reps, ..old.key.clone() };
            let mut head = old.clone();
            head.blocks = regroup(&old.blocks, reps, 2 * reps);
            let all: Vec<CellResult> = std::iter::once(head).chain(new).collect();
            *old = merge_blocks(key, &all);
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

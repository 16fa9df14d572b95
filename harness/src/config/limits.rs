//! Every bound the harness puts on a number it reads, in one place (bad input is refused before
//! anything runs). The same bounds apply on every input path: command-line flags, TOML and
//! JSON config files, and the sweep stored in a shard manifest that `mcbench merge` rebuilds.
//!
//! | field | bound | why |
//! |---|---|---|
//! | `reps` | 2 ..= [`MAX_REPS`] | variances need two repetitions; a cell's statistics are reduced a chunk of repetition blocks at a time, but the run still does `reps` times the work |
//! | `budgets` (samples) | 1 ..= [`MAX_SAMPLES`] per estimate | one estimate must end |
//! | `budgets` (fetches) | 1 ..= [`MAX_FETCHES`] per estimate | as samples; a fetch budget also caps samples at 64x the budget |
//! | `budgets` (micros) | 1 ..= [`MAX_MICROS`] per estimate | one hour of CPU per estimate |
//! | number of `budgets` | 1 ..= [`MAX_BUDGETS`] | |
//! | `testbeds`, `estimators` entries | 1 ..= [`MAX_ENTRIES`] each, no duplicates | duplicates would give duplicate rows |
//! | `--threads` | 1 ..= [`MAX_THREADS`] | |
//! | test-bed and estimator parameters | their own ranges (`mcbench list`), checked when built | |

/// Most repetitions per integral.
pub const MAX_REPS: usize = 1_000_000;
/// Largest sample budget per estimate (2^32).
pub const MAX_SAMPLES: u64 = 1 << 32;
/// Largest fetch budget per estimate (2^32).
pub const MAX_FETCHES: u64 = 1 << 32;
/// Largest time budget per estimate, in microseconds of CPU (one hour).
pub const MAX_MICROS: u64 = 3_600_000_000;
/// Most budgets in one sweep.
pub const MAX_BUDGETS: usize = 64;
/// Most test-bed entries, and most estimator entries, in one sweep.
pub const MAX_ENTRIES: usize = 256;
/// Most worker threads.
pub const MAX_THREADS: u64 = 1024;

/// The largest budget of a kind.
pub fn max_budget(kind: mcbench_core::budget::BudgetKind) -> u64 {
    use mcbench_core::budget::BudgetKind::*;
    match kind {
        Samples => MAX_SAMPLES,
        Fetches => MAX_FETCHES,
        Micros => MAX_MICROS,
    }
}

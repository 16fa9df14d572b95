//! Estimates taken outside the runner, for checks that must survive a misbehaving estimator (the
//! conformance suite, the `stability` cases): one sequence on its own stream with panics caught
//! and refusals told apart, and the pseudo-cell of per-integral moments that the harness's
//! unbiasedness tests ([`crate::analysis::unbiasedness`]) read.

use crate::run::cell::{CellKey, CellResult};
use mcbench_core::budget::Budget;
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::Estimator;
use mcbench_core::rng::StreamKey;
use mcbench_core::stats::Moments;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Why a guarded sequence produced no estimates.
#[derive(Debug)]
pub enum Stopped {
    /// The estimator panicked (the first line of the panic message).
    Panicked(String),
    /// It returned an error.
    Error(EstimateError),
}

/// The first line of `s`, trimmed.
pub fn one_line(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().to_string()
}

/// The first line of a caught panic's message.
pub fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    let msg = p
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "non-string payload".into());
    one_line(&msg)
}

/// The estimates of the sequence starting at integral `first`, `budget` samples each, on the
/// stream of `key` (whose `integral` must be `first`), with a panic caught.
pub fn sequence(
    est: &dyn Estimator,
    bed: &dyn TestBed,
    key: &StreamKey<'_>,
    budget: Budget,
    first: usize,
) -> Result<Vec<[f64; 3]>, Stopped> {
    let f = bed.sequence_length().max(1);
    let tasks: Vec<Task<'_>> = (first..first + f).map(|i| Task::new(bed, i, budget)).collect();
    match catch_unwind(AssertUnwindSafe(|| est.estimate_sequence(&tasks, &mut key.rng()))) {
        Err(p) => Err(Stopped::Panicked(panic_message(p))),
        Ok(Err(e)) => Err(Stopped::Error(e)),
        Ok(Ok(v)) => Ok(v.into_iter().map(|x| x.0).collect()),
    }
}

/// A cell of `estimator` on `bed` at `budget` from the per-repetition estimates of every integral
/// (pushed in repetition order), with no costs: what the unbiasedness tests need.
pub fn cell_of(bed: &dyn TestBed, estimator: &str, budget: Budget, seed: u64, per_rep: &[Vec<[f64; 3]>]) -> CellResult {
    let n = bed.integrals();
    let reference = &bed.reference().value;
    let mut moments = vec![[Moments::new(), Moments::new(), Moments::new()]; n];
    let (mut rep_dev, mut rep_sq) = (Moments::new(), Moments::new());
    for v in per_rep {
        let (mut dev, mut sq) = (mcbench_core::stats::NeumaierSum::new(), mcbench_core::stats::NeumaierSum::new());
        for (i, (m, x)) in moments.iter_mut().zip(v).enumerate() {
            for c in 0..3 {
                m[c].push(x[c]);
                let d = x[c] - reference[i][c];
                dev.add(d);
                sq.add(d * d);
            }
        }
        rep_dev.push(dev.value());
        rep_sq.push(sq.value() / (3 * n).max(1) as f64);
    }
    CellResult {
        key: CellKey {
            testbed: bed.id().into(),
            variant: bed.variant().into(),
            testbed_params: String::new(),
            estimator: estimator.into(),
            budget,
            reps: per_rep.len(),
            seed,
            version: env!("CARGO_PKG_VERSION").into(),
        },
        moments,
        costs: Default::default(),
        estimates: (per_rep.len() * n) as u64,
        time: Default::default(),
        cpu_time: None,
        diagnostics: Vec::new(),
        rep_dev,
        rep_sq,
        blocks: Vec::new(),
    }
}

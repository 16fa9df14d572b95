//! The dedicated unbiasedness check of `envmap-smc` (book: statistics.md): the per-integral tests of
//! the main sweep have a dozen repetitions, too few for the skewed estimates of an HDR sky (a rare
//! sun hit), so every paper 004 estimator is also run on a small `envmap-sequence` (2x2 pixels,
//! 4 frames, N = 4 particles) with thousands of repetitions: one-sample t-tests per integral and
//! channel with Holm-Bonferroni (family-wise alpha 1e-3) and the pooled z-test, exactly the
//! harness's [`unbiasedness`] on a cell of these repetitions. Theory: `bidirectional_is`, `smc` and `smc_bridge` are unbiased (the unnormalised SMC
//! estimate); `smc_path` (exponentiated log) and `smc_adaptive` (particle-dependent schedule) only
//! consistent; `bidirectional_is_sn` is the biased control and must be flagged.

use mcbench::analysis::{unbiasedness, TestRow};
use mcbench::config::Mode;
use mcbench::error::Result;
use mcbench::registry::Registry;
use mcbench_core::budget::Budget;
use mcbench_core::params::Params;
use mcbench_core::rng::StreamKey;
use mcbench_core::task::Task;
use rayon::prelude::*;

/// (estimator id, its parameters) checked.
fn cases() -> Vec<(&'static str, Params)> {
    vec![
        ("bidirectional_is", Params::new().with("candidates", 32.0)),
        ("smc", Params::new().with("moves", 2.0).with("candidates", 32.0)),
        ("smc_bridge", Params::new().with("bridges", 3.0).with("candidates", 32.0)),
        ("smc_path", Params::new().with("bridges", 3.0).with("candidates", 32.0)),
        ("smc_adaptive", Params::new().with("candidates", 32.0)),
        ("bidirectional_is_sn", Params::new().with("candidates", 5.0)),
    ]
}

/// The relative bias the dedicated check must resolve to pass (it runs thousands of repetitions).
const DEDICATED_TOLERANCE: f64 = 0.01;

/// Runs the check, each cell gated by a pilot of as many repetitions on its own seed; one
/// `holm_t`, one `pooled_t` and one `combined` row per (variant, estimator), test names suffixed
/// `_dedicated`.
pub fn check(mode: Mode, seed: u64, registry: &Registry) -> Result<Vec<TestRow>> {
    let reps: u64 = if mode == Mode::Quick { 3000 } else { 20_000 };
    let n = 4u64;
    let mut rows = Vec::new();
    for variant in ["mixed", "mixed-lns"] {
        let params = Params::new().with("resolution", 2.0).with("frames", 4.0);
        let bed = (registry.test_bed("envmap-sequence")?.build)(variant, &params, registry.references())?;
        let f = bed.sequence_length();
        let seqs = bed.integrals() / f;
        for (id, p) in cases() {
            let entry = registry.estimator(id)?;
            let est = (entry.build)(&p)?;
            let label = format!("{id}-dedicated");
            let per_rep_of = |seed: u64| -> Vec<Vec<[f64; 3]>> {
                (0..reps)
                    .into_par_iter()
                    .map(|rep| {
                        let mut out = Vec::with_capacity(bed.integrals());
                        for s in 0..seqs {
                            let key = StreamKey {
                                seed,
                                testbed: variant,
                                estimator: &label,
                                budget: n,
                                rep,
                                integral: (s * f) as u64,
                            };
                            let tasks: Vec<Task<'_>> = (s * f..(s + 1) * f)
                                .map(|i| {
                                    Task::new(
                                        bed.as_ref(),
                                        i,
                                        Budget { kind: mcbench_core::budget::BudgetKind::Samples, amount: n },
                                    )
                                })
                                .collect();
                            match est.estimate_sequence(&tasks, &mut key.rng()) {
                                Ok(v) => out.extend(v.into_iter().map(|x| x.0)),
                                Err(_) => out.extend(std::iter::repeat_n([f64::NAN; 3], f)),
                            }
                        }
                        out
                    })
                    .collect()
            };
            let reference = bed.reference();
            let budget = Budget::samples(n)?;
            let cell = mcbench::run::guarded::cell_of(bed.as_ref(), id, budget, seed, &per_rep_of(seed));
            let pilot_seed = mcbench::unbiasedness::run::pilot_seed(seed);
            let pilot = mcbench::run::guarded::cell_of(bed.as_ref(), id, budget, pilot_seed, &per_rep_of(pilot_seed));
            let gate = mcbench::analysis::Gate::from_cell(&pilot, "pilot", 1.0)
                .with_group(mcbench::analysis::Gate::group_of(est.as_ref(), bed.as_ref()));
            for mut row in unbiasedness(&cell, reference, entry.bias, Some(&gate), DEDICATED_TOLERANCE) {
                row.test.push_str("_dedicated");
                // The self-normalised control is only biased for L_r; its L_ns estimate is unbiased.
                if entry.bias == mcbench_core::estimator::Bias::Biased && variant.ends_with("-lns") {
                    row.agrees = true;
                }
                rows.push(row);
            }
        }
    }
    Ok(rows)
}

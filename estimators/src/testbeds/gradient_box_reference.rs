//! The stored reference of `gradient-box` (SPEC §3.2, §2): a long run of the independent volumetric
//! path tracer (`is0_cv0` on a medium: free flights of paper 000 Eq. 7, phase sampling) per pixel,
//! split into [`BATCHES`] independent batches whose spread gives each pixel's and channel's
//! standard error. Made by `mcbench reference gradient-box --variant V [--samples N]`; the command,
//! seed and sample count are stored in the file.

use super::gradient_box::GradientBox;
use crate::budget::Budget;
use crate::error::ConfigError;
use crate::estimator::Estimator;
use crate::math::Rgb;
use crate::media_smc::PathTracer;
use crate::params::Params;
use crate::references::{ReferenceKey, StoredReference};
use crate::rng::StreamKey;
use crate::stats::Moments;
use crate::task::Task;
use crate::testbed::{Reference, ReferenceKind, TestBed};

/// Independent batches per pixel (the standard error's degrees of freedom + 1).
pub const BATCHES: u64 = 64;
/// The seed of every stored reference.
pub const SEED: u64 = 1;

/// Default paths per pixel of a variant (sized so the reference's RMS standard error stays below
/// a third of the smallest RMSE the experiments measure, see README).
pub fn default_samples(variant: &str) -> u64 {
    match variant {
        "thick" => 1 << 14,
        _ => 1 << 20,
    }
}

/// Computes the reference of `variant` with the test bed's `params` and `samples` paths per pixel
/// (default [`default_samples`]) on `threads` threads; the result does not depend on the thread
/// count.
pub fn compute_reference(
    variant: &str,
    params: &Params,
    samples: Option<u64>,
    threads: usize,
) -> Result<(ReferenceKey, StoredReference), ConfigError> {
    let samples = samples.unwrap_or_else(|| default_samples(variant));
    let per_batch = samples.div_ceil(BATCHES).max(1);
    let bed = GradientBox::without_reference(variant, params)?;
    let key = bed.reference_key();
    let n = bed.integrals();
    let label = format!("gradient-box/{variant}/reference");
    let budget = Budget::samples(per_batch).map_err(|e| ConfigError::invalid("samples", samples, e.to_string()))?;
    let results = crate::parallel::map_indices(n, threads, |i| {
        let mut m: [Moments; 3] = Default::default();
        for batch in 0..BATCHES {
            let key = StreamKey {
                seed: SEED,
                testbed: &label,
                estimator: "is0_cv0",
                budget: per_batch,
                rep: batch,
                integral: i as u64,
            };
            let task = Task::new(&bed, i, budget);
            let v = PathTracer.estimate(&task, &mut key.rng()).unwrap_or(Rgb([f64::NAN; 3]));
            for c in 0..3 {
                m[c].push(v[c]);
            }
        }
        (Rgb([m[0].mean(), m[1].mean(), m[2].mean()]), Rgb([m[0].std_err(), m[1].std_err(), m[2].std_err()]))
    });
    if results.iter().any(|(m, _)| !m.is_finite()) {
        return Err(ConfigError::invalid("reference", variant, "a pixel's estimate was not finite"));
    }
    let (w, h) = bed.resolution();
    let sigma_t = bed.setup().sigma_t;
    let command = format!(
        "{} --samples {} (resolution {w}, sigma_t {sigma_t}, seed {SEED}, {BATCHES} batches of {per_batch} is0_cv0 paths per pixel)",
        key.command(),
        per_batch * BATCHES
    );
    let reference = Reference {
        kind: ReferenceKind::Stored { command: command.clone(), samples: BATCHES },
        value: results.iter().map(|r| r.0).collect(),
        std_err: results.iter().map(|r| r.1).collect(),
    };
    Ok((
        key.clone(),
        StoredReference {
            testbed: key.testbed,
            variant: key.variant,
            params: key.params,
            command,
            resolution: (w, h),
            reference,
        },
    ))
}

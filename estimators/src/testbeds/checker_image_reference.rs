//! The stored reference of `checker-image` (book: testbeds.md): per pixel, the mean of many pixel samples
//! at independent uniform footprint positions, split into [`BATCHES`] independent batches whose
//! spread gives the standard error. Made by `mcbench reference checker-image --variant V
//! [--samples N]`; the command, seed and sample count are stored in the file.

use super::checker_image::CheckerImage;
use mcbench_core::error::ConfigError;
use mcbench_core::math::Rgb;
use mcbench_core::params::Params;
use mcbench_core::references::{ReferenceKey, StoredReference};
use mcbench_core::rng::StreamKey;
use mcbench_core::stats::Moments;
use mcbench_core::testbed::{ImagePlaneScene, Reference, ReferenceKind, TestBed};

/// The variance of one pixel sample of every pixel (mean over the channels), from a reference
/// made here: its standard error is that of the mean of all its samples, `sigma / sqrt(samples)`,
/// and its command records `--samples`. `None` for any other kind of reference. (The input of the
/// image-plane ceiling, [`crate::pmc::ceiling`].)
pub fn sample_variances(reference: &Reference) -> Option<Vec<f64>> {
    let ReferenceKind::Stored { command, .. } = &reference.kind else { return None };
    let samples: f64 = command.split("--samples ").nth(1)?.split_whitespace().next()?.parse().ok()?;
    Some(reference.std_err.iter().map(|se| se.0.iter().map(|s| s * s * samples).sum::<f64>() / 3.0).collect())
}
use rand::Rng;

/// Independent batches per pixel (the standard error's degrees of freedom + 1).
pub const BATCHES: u64 = 64;
/// The seed of every stored reference.
pub const SEED: u64 = 1;
/// Default pixel samples per pixel: the reference's standard error is then about 45 times below
/// the standard error of one 32-spp estimate, the largest budget `pmc-ip` runs.
pub const DEFAULT_SAMPLES: u64 = 1 << 16;

/// Computes the reference of `variant` with the test bed's `params` and `samples` pixel samples per
/// pixel (default [`DEFAULT_SAMPLES`]) on `threads` threads; the result does not depend on the
/// thread count.
pub fn compute_reference(
    variant: &str,
    params: &Params,
    samples: Option<u64>,
    threads: usize,
) -> Result<(ReferenceKey, StoredReference), ConfigError> {
    let samples = samples.unwrap_or(DEFAULT_SAMPLES);
    let per_batch = samples.div_ceil(BATCHES).max(1);
    let bed = CheckerImage::without_reference(variant, params)?;
    let key = bed.reference_key();
    let n = bed.integrals();
    let label = format!("checker-image/{variant}/reference");
    let pixel = |i: usize| {
        let mut m: [Moments; 3] = Default::default();
        for batch in 0..BATCHES {
            let key = StreamKey {
                seed: SEED,
                testbed: &label,
                estimator: "uniform_image",
                budget: per_batch,
                rep: batch,
                integral: i as u64,
            };
            let mut rng = key.rng();
            let mut sum = Rgb::ZERO;
            for _ in 0..per_batch {
                let (u, v): (f64, f64) = (rng.gen(), rng.gen());
                sum += bed.pixel_sample(i, u, v, &mut rng).0;
            }
            let mean = sum / per_batch as f64;
            for c in 0..3 {
                m[c].push(mean[c]);
            }
        }
        (Rgb([m[0].mean(), m[1].mean(), m[2].mean()]), Rgb([m[0].std_err(), m[1].std_err(), m[2].std_err()]))
    };
    let results = mcbench_core::parallel::map_indices(n, threads, pixel);
    if results.iter().any(|(m, se)| !m.is_finite() || !se.is_finite()) {
        return Err(ConfigError::invalid("reference", variant, "a pixel's estimate was not finite"));
    }
    let (w, h) = bed.resolution();
    let command = format!(
        "{} --samples {} (resolution {w}, seed {SEED}, {BATCHES} batches of {per_batch} uniform pixel samples per pixel)",
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

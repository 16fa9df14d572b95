//! Independent-sample Monte Carlo baselines (the papers' "MCMC", labelled "independent MC") and a
//! deliberately biased control.

pub mod brdf_is0_cv0;
pub mod clamped_is0_cv0;
pub mod is0_cv0;

use mcbench_core::accumulate::RgbMean;
use mcbench_core::error::EstimateError;
use mcbench_core::math::{Frame, Rgb};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::{HemisphereProbe, Task};

/// Averages `sample(probe, frame, rng)` while the budget lasts; refuses scenes without a surface.
pub(crate) fn average(
    task: &Task<'_>,
    rng: &mut StreamRng,
    mut sample: impl FnMut(&HemisphereProbe<'_>, &Frame, &mut StreamRng) -> Rgb,
) -> Result<Rgb, EstimateError> {
    let probe =
        task.hemisphere().ok_or_else(|| EstimateError::Refused("the test bed has no surface integrals".into()))?;
    // The shading frame is fixed for the whole estimate: built once, not per sample.
    let frame = Frame::around(probe.point().normal);
    let mut mean = RgbMean::new();
    while task.more() {
        mean.push(sample(&probe, &frame, rng));
    }
    Ok(mean.mean())
}

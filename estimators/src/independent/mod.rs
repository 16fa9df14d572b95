//! Independent-sample Monte Carlo baselines (the papers' "MCMC", labelled "independent MC") and a
//! deliberately biased control.

pub mod brdf_is0_cv0;
pub mod clamped_is0_cv0;
pub mod is0_cv0;

use crate::accumulate::RgbMean;
use crate::error::EstimateError;
use crate::math::{Frame, Rgb};
use crate::rng::StreamRng;
use crate::task::{HemisphereProbe, Task};

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

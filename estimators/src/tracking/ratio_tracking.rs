//! `ratio_tracking` (Novák et al. 2014; paper 002 Eq. 8 with a constant majorant): free flights
//! with `sigma_samp` = the declared majorant (or parameter `sigma_samp`), weight `*= 1 - r`.

use super::{sigma_samp_param, supports_transmittance, track, transmittance, Rule};
use crate::error::EstimateError;
use crate::estimator::{Bias, Estimator};
use crate::math::Rgb;
use crate::registry::EstimatorEntry;
use crate::rng::StreamRng;
use crate::samplers::free_flight::SamplingDensity;
use crate::task::Task;
use crate::testbed::{Needs, TestBed};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "ratio_tracking",
    paper: "002",
    label: "ratio tracking",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    summary: "ratio tracking with the constant majorant (paper 002 Eq. 8, [NSJ14])",
    build: |p| {
        p.reject_unknown("ratio_tracking", &["sigma_samp"])?;
        Ok(Box::new(RatioTracking { sigma_samp: sigma_samp_param(p, "ratio_tracking")? }))
    },
};

/// The estimator.
pub struct RatioTracking {
    /// Sampling extinction (`None`: the scene's majorant).
    pub sigma_samp: Option<f64>,
}

impl Estimator for RatioTracking {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        transmittance(task, rng, |probe, seg, rng| {
            let samp = SamplingDensity::constant(self.sigma_samp.unwrap_or(probe.majorant()));
            track(probe, (probe.ray().origin, probe.ray().dir), seg, &samp, None, Rule::Double, rng, |_| ())
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_transmittance(bed)
    }
}

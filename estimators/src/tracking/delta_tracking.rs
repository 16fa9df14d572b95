//! `delta_tracking` (Woodcock tracking, the classic baseline of paper 002): free flights with the
//! constant majorant (declared by the scene, or parameter `sigma_samp`, which must be a majorant).
//! Transmittance: terminate with probability `r = sigma_t / sigma_samp`. Radiance (particle
//! tracing): the analog collision of Eq. 7 (scatter with probability `a r`, absorb `(1 - a) r`,
//! pass `1 - r`), i.e. the terminating single particle model at a majorant. Point-light single
//! scattering: Woodcock tracking to the first real collision and a Woodcock shadow ray
//! ([`crate::single_scatter::delta_tracking`]).

use super::spm::{trace, SpmMode};
use super::{sigma_samp_param, track, transmittance, Rule};
use crate::accumulate::RgbMean;
use crate::error::{ConfigError, EstimateError};
use crate::estimator::{Bias, Estimator};
use crate::math::Rgb;
use crate::registry::EstimatorEntry;
use crate::rng::StreamRng;
use crate::samplers::free_flight::SamplingDensity;
use crate::task::Task;
use crate::testbed::{MediumQuantity, Needs, TestBed};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "delta_tracking",
    paper: "002",
    label: "Woodcock (delta) tracking",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    summary:
        "Woodcock tracking with the majorant: transmittance, analog particle tracing, or point-light single scattering",
    build: |p| {
        crate::single_scatter::SingleScatterOr::build(
            "delta_tracking",
            p,
            (&["sigma_samp"], |p| Ok(Box::new(DeltaTracking { sigma_samp: sigma_samp_param(p, "delta_tracking")? }))),
            (&["sigma_samp"], |p| {
                let sigma_samp = sigma_samp_param(p, "delta_tracking")?;
                Ok(Box::new(crate::single_scatter::delta_tracking::DeltaTrackingScatter { sigma_samp }))
            }),
        )
    },
};

/// The estimator.
pub struct DeltaTracking {
    /// Sampling extinction (`None`: the scene's majorant).
    pub sigma_samp: Option<f64>,
}

impl Estimator for DeltaTracking {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.medium().ok_or_else(|| EstimateError::Refused("the test bed has no medium".into()))?;
        let sigma = self.sigma_samp.unwrap_or(probe.majorant());
        if let MediumQuantity::Transmittance { .. } = probe.ray().quantity {
            return transmittance(task, rng, |probe, seg, rng| {
                track(
                    probe,
                    (probe.ray().origin, probe.ray().dir),
                    seg,
                    &SamplingDensity::constant(sigma),
                    None,
                    Rule::Delta,
                    rng,
                    |_| (),
                )
            });
        }
        let mut mean = RgbMean::new();
        while task.more() {
            probe.start_sample();
            mean.push(trace(&probe, sigma, SpmMode::Terminating, rng)?);
        }
        Ok(mean.mean())
    }
    fn validate(&self, bed: &dyn TestBed) -> Result<(), ConfigError> {
        match (bed.medium(), self.sigma_samp) {
            (Some(m), Some(s)) if s < m.majorant() => Err(ConfigError::invalid(
                "delta_tracking.sigma_samp",
                s,
                format!("delta tracking needs a majorant (>= {} on {}/{})", m.majorant(), bed.id(), bed.variant()),
            )),
            _ => Ok(()),
        }
    }
}

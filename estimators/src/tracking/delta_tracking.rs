//! `delta_tracking` (Woodcock tracking, the classic baseline of paper 002): free flights with the
//! constant majorant (declared by the scene, or parameter `sigma_samp` / `sigma_samp_ratio`, which
//! must give a majorant: a smaller density is refused as a skipped pair with the reason).
//! Transmittance: terminate with probability `r = sigma_t / sigma_samp`. Radiance (particle
//! tracing): the analog collision of Eq. 7 (scatter with probability `a r`, absorb `(1 - a) r`,
//! pass `1 - r`), i.e. the terminating single particle model at a majorant. Point-light single
//! scattering: Woodcock tracking to the first real collision and a Woodcock shadow ray
//! ([`crate::single_scatter::delta_tracking`]).

use super::constant::ConstantTracker;
use super::params::SigmaSampParams;
use super::spm::{trace, SpmMode};
use super::{ray_moments, transmittance, Rule, SigmaSamp};
use mcbench_core::accumulate::RgbMean;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::EstimateMoments;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;
use mcbench_core::testbed::{MediumQuantity, Needs, TestBed};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "delta_tracking",
    paper: "002",
    label: "Woodcock (delta) tracking",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    samplers: &["free_flight"],
    summary:
        "Woodcock tracking with the majorant: transmittance, analog particle tracing, or point-light single scattering",
    build: |p| {
        let p = parse::<SigmaSampParams>("delta_tracking", p)?;
        Ok(Box::new(crate::single_scatter::SingleScatterOr {
            single_scatter: Box::new(crate::single_scatter::delta_tracking::DeltaTrackingScatter {
                sigma_samp: p.sigma_samp,
            }),
            other: Box::new(DeltaTracking {
                sigma_samp: SigmaSamp::from_params(&p, "delta_tracking", SigmaSamp::Majorant)?,
            }),
        }))
    },
    params: ParamSpec::of::<SigmaSampParams>().display("delta tracking").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct DeltaTracking {
    /// Sampling extinction (a majorant).
    pub sigma_samp: SigmaSamp,
}

impl Estimator for DeltaTracking {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.medium().ok_or_else(|| EstimateError::Refused("the test bed has no medium".into()))?;
        let sigma = self.sigma_samp.resolve(probe.majorant());
        if let MediumQuantity::Transmittance { .. } = probe.ray().quantity {
            let mut tracker = ConstantTracker::default();
            return transmittance(task, rng, |probe, seg, rng| tracker.track(probe, seg, sigma, Rule::Delta, rng));
        }
        let mut mean = RgbMean::new();
        while task.more() {
            probe.start_sample();
            mean.push(trace(&probe, sigma, SpmMode::Terminating, rng)?);
        }
        Ok(mean.mean())
    }
    fn sample_moments(&self, task: &Task<'_>) -> Option<EstimateMoments> {
        ray_moments(task, self.sigma_samp, |_| Rule::Delta, None)
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        self.sigma_samp.require_majorant("delta_tracking", bed)
    }
}

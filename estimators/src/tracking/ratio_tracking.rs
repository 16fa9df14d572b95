//! `ratio_tracking` (Novák et al. 2014; paper 002 Eq. 8 with a constant majorant): free flights
//! with `sigma_samp` = the declared majorant (or parameter `sigma_samp` / `sigma_samp_ratio`, which
//! must give a majorant: a smaller density is the double particle model, and is refused here as a
//! skipped pair with the reason), weight `*= 1 - r`.

use super::constant::ConstantTracker;
use super::params::SigmaSampParams;
use super::{ray_moments, supports_transmittance, transmittance, Rule, SigmaSamp};
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::EstimateMoments;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;
use mcbench_core::testbed::{Needs, TestBed};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "ratio_tracking",
    paper: "002",
    label: "ratio tracking",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    samplers: &["free_flight"],
    summary: "ratio tracking with the constant majorant (paper 002 Eq. 8, [NSJ14])",
    build: |p| {
        let p = parse::<SigmaSampParams>("ratio_tracking", p)?;
        Ok(Box::new(RatioTracking { sigma_samp: SigmaSamp::from_params(&p, "ratio_tracking", SigmaSamp::Majorant)? }))
    },
    params: ParamSpec::of::<SigmaSampParams>().display("ratio tracking").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct RatioTracking {
    /// Sampling extinction (a majorant).
    pub sigma_samp: SigmaSamp,
}

impl Estimator for RatioTracking {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut tracker = ConstantTracker::default();
        transmittance(task, rng, |probe, seg, rng| {
            tracker.track(probe, seg, self.sigma_samp.resolve(probe.majorant()), Rule::Double, rng)
        })
    }
    fn sample_moments(&self, task: &Task<'_>) -> Option<EstimateMoments> {
        ray_moments(task, self.sigma_samp, |_| Rule::Double, None)
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_transmittance(bed)?;
        self.sigma_samp.require_majorant("ratio_tracking", bed)
    }
}

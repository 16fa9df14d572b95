//! `attenuation_driven` (paper 002 §4.3): the interaction points of the primary ray's residual
//! ratio tracking are the scattering points. They form a Poisson process of density `sigma_samp`
//! (paper's supplementary material), so by the Mecke formula
//! `E[sum_k T^(s_k-) g(s_k) / sigma_samp] = int T(s) g(s) ds` when `T^(s_k-)` uses only the
//! interactions before `s_k` (the weight *before* the interaction) and `g` = `a sigma_t rho I T_l
//! / r^2` with `sigma_t` already fetched by the tracker and `T_l` a shadow ray by residual ratio
//! tracking from every interaction point. The density mimics none of the integrand's factors; the
//! only gain is that the transmittance samples are reused (paper: poor importance sampling).

use super::transmittance::PrimaryTracker;
use super::{run, supports_single_scatter, ShadowRays};
use crate::tracking::params::ResidualParams;
use crate::tracking::residual_ratio_tracking::ResidualRatioTracking;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;
use mcbench_core::testbed::{Needs, TestBed};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "attenuation_driven",
    paper: "002",
    label: "attenuation-driven",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM.and(Needs::POINT_LIGHT),
    samplers: &["free_flight"],
    summary: "point-light single scattering at the primary ray's residual-ratio-tracking interaction points (density sigma_samp), a shadow ray from each",
    build: |p| {
        let p = parse::<ResidualParams>("attenuation_driven", p)?;
        Ok(Box::new(AttenuationDriven { cfg: ResidualRatioTracking::from_params(&p, "attenuation_driven")? }))
    },
    params: ParamSpec::of::<ResidualParams>().display("attenuation-driven").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct AttenuationDriven {
    /// Residual ratio tracking of the primary and shadow rays.
    pub cfg: ResidualRatioTracking,
}

impl Estimator for AttenuationDriven {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut state: Option<(PrimaryTracker, ShadowRays)> = None;
        run(task, rng, |probe, geo, rng| {
            let (tracker, shadows) = state.get_or_insert_with(|| {
                (PrimaryTracker::new(probe, geo, &self.cfg), ShadowRays::new(&self.cfg, probe.majorant()))
            });
            let run = tracker.track(probe, geo, geo.seg.1, rng)?;
            let mut sum = 0.0;
            for i in run.interactions() {
                let weight = run.before(i) * geo.emission(i.s, i.sigma_t) / run.sigma_samp();
                if weight != 0.0 {
                    sum += weight * shadows.transmittance(probe, geo.point(i.s), &geo.light, rng)?;
                }
            }
            Ok(sum)
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_single_scatter(bed)
    }
}

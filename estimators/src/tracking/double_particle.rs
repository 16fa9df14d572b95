//! `double_particle`: the Double Particle Model of paper 002 (Eq. 8, §3.3) for transmittance with
//! any constant `sigma_samp > 0` (parameter `sigma_samp`, default 1, or `sigma_samp_ratio` times
//! the declared majorant; a majorant or not): the transmitted particle's weight is multiplied by
//! `1 - r`, `r = sigma_diff / sigma_samp`, which is negative when `r > 1` (negative energy).
//! Optional control variate (negative difference extinction, §3.3): `control = 1` subtracts a
//! piecewise-linear main part through explorer points spaced `explorer_spacing`, `control = 2`
//! the constant at its mean (the L2-optimal constant of §3.4).

use super::constant::ConstantTracker;
use super::params::DoubleParticleParams;
use super::residual_ratio_tracking::{main_part, MainPart};
use super::{ray_moments, supports_transmittance, track, transmittance, Rule, SigmaSamp};
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::EstimateMoments;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::SamplingDensity;
use mcbench_core::task::Task;
use mcbench_core::testbed::{Needs, TestBed};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "double_particle",
    paper: "002",
    label: "double particle model",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    samplers: &["free_flight"],
    summary:
        "double particle model (Eq. 8) with any sigma_samp (default 1), optional control variate (1 linear, 2 mean)",
    build: |p| {
        let p = parse::<DoubleParticleParams>("double_particle", p)?;
        let sigma_samp = SigmaSamp::from_params(&p.sigma(), "double_particle", SigmaSamp::Absolute(1.0))?;
        let control = MainPart::from_control(p.control, "double_particle")?;
        Ok(Box::new(DoubleParticle { sigma_samp, control, spacing: p.explorer_spacing }))
    },
    params: ParamSpec::of::<DoubleParticleParams>().display("double particle").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct DoubleParticle {
    /// Constant sampling extinction.
    pub sigma_samp: SigmaSamp,
    /// The explorer main part subtracted, if any.
    pub control: Option<MainPart>,
    /// Explorer spacing.
    pub spacing: f64,
}

impl Estimator for DoubleParticle {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut main: Option<(SamplingDensity, f64)> = None;
        let mut tracker = ConstantTracker::default();
        transmittance(task, rng, |probe, seg, rng| {
            if let (Some(kind), None) = (self.control, &main) {
                main = Some(main_part(probe, seg, self.spacing, kind));
            }
            let sigma = self.sigma_samp.resolve(probe.majorant());
            match main.as_ref() {
                None => tracker.track(probe, seg, sigma, Rule::Double, rng),
                Some((m, t_main)) => {
                    let (samp, line) = (SamplingDensity::constant(sigma), (probe.ray().origin, probe.ray().dir));
                    Ok(track(probe, line, seg, &samp, Some(m), Rule::Double, rng, |_| ())? * t_main)
                }
            }
        })
    }
    fn sample_moments(&self, task: &Task<'_>) -> Option<EstimateMoments> {
        ray_moments(task, self.sigma_samp, |_| Rule::Double, self.control.map(|k| (k, self.spacing)))
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_transmittance(bed)
    }
    fn validate(&self, bed: &dyn TestBed) -> Result<(), ConfigError> {
        super::check_finite_variance("double_particle", self, self.sigma_samp, bed)
    }
}

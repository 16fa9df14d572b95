//! Transmittance by the Single Particle Model of paper 002 (Eq. 9, §3.3) with a constant
//! `sigma_samp` (parameter `sigma_samp`, default 1, or `sigma_samp_ratio` times the declared
//! majorant): the particle keeps only one offspring; on the ray's
//! transmittance only the transmitted one counts (a scattered or absorbed particle scores 0).
//! - `single_particle_terminating`: `q_scat = a r`, `q_tran = |1 - r|`; valid only for
//!   `0 <= r <= 2/(a+1)`: configurations whose declared majorant allows a larger `r` are refused
//!   before the run (`ConfigError`, exit 2), and an `r` out of range met at run time is refused.
//! - `single_particle_nonterminating`: Eq. 12 probabilities, any `r`.

use super::constant::ConstantTracker;
use super::params::SigmaSampParams;
use super::{ray_moments, supports_transmittance, transmittance, Rule, SigmaSamp};
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::EstimateMoments;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec, Params};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;
use mcbench_core::testbed::{Needs, TestBed};

/// `single_particle_terminating` registry entry.
pub static TERMINATING: EstimatorEntry = EstimatorEntry {
    id: "single_particle_terminating",
    paper: "002",
    label: "single particle, terminating",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    samplers: &["free_flight"],
    summary: "single particle model, terminating (Eq. 9, 19): refuses r > 2/(a+1) or r < 0",
    build: |p| build(p, "single_particle_terminating", true),
    params: ParamSpec::of::<SigmaSampParams>().display("single particle, terminating").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// `single_particle_nonterminating` registry entry.
pub static NONTERMINATING: EstimatorEntry = EstimatorEntry {
    id: "single_particle_nonterminating",
    paper: "002",
    label: "single particle, non-terminating",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    samplers: &["free_flight"],
    summary: "single particle model, non-terminating (Eq. 12, 20), any r",
    build: |p| build(p, "single_particle_nonterminating", false),
    params: ParamSpec::of::<SigmaSampParams>().display("single particle, non-terminating").words(crate::words::param),
    checks: Checks::DEFAULT,
};

fn build(p: &Params, id: &str, terminating: bool) -> Result<Box<dyn Estimator>, ConfigError> {
    let p = parse::<SigmaSampParams>(id, p)?;
    Ok(Box::new(SingleParticle { sigma_samp: SigmaSamp::from_params(&p, id, SigmaSamp::Absolute(1.0))?, terminating }))
}

/// The estimator.
pub struct SingleParticle {
    /// Constant sampling extinction.
    pub sigma_samp: SigmaSamp,
    /// Terminating (true) or non-terminating.
    pub terminating: bool,
}

/// Refuses a terminating model whose `r` can exceed `2/(a+1)` (paper 002 §3.3).
pub fn check_terminating(id: &str, sigma_samp: f64, bed: &dyn TestBed) -> Result<(), ConfigError> {
    let Some(m) = bed.medium() else { return Ok(()) };
    let (r_max, a) = (m.majorant() / sigma_samp, m.albedo());
    if r_max > 2.0 / (a + 1.0) {
        return Err(ConfigError::invalid(
            format!("{id}.sigma_samp"),
            sigma_samp,
            format!(
                "the terminating model is invalid on {}/{}: r = sigma_t/sigma_samp reaches {r_max:.4} > 2/(a+1) = {:.4} (albedo {a}); use sigma_samp >= {:.4} or the non-terminating model",
                bed.id(),
                bed.variant(),
                2.0 / (a + 1.0),
                m.majorant() * (a + 1.0) / 2.0
            ),
        ));
    }
    Ok(())
}

impl Estimator for SingleParticle {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut tracker = ConstantTracker::default();
        transmittance(task, rng, |probe, seg, rng| {
            let (a, sigma) = (probe.albedo(), self.sigma_samp.resolve(probe.majorant()));
            // One loop per rule (the rule is folded into each).
            if self.terminating {
                tracker.track(probe, seg, sigma, Rule::Terminating { a }, rng)
            } else {
                tracker.track(probe, seg, sigma, Rule::NonTerminating { a }, rng)
            }
        })
    }
    fn sample_moments(&self, task: &Task<'_>) -> Option<EstimateMoments> {
        let terminating = self.terminating;
        let rule = move |a| if terminating { Rule::Terminating { a } } else { Rule::NonTerminating { a } };
        ray_moments(task, self.sigma_samp, rule, None)
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_transmittance(bed)
    }
    fn validate(&self, bed: &dyn TestBed) -> Result<(), ConfigError> {
        if self.terminating {
            let majorant = bed.medium().map_or(1.0, |m| m.majorant());
            check_terminating("single_particle_terminating", self.sigma_samp.resolve(majorant), bed)?;
            Ok(())
        } else {
            super::check_finite_variance("single_particle_nonterminating", self, self.sigma_samp, bed)
        }
    }
}

//! Particle tracing of multiple scattering under the environment light with the Single Particle
//! Model (paper 002 §4.1, `SimulateParticle`): camera importons, constant `sigma_samp`
//! (parameter, default 1), scattering by the test bed's phase function (Rayleigh in paper 002's
//! media, isotropic or Henyey-Greenstein in `gradient-box`), environment radiance collected on exit.
//! `spm_terminating` (Eq. 9, `q_scat = a r`, `q_tran = |1 - r|`; refuses `r > 2/(a+1)`),
//! `spm_nonterminating` (Eq. 12), `spm_adaptive` (non-terminating when `r < 1` or
//! `q_scat + q_tran > 1`, terminating otherwise).

use super::params::SpmParams;
use super::single_particle::check_terminating;
use mcbench_core::accumulate::RgbMean;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::phase::Phase;
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::rayleigh;
use mcbench_core::task::{MediumProbe, Task};
use mcbench_core::testbed::{MediumQuantity, Needs, TestBed};
use rand::Rng;

/// The collision rule of a particle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpmMode {
    /// Eq. 9 with `q_scat = a r`, `q_tran = |1 - r|`.
    Terminating,
    /// Eq. 12 (normalised).
    NonTerminating,
    /// The paper's adaptive choice.
    Adaptive,
}

/// One importon path from the integral's ray (`SimulateParticle`): its radiance estimate.
pub fn trace(
    probe: &MediumProbe<'_>,
    sigma_samp: f64,
    mode: SpmMode,
    rng: &mut StreamRng,
) -> Result<Rgb, EstimateError> {
    let ray = *probe.ray();
    let (mut pos, mut dir, mut e) = (ray.origin, ray.dir, 1.0f64);
    let a = probe.albedo();
    let phase = probe.phase();
    loop {
        let Some((t0, t1)) = probe.clip(pos, dir) else { return Ok(probe.environment(dir) * e) };
        let mut s = t0;
        loop {
            s += -(-rng.gen::<f64>()).ln_1p() / sigma_samp;
            if s >= t1 {
                return Ok(probe.environment(dir) * e);
            }
            let p = pos + dir * s;
            let r = probe.sigma_t(p) / sigma_samp;
            let (mut q_scat, mut q_tran) = (a * r, (1.0 - r).abs());
            let q_sum = q_scat + q_tran;
            let normalise = match mode {
                SpmMode::Terminating => {
                    if r < 0.0 || r > 2.0 / (a + 1.0) {
                        return Err(EstimateError::Refused(format!("terminating model invalid at r = {r} > 2/(a+1)")));
                    }
                    false
                }
                SpmMode::NonTerminating => true,
                SpmMode::Adaptive => r < 1.0 || q_sum > 1.0,
            };
            if normalise && q_sum > 0.0 {
                q_scat /= q_sum;
                q_tran /= q_sum;
            }
            let xi: f64 = rng.gen();
            if xi < q_scat {
                e *= a * r / q_scat;
                pos = p;
                // Importance sampling the phase function exactly, so its value cancels in the
                // weight. Rayleigh keeps its own sampler (the paper 002 media's streams as pinned).
                dir = match phase {
                    Phase::Rayleigh => rayleigh::sample(dir, rng),
                    other => other.sample(dir, rng).0,
                };
                probe.scattered_ray();
                break;
            } else if xi < q_scat + q_tran {
                e *= (1.0 - r) / q_tran;
            } else {
                return Ok(Rgb::ZERO);
            }
        }
    }
}

macro_rules! spm_entry {
    ($name:ident, $id:literal, $label:literal, $display:literal, $mode:expr, $summary:literal) => {
        #[doc = concat!("`", $id, "` registry entry.")]
        pub static $name: EstimatorEntry = EstimatorEntry {
            id: $id,
            paper: "002",
            label: $label,
            bias: Bias::Unbiased,
            needs: Needs::MEDIUM,
            samplers: &["free_flight", "phase"],
            summary: $summary,
            build: |p| Ok(Box::new(Spm { sigma_samp: parse::<SpmParams>($id, p)?.sigma_samp, mode: $mode })),
            params: ParamSpec::of::<SpmParams>().display($display).words(crate::words::param),
            checks: Checks::DEFAULT,
        };
    };
}

spm_entry!(
    TERMINATING,
    "spm_terminating",
    "SPM terminating",
    "SPM terminating",
    SpmMode::Terminating,
    "particle tracing, terminating single particle model (Eq. 9)"
);
spm_entry!(
    NONTERMINATING,
    "spm_nonterminating",
    "SPM non-terminating",
    "SPM non-terminating",
    SpmMode::NonTerminating,
    "particle tracing, non-terminating single particle model (Eq. 12)"
);
spm_entry!(
    ADAPTIVE,
    "spm_adaptive",
    "SPM adaptive (SimulateParticle)",
    "SPM adaptive",
    SpmMode::Adaptive,
    "particle tracing, the paper's adaptive SimulateParticle"
);

/// A particle tracer.
pub struct Spm {
    /// Constant sampling extinction.
    pub sigma_samp: f64,
    /// Collision rule.
    pub mode: SpmMode,
}

impl Estimator for Spm {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.medium().ok_or_else(|| EstimateError::Refused("the test bed has no medium".into()))?;
        let mut mean = RgbMean::new();
        while task.more() {
            probe.start_sample();
            mean.push(trace(&probe, self.sigma_samp, self.mode, rng)?);
        }
        Ok(mean.mean())
    }
    /// A terminating model whose `r` can exceed `2/(a+1)` on this bed is a skipped pair with the
    /// reason (as delta tracking below a majorant), so a sweep over sigma_samp and media runs it
    /// only where it is valid; [`Estimator::validate`] refuses it with the same reason.
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        match bed.medium().map(|m| m.ray(0).quantity) {
            Some(MediumQuantity::Radiance) => {}
            _ => return Err("particle tracing estimates scattered radiance; this variant is a transmittance".into()),
        }
        if self.mode == SpmMode::Terminating {
            check_terminating("spm_terminating", self.sigma_samp, bed).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
    fn validate(&self, bed: &dyn TestBed) -> Result<(), ConfigError> {
        if self.mode == SpmMode::Terminating {
            check_terminating("spm_terminating", self.sigma_samp, bed)?;
        }
        Ok(())
    }
}

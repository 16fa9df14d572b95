//! `double_particle`: the Double Particle Model of paper 002 (Eq. 8, §3.3) for transmittance with
//! any constant `sigma_samp > 0` (parameter, default 1; a majorant or not): the transmitted
//! particle's weight is multiplied by `1 - r`, `r = sigma_t / sigma_samp`, which is negative when
//! `r > 1` (negative energy). Optional `control = 1` subtracts a piecewise-linear main part
//! through explorer points spaced `explorer_spacing` (negative difference extinction, §3.3).

use super::residual_ratio_tracking::main_part;
use super::{supports_transmittance, track, transmittance, Rule};
use crate::error::{ConfigError, EstimateError};
use crate::estimator::{Bias, Estimator};
use crate::math::Rgb;
use crate::registry::EstimatorEntry;
use crate::rng::StreamRng;
use crate::samplers::free_flight::SamplingDensity;
use crate::task::Task;
use crate::testbed::{Needs, TestBed};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "double_particle",
    paper: "002",
    label: "double particle model",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    summary: "double particle model (Eq. 8) with any sigma_samp (default 1), optional control variate",
    build: |p| {
        p.reject_unknown("double_particle", &["sigma_samp", "control", "explorer_spacing"])?;
        let sigma_samp = super::sigma_samp_param(p, "double_particle")?.unwrap_or(1.0);
        let control = p.f64_in("control", 0.0, 0.0, 1.0)? == 1.0;
        let spacing = p.f64("explorer_spacing", 0.5)?;
        if spacing <= 0.0 {
            return Err(ConfigError::invalid("double_particle.explorer_spacing", spacing, "must be > 0"));
        }
        Ok(Box::new(DoubleParticle { sigma_samp, control, spacing }))
    },
};

/// The estimator.
pub struct DoubleParticle {
    /// Constant sampling extinction.
    pub sigma_samp: f64,
    /// Subtract the explorer main part.
    pub control: bool,
    /// Explorer spacing.
    pub spacing: f64,
}

impl Estimator for DoubleParticle {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut main: Option<(SamplingDensity, f64)> = None;
        transmittance(task, rng, |probe, seg, rng| {
            if self.control && main.is_none() {
                main = Some(main_part(probe, seg, self.spacing));
            }
            let samp = SamplingDensity::constant(self.sigma_samp);
            let m = main.as_ref();
            let e = track(
                probe,
                (probe.ray().origin, probe.ray().dir),
                seg,
                &samp,
                m.map(|x| &x.0),
                Rule::Double,
                rng,
                |_| (),
            )?;
            Ok(e * m.map_or(1.0, |x| x.1))
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_transmittance(bed)
    }
}

//! `delta_tracking` on single scattering (Woodcock tracking, the classic baseline of paper 002
//! Fig. 12): free flights with the constant majorant `sigma_bar` along the primary ray until the
//! first real collision (probability `sigma_t / sigma_bar` at each tentative one), whose density
//! is `T(t) sigma_t(t)`; there the estimate is `a rho I V / r^2` with `V` a Woodcock shadow ray
//! (0 or 1, unbiased for `T_l`). No collision before the medium ends: 0.

use super::{run, supports_single_scatter};
use crate::tracking::{track, Rule};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::Estimator;
use mcbench_core::math::Rgb;
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::SamplingDensity;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use rand::Rng;

/// The estimator.
pub struct DeltaTrackingScatter {
    /// Sampling extinction (`None`: the scene's majorant); must be a majorant.
    pub sigma_samp: Option<f64>,
}

impl Estimator for DeltaTrackingScatter {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        run(task, rng, |probe, geo, rng| {
            let majorant = self.sigma_samp.unwrap_or(probe.majorant());
            let samp = SamplingDensity::constant(majorant);
            let (mut s, t1) = geo.seg;
            loop {
                s = samp.sample(s, rng.gen::<f64>());
                if s >= t1 {
                    return Ok(0.0);
                }
                let sigma = probe.sigma_t(geo.point(s));
                let r = sigma / majorant;
                if !(0.0..=1.0).contains(&r) {
                    return Err(EstimateError::Refused(format!(
                        "delta tracking needs a majorant, but sigma_t / sigma_samp = {r}"
                    )));
                }
                if rng.gen::<f64>() < r {
                    break;
                }
            }
            let p = geo.point(s);
            let to = geo.light.position - p;
            let dist = to.length();
            if dist == 0.0 {
                return Ok(0.0); // a collision exactly on the light: probability zero
            }
            probe.shadow_ray();
            let w = to / dist;
            let v = match probe.clip(p, w).map(|(a, b)| (a, b.min(dist))).filter(|(a, b)| b > a) {
                Some(seg) => track(probe, (p, w), seg, &samp, None, Rule::Delta, rng, |_| ())?,
                None => 1.0,
            };
            // f / p with p = T sigma_t: a rho I V / r^2 (emission divides out sigma_t).
            Ok(if v == 0.0 { 0.0 } else { geo.emission(s, 1.0) * v })
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_single_scatter(bed)
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

//! Single scattering of a point light in a heterogeneous medium (paper 002 §4.3, Eq. 22, Fig. 12):
//! the radiance a pixel ray receives from the light by one scattering event,
//!
//! `L = int_{t0}^{t1} T(t) a sigma_t(t) rho(cos) I T_l(t) / r(t)^2 dt`, `r^2 = D^2 + (t - t_l)^2`,
//!
//! estimated one primary ray per sample (`probe.start_sample()`, so the number of primary rays a
//! fetch budget buys is the `samples` column), each shadow ray counted as a ray:
//! - `ray_marching` (biased control): fixed steps along both rays;
//! - `delta_tracking`: Woodcock tracking to the first real collision, a Woodcock shadow ray;
//! - `attenuation_driven`: the interaction points of the primary ray's residual ratio tracking
//!   (density `sigma_samp`) are the scattering points;
//! - `attenuation_driven_sir`: the same candidates, shadow rays only for `shadow_rays` of them
//!   resampled by importance (SIR);
//! - `source_driven`: equiangular (Cauchy) scattering points, the `1 / r^2` peak;
//! - `scattering_driven`: scattering points from `T sigma_t` mimicked with the primary ray's
//!   piecewise-linear main part;
//! - `mis`: one source- and one scattering-driven point per ray, balance heuristic.
//!
//! All but the first two evaluate `T(t)` at any point with the continuous transmittance estimate
//! of [`transmittance`] (the primary ray's interaction data with the control variate's
//! exponential fall-off) and trace shadow rays by residual ratio tracking ([`ShadowRays`]).
//! `ray_marching`, `delta_tracking` and `mis` are ids shared with the transmittance trackers and
//! paper 003's MIS: [`SingleScatterOr`] dispatches on the test bed's quantity.

pub mod attenuation_driven;
pub mod attenuation_driven_sir;
pub mod delta_tracking;
pub mod mis;
pub mod params;
pub mod points;
pub mod ray_marching;
pub mod scattering_driven;
pub mod source_driven;
pub mod transmittance;

use crate::tracking::residual_ratio_tracking::{main_part_along, MainPart, RecentMaximum, ResidualRatioTracking};
use crate::tracking::{track, Rule};
use mcbench_core::accumulate::RgbMean;
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::Estimator;
use mcbench_core::lighting::PointLight;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::phase::Phase;
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::SamplingDensity;
use mcbench_core::task::{MediumProbe, Task};
use mcbench_core::testbed::{MediumQuantity, TestBed};

/// The geometry of one pixel's integral: the primary ray's medium segment and the light.
#[derive(Clone, Copy, Debug)]
pub struct Geometry {
    /// Ray origin.
    pub origin: Vec3,
    /// Unit ray direction.
    pub dir: Vec3,
    /// The medium segment `[t0, t1]` of the ray.
    pub seg: (f64, f64),
    /// The light.
    pub light: PointLight,
    /// Ray parameter closest to the light.
    pub t_l: f64,
    /// Distance between the ray and the light.
    pub d: f64,
    /// Albedo.
    pub albedo: f64,
    /// Phase function.
    pub phase: Phase,
}

impl Geometry {
    /// The point at ray parameter `t`.
    pub fn point(&self, t: f64) -> Vec3 {
        self.origin + self.dir * t
    }
    /// Everything of the integrand at `t` but the two transmittances:
    /// `a sigma_t rho(cos) I / r^2` (the light's flux travels from the light to `p`, then `-dir`).
    pub fn emission(&self, t: f64, sigma_t: f64) -> f64 {
        let to_p = self.point(t) - self.light.position;
        let r2 = to_p.dot(to_p);
        if sigma_t == 0.0 || r2 == 0.0 {
            return 0.0;
        }
        let cos = to_p.dot(-self.dir) / r2.sqrt();
        self.albedo * sigma_t * self.phase.eval(cos) * self.light.intensity / r2
    }
}

/// The probe and geometry of a single-scatter task, or `None` when its ray misses the medium
/// (then the integral is exactly zero). Refuses integrals that are not point-light single
/// scattering.
pub fn setup<'t>(task: &'t Task<'t>) -> Result<(MediumProbe<'t>, Option<Geometry>), EstimateError> {
    let probe = task.medium().ok_or_else(|| EstimateError::Refused("the test bed has no medium".into()))?;
    let ray = *probe.ray();
    let MediumQuantity::SingleScatter { light } = ray.quantity else {
        return Err(EstimateError::Refused(
            "a single-scatter estimator needs a point-light single-scatter integral".into(),
        ));
    };
    let Some(seg) = crate::tracking::segment(&probe) else { return Ok((probe, None)) };
    let (t_l, d) = light.closest_approach(ray.origin, ray.dir);
    let (albedo, phase) = (probe.albedo(), probe.phase());
    Ok((probe, Some(Geometry { origin: ray.origin, dir: ray.dir, seg, light, t_l, d, albedo, phase })))
}

/// Runs a single-scatter estimator: averages `one()` over primary rays (one sample each) while
/// the budget lasts. A ray that misses the medium is exact (zero) and costs one sample.
pub fn run(
    task: &Task<'_>,
    rng: &mut StreamRng,
    mut one: impl FnMut(&MediumProbe<'_>, &Geometry, &mut StreamRng) -> Result<f64, EstimateError>,
) -> Result<Rgb, EstimateError> {
    let (probe, geo) = setup(task)?;
    let Some(geo) = geo else {
        probe.start_sample();
        return Ok(Rgb::ZERO);
    };
    let mut mean = RgbMean::new();
    while task.more() {
        probe.start_sample();
        mean.push(Rgb::splat(one(&probe, &geo, rng)?));
    }
    Ok(mean.mean())
}

/// True when `bed` asks for point-light single scattering.
pub fn is_single_scatter(bed: &dyn TestBed) -> bool {
    bed.medium().is_some_and(|m| matches!(m.ray(0).quantity, MediumQuantity::SingleScatter { .. }))
}

/// Refuses (as a skipped pair) test beds that are not point-light single scattering.
pub fn supports_single_scatter(bed: &dyn TestBed) -> Result<(), String> {
    if is_single_scatter(bed) {
        Ok(())
    } else {
        Err("estimates point-light single scattering (paper 002 §4.3); this test bed asks for something else".into())
    }
}

/// Shadow rays towards the light by residual ratio tracking (paper 002 §4.2-4.3): a
/// piecewise-linear main part through explorer points along each shadow ray (cheap fetches) and a
/// constant `sigma_samp`, the largest `|sigma_diff|` of the last few shadow rays.
pub struct ShadowRays {
    spacing: f64,
    kind: MainPart,
    memory: RecentMaximum,
}

impl ShadowRays {
    /// Shadow rays with the residual tracking parameters `cfg` in a medium with this majorant.
    pub fn new(cfg: &ResidualRatioTracking, majorant: f64) -> Self {
        ShadowRays { spacing: cfg.spacing, kind: cfg.kind, memory: cfg.memory(majorant) }
    }
    /// An unbiased estimate of the transmittance from `p` to the light (one ray).
    pub fn transmittance(
        &mut self,
        probe: &MediumProbe<'_>,
        p: Vec3,
        light: &PointLight,
        rng: &mut StreamRng,
    ) -> Result<f64, EstimateError> {
        probe.shadow_ray();
        let to = light.position - p;
        let r = to.length();
        if r == 0.0 {
            return Ok(1.0);
        }
        let w = to / r;
        let Some(seg) = probe.clip(p, w).map(|(a, b)| (a, b.min(r))).filter(|(a, b)| b > a) else {
            return Ok(1.0);
        };
        let (main, tm) = main_part_along(probe, (p, w), seg, self.spacing, self.kind);
        let sigma = self.memory.sigma();
        let mut seen = 0.0f64;
        let e = track(probe, (p, w), seg, &SamplingDensity::constant(sigma), Some(&main), Rule::Double, rng, |i| {
            seen = seen.max(i.sigma_diff.abs())
        })?;
        self.memory.push(seen);
        Ok(e * tm)
    }
}

/// One id serving point-light single-scatter integrals with `single_scatter` and every other test
/// bed with `other` (paper 002 names `ray_marching`, `delta_tracking` and `mis` for single
/// scattering too, and one id is one registry entry).
pub struct SingleScatterOr {
    /// Used on single-scatter integrals.
    pub single_scatter: Box<dyn Estimator>,
    /// Used elsewhere.
    pub other: Box<dyn Estimator>,
}

impl SingleScatterOr {
    fn pick(&self, task: &Task<'_>) -> &dyn Estimator {
        match task.medium().map(|m| m.ray().quantity) {
            Some(MediumQuantity::SingleScatter { .. }) => self.single_scatter.as_ref(),
            _ => self.other.as_ref(),
        }
    }
}

impl Estimator for SingleScatterOr {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        self.pick(task).estimate(task, rng)
    }
    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        match tasks.first() {
            Some(t) => self.pick(t).estimate_sequence(tasks, rng),
            None => Ok(Vec::new()),
        }
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        if is_single_scatter(bed) {
            self.single_scatter.supports(bed)
        } else {
            self.other.supports(bed)
        }
    }
    fn validate(&self, bed: &dyn TestBed) -> Result<(), ConfigError> {
        if is_single_scatter(bed) {
            self.single_scatter.validate(bed)
        } else {
            self.other.validate(bed)
        }
    }
    fn sample_moments(&self, task: &Task<'_>) -> Option<mcbench_core::estimator::EstimateMoments> {
        self.pick(task).sample_moments(task)
    }
}

#[cfg(test)]
mod tests;

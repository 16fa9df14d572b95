//! `ray_marching` on single scattering (the biased control of paper 002 Fig. 12): one step `h`
//! along the primary ray with one random offset `u`, `T(t_j) = exp(-h (sum_{i<j} sigma_i + u
//! sigma_j))` at `t_j = t0 + (j + u) h`, and at every step a shadow ray marched with the same step
//! (its own offset): `L = h sum_j T(t_j) a sigma_j rho I T_l(t_j) / r_j^2`. Biased by construction
//! (Jensen: `E[exp(-X)] != exp(-E[X])`).
//!
//! `jitter` (default 1) draws the offsets at random; `jitter = 0` fixes them at 1/2: the paper's
//! "noise free but biased" marcher (a deterministic estimate per pixel).
//!
//! Step: parameter `step` (default 0.9, as paper 002 Fig. 9) under a sample budget, and under a
//! fetch budget when `step` is given (the rays keep it and the budget buys more of them: a coarse
//! `step` makes the harness's detectably biased control). Under a fetch budget `B` without `step`,
//! one primary ray spends about the budget (the paper's "single ray per pixel" of Fig. 12): with
//! `L` the primary segment and `R = int r_in(t) dt` the summed shadow lengths inside the sphere
//! (geometry, no fetches), `L / h + R / h^2 = B` gives `h = (L + sqrt(L^2 + 4 B R)) / (2 B)`, and
//! exactly one primary ray is marched.

use super::{run, setup, supports_single_scatter, Geometry};
use mcbench_core::budget::BudgetKind;
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::Estimator;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::quadrature::gauss_legendre;
use mcbench_core::rng::StreamRng;
use mcbench_core::task::{MediumProbe, Task};
use mcbench_core::testbed::TestBed;
use rand::Rng;

/// The estimator.
pub struct RayMarchingScatter {
    /// Step length under a sample budget (and under a fetch budget when `fixed_step`).
    pub step: f64,
    /// The step was given explicitly: keep it under a fetch budget too.
    pub fixed_step: bool,
    /// Random offsets (else 1/2).
    pub jitter: bool,
}

impl RayMarchingScatter {
    /// The offset of a marched ray.
    fn offset(&self, rng: &mut StreamRng) -> f64 {
        if self.jitter {
            rng.gen()
        } else {
            0.5
        }
    }
}

/// The shadow segment from `p` to the light inside the medium (origin, direction, segment).
fn shadow_segment(probe: &MediumProbe<'_>, p: Vec3, geo: &Geometry) -> Option<(Vec3, (f64, f64))> {
    let to = geo.light.position - p;
    let r = to.length();
    (r > 0.0).then_some(())?;
    let w = to / r;
    probe.clip(p, w).map(|(a, b)| (w, (a, b.min(r)))).filter(|(_, (a, b))| b > a)
}

/// `int_{t0}^{t1}` of the shadow length inside the medium (32-point Gauss-Legendre; geometry only).
fn summed_shadow_length(probe: &MediumProbe<'_>, geo: &Geometry) -> f64 {
    let (x, w) = gauss_legendre(32);
    let (t0, t1) = geo.seg;
    let (c, h) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
    x.iter()
        .zip(&w)
        .map(|(xi, wi)| wi * shadow_segment(probe, geo.point(c + h * xi), geo).map_or(0.0, |(_, (a, b))| b - a))
        .sum::<f64>()
        * h
}

/// `exp(-h sum sigma)` over `n` steps of `[a, b]` of a line with offset `u`.
fn marched(probe: &MediumProbe<'_>, o: Vec3, w: Vec3, (a, b): (f64, f64), h: f64, u: f64) -> f64 {
    let n = ((b - a) / h).ceil().max(1.0);
    let hs = (b - a) / n;
    let tau: f64 = (0..n as u64).map(|k| probe.sigma_t(o + w * (a + (k as f64 + u) * hs))).sum::<f64>() * hs;
    (-tau).exp()
}

impl RayMarchingScatter {
    /// One primary ray marched with step `h` (rounded down to divide the segment).
    fn one(&self, probe: &MediumProbe<'_>, geo: &Geometry, h: f64, rng: &mut StreamRng) -> f64 {
        let (t0, t1) = geo.seg;
        let n = ((t1 - t0) / h).ceil().max(1.0);
        let h = (t1 - t0) / n;
        let u = self.offset(rng);
        let (mut tau, mut sum) = (0.0, 0.0);
        for j in 0..n as u64 {
            let t = t0 + (j as f64 + u) * h;
            let sigma = probe.sigma_t(geo.point(t));
            let t_cam = (-(tau + u * h * sigma)).exp();
            tau += h * sigma;
            if sigma > 0.0 {
                let t_l = match shadow_segment(probe, geo.point(t), geo) {
                    Some((w, seg)) => {
                        probe.shadow_ray();
                        marched(probe, geo.point(t), w, seg, h, self.offset(rng))
                    }
                    None => 1.0,
                };
                sum += h * t_cam * geo.emission(t, sigma) * t_l;
            }
        }
        sum
    }
}

impl Estimator for RayMarchingScatter {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let budget = task.budget();
        if budget.kind != BudgetKind::Fetches || self.fixed_step {
            return run(task, rng, |probe, geo, rng| Ok(self.one(probe, geo, self.step, rng)));
        }
        // One primary ray spends the fetch budget (module doc).
        let (probe, geo) = setup(task)?;
        probe.start_sample();
        let Some(geo) = geo else { return Ok(Rgb::ZERO) };
        let len = geo.seg.1 - geo.seg.0;
        let (b, r) = (budget.amount as f64, summed_shadow_length(&probe, &geo));
        let h = (len + (len * len + 4.0 * b * r).sqrt()) / (2.0 * b);
        Ok(Rgb::splat(self.one(&probe, &geo, h, rng)))
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_single_scatter(bed)
    }
}

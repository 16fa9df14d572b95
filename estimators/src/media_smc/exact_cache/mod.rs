//! How far paper 000's Eq. 7 estimator can go on `gradient-box` (book: paper-000.md, "How far Eq. 7
//! can go"): the work ratio (variance x rays per estimate) of the independent path tracer over
//! (1) Eq. 7 with the cache every SMC estimator of the family converges to, the true radiance field
//! ([`field::Field`]): the exact-cache limit, [`Limits::work_ratio`]; and (2) the floor no cache
//! and no direction sampling can go below, the variance of the camera ray's own free flight
//! ([`first_flight_variance`]): the family's bound, [`Limits::family_bound`].
//!
//! At a vertex `x` the family's estimate of the in-scattered radiance is `G + (f - g) / p` (Fig. 2):
//! `f = L_hat(x, w) Phi` from the traced flight (itself an estimate: the next vertex's estimate, or
//! the background), `g` the cache's radiance times the phase function, `G` its integral, `w ~ p`.
//! For a given `p` its conditional variance is `E[(f - g)^2 / p^2]`, smallest when
//! `g = E[f | w] = L(x, w) Phi`, the exact radiance: what remains is the variance of the flight's
//! own estimate (where it collides or escapes, and what the next vertex's estimate adds), which no
//! cache removes, since `f` is always a traced sample. Here `G = L_i(x)`, `g = L(x, w) / 4 pi`, and
//! `p` is the cache's own importance sampling with the exact radiance (`is1`): proportional to the
//! luminance of `L(x', w)` over the direction cells at the node `x'` nearest `x`, mixed with
//! [`DEFENSIVE`] of the uniform density. The camera ray's pass-or-collide choice, absorption weights
//! and Russian roulette are those of [`crate::media_smc::walk`] ([`albedo_factor`]); rays count one
//! per flight.
//!
//! The exact-cache value is therefore a limit only for the estimators whose importance sampling
//! follows the cache (a converged cache gives exactly this `p`): a different `p` changes the
//! variance that remains, so it bounds a narrower family than the papers' claim, and a learned
//! cache's `p` may do better. The family's bound holds for any cache and any `p`.

pub mod field;

use crate::media_smc::walk::albedo_factor;
use field::{direction, exit_distance, Field};
use mcbench_core::math::{Rgb, Vec3};
use rand::Rng;
use rand_pcg::Pcg64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The share of the uniform density in the exact cache's direction sampling.
pub const DEFENSIVE: f64 = 0.05;

/// The exact cache: the field and, per node, the cumulative direction distribution.
pub struct ExactCache<'f> {
    field: &'f Field,
    /// Per node, `m^2` cumulative probabilities of the direction cells.
    cdf: Vec<f64>,
}

/// One estimator's per-pixel statistics.
#[derive(Clone, Debug)]
pub struct Measured {
    /// Per pixel, the mean estimate.
    pub mean: Vec<Rgb>,
    /// Per pixel, the variance of one estimate.
    pub variance: Vec<Rgb>,
    /// Mean variance of one estimate over pixels and channels.
    pub mean_variance: f64,
    /// Rays (flights) per estimate.
    pub rays: f64,
}

impl<'f> ExactCache<'f> {
    /// The cache of `field`: direction tables at every node from the exact radiance.
    pub fn new(field: &'f Field) -> Self {
        let (n, m) = (field.resolution().n, field.resolution().m);
        let cdf: Vec<f64> = (0..n * n * n)
            .into_par_iter()
            .flat_map_iter(|i| {
                let x = field.node(i);
                let lum: Vec<f64> = (0..m * m)
                    .map(|c| {
                        let w = direction(((c % m) as f64 + 0.5) / m as f64, ((c / m) as f64 + 0.5) / m as f64);
                        field.radiance(x, w).mean().max(0.0)
                    })
                    .collect();
                let total: f64 = lum.iter().sum();
                let cells = (m * m) as f64;
                let mut acc = 0.0;
                lum.into_iter()
                    .map(move |l| {
                        let share = if total > 0.0 { l / total } else { 1.0 / cells };
                        acc += (1.0 - DEFENSIVE) * share + DEFENSIVE / cells;
                        acc
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        ExactCache { field, cdf }
    }

    /// A direction at `x` and its density (per steradian).
    fn sample<R: Rng + ?Sized>(&self, x: Vec3, rng: &mut R) -> (Vec3, f64) {
        let m = self.field.resolution().m;
        let cells = m * m;
        let row = &self.cdf[self.field.nearest_node(x) * cells..][..cells];
        let u = rng.gen::<f64>() * row[cells - 1];
        let c = row.partition_point(|&v| v <= u).min(cells - 1);
        let p_cell = (row[c] - if c > 0 { row[c - 1] } else { 0.0 }) / row[cells - 1];
        let s = ((c % m) as f64 + rng.gen::<f64>()) / m as f64;
        let t = ((c / m) as f64 + rng.gen::<f64>()) / m as f64;
        (direction(s, t), p_cell * cells as f64 / (4.0 * PI))
    }

    /// One estimate of Eq. 7 along `dir` from `origin` (on the cube's boundary) with the exact
    /// cache at every vertex, and its flights.
    pub fn path<R: Rng + ?Sized>(&self, origin: Vec3, dir: Vec3, rng: &mut R) -> (Rgb, u64) {
        let scene = self.field.scene();
        let (mut pos, mut dir, mut throughput, mut flights) = (origin, dir, 1.0, 0u64);
        // Per vertex: G, g (radiance, without the phase), pdf, albedo factor.
        let mut vertices: Vec<(Rgb, Rgb, f64, f64)> = Vec::new();
        let mut radiance = loop {
            flights += 1;
            let d = exit_distance(pos, dir);
            let s = -(1.0 - rng.gen::<f64>()).ln() / scene.sigma_t;
            if s >= d {
                break scene.background.eval(dir);
            }
            let x = pos + dir * s;
            let Some(factor) = albedo_factor(scene.albedo, &mut throughput, rng) else { break Rgb::ZERO };
            let (w, pdf) = self.sample(x, rng);
            vertices.push((self.field.in_scattered(x), self.field.radiance(x, w), pdf, factor));
            pos = x;
            dir = w;
        };
        let phase = 1.0 / (4.0 * PI);
        while let Some((big_g, g, pdf, factor)) = vertices.pop() {
            radiance = (big_g + (radiance - g) * (phase / pdf)) * factor;
        }
        (radiance, flights)
    }
}

/// One path of the independent path tracer (`is0_cv0` on a medium: free flights, isotropic
/// directions) in the field's scene, and its flights.
pub fn independent_path<R: Rng + ?Sized>(field: &Field, origin: Vec3, dir: Vec3, rng: &mut R) -> (Rgb, u64) {
    let scene = field.scene();
    let (mut pos, mut dir, mut weight, mut throughput, mut flights) = (origin, dir, 1.0, 1.0, 0u64);
    loop {
        flights += 1;
        let d = exit_distance(pos, dir);
        let s = -(1.0 - rng.gen::<f64>()).ln() / scene.sigma_t;
        if s >= d {
            return (scene.background.eval(dir) * weight, flights);
        }
        pos = pos + dir * s;
        let Some(a) = albedo_factor(scene.albedo, &mut throughput, rng) else { return (Rgb::ZERO, flights) };
        weight *= a;
        dir = direction(rng.gen(), rng.gen());
    }
}

/// The camera ray of pixel `(px, py)` of a `resolution`-square image: orthographic along `+y`,
/// pixel centres over `x, z in [-0.5, 0.5]`, row 0 at `z = +0.5` (`gradient-box`).
pub fn camera_ray(resolution: usize, px: usize, py: usize) -> (Vec3, Vec3) {
    let r = resolution as f64;
    let origin = Vec3::new(-0.5 + (px as f64 + 0.5) / r, -0.5, 0.5 - (py as f64 + 0.5) / r);
    (origin, Vec3::new(0.0, 1.0, 0.0))
}

/// `paths` estimates per pixel of a `resolution`-square image by `estimate`, each pixel on its own
/// stream of `seed` (the same numbers whatever the thread count).
pub fn measure<F>(resolution: usize, paths: usize, seed: u64, estimate: F) -> Measured
where
    F: Fn(Vec3, Vec3, &mut Pcg64) -> (Rgb, u64) + Sync,
{
    let per_pixel: Vec<(Rgb, Rgb, u64)> = (0..resolution * resolution)
        .into_par_iter()
        .map(|i| {
            let mut rng =
                <Pcg64 as rand::SeedableRng>::seed_from_u64(seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            let (o, d) = camera_ray(resolution, i % resolution, i / resolution);
            let (mut mean, mut m2, mut flights) = (Rgb::ZERO, Rgb::ZERO, 0u64);
            for k in 0..paths {
                let (v, f) = estimate(o, d, &mut rng);
                flights += f;
                // Welford, per channel.
                let delta = v - mean;
                mean += delta / (k + 1) as f64;
                m2 += delta * (v - mean);
            }
            (mean, m2 / (paths - 1).max(1) as f64, flights)
        })
        .collect();
    let pixels = per_pixel.len() as f64;
    Measured {
        mean: per_pixel.iter().map(|p| p.0).collect(),
        variance: per_pixel.iter().map(|p| p.1).collect(),
        mean_variance: per_pixel.iter().map(|p| p.1.mean()).sum::<f64>() / pixels,
        rays: per_pixel.iter().map(|p| p.2 as f64).sum::<f64>() / (pixels * paths as f64),
    }
}

/// The proven floor of any Eq. 7 estimator's variance on a camera ray (paper 000 Eq. 7 samples
/// the camera ray's free flight: it passes with probability `exp(-sigma_t d)` and sees `L_b`, or
/// collides at `s` with density `sigma_t exp(-sigma_t s)` and estimates `a L_i(x(s))`). Whatever
/// the cache, the estimate given that first flight has mean `L_b` or `a L_i(x(s))`, so by the law
/// of total variance its variance is at least the variance of those means over the flight,
/// computed here per pixel and channel by quadrature over `s` with `segments` segments (the
/// field's `L_i`), and averaged as [`Measured::mean_variance`].
pub fn first_flight_variance(field: &Field, resolution: usize, segments: usize) -> f64 {
    let scene = field.scene();
    let sigma = scene.sigma_t;
    let mut total = 0.0;
    for i in 0..resolution * resolution {
        let (o, d) = camera_ray(resolution, i % resolution, i / resolution);
        let length = exit_distance(o, d);
        let pass = (-sigma * length).exp();
        let lb = scene.background.eval(d);
        let (mut m1, mut m2) = (lb * pass, lb * lb * pass);
        let step = length / segments as f64;
        let mut before = 1.0;
        for j in 0..segments {
            let after = (-sigma * step * (j + 1) as f64).exp();
            let v = field.in_scattered(o + d * (step * (j as f64 + 0.5))) * scene.albedo;
            m1 += v * (before - after);
            m2 += v * v * (before - after);
            before = after;
        }
        total += (m2 - m1 * m1).mean();
    }
    total / (resolution * resolution) as f64
}

/// The limits at one extinction: the independent path tracer's and the exact cache's statistics,
/// the exact cache's work ratio `(variance x rays)_independent / (variance x rays)_exact` and the
/// family's bound.
pub struct Limits {
    /// The independent path tracer.
    pub independent: Measured,
    /// Eq. 7 with the exact cache.
    pub exact: Measured,
}

impl Limits {
    /// Measures both estimators on `field`'s scene.
    pub fn measure(field: &Field, resolution: usize, paths: usize, seed: u64) -> Limits {
        let cache = ExactCache::new(field);
        let independent = measure(resolution, paths, seed, |o, d, rng| independent_path(field, o, d, rng));
        let exact = measure(resolution, paths, seed.wrapping_add(1), |o, d, rng| cache.path(o, d, rng));
        Limits { independent, exact }
    }

    /// The work ratio of the exact cache.
    pub fn work_ratio(&self) -> f64 {
        (self.independent.mean_variance * self.independent.rays) / (self.exact.mean_variance * self.exact.rays)
    }

    /// The work ratio no Eq. 7 estimator can exceed on this image, whatever its cache and
    /// direction sampling: the independent tracer's variance x rays over the first flight's
    /// variance ([`first_flight_variance`]) x the fewest rays such an estimator traces (the camera
    /// ray, and one more flight whenever it collides: `2 - exp(-sigma_t d)` on average).
    pub fn family_bound(&self, field: &Field, resolution: usize) -> f64 {
        let sigma = field.scene().sigma_t;
        let fewest = (0..resolution * resolution)
            .map(|i| {
                let (o, d) = camera_ray(resolution, i % resolution, i / resolution);
                2.0 - (-sigma * exit_distance(o, d)).exp()
            })
            .sum::<f64>()
            / (resolution * resolution) as f64;
        let floor = first_flight_variance(field, resolution, 256);
        (self.independent.mean_variance * self.independent.rays) / (floor * fewest)
    }
}

#[cfg(test)]
mod tests;

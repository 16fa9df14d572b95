//! Random walks in a medium through the counted [`MediumProbe`]: free-flight sampling of paper 000
//! Eq. 7 (the pdf `exp(-tau) sigma_t` along the ray; beyond the exit the background `L_b` is seen),
//! phase-function sampling (independent path tracer), and the SMC walk whose every scattering
//! vertex estimates its in-scattered radiance from the octree's cache (paper 000 Fig. 2).
//!
//! Absorption: each vertex multiplies by the albedo `a = sigma_s / sigma_t` (Eq. 7's source term
//! `L_t = a L_i` with `L_e = 0`); once the product of albedos along a path falls below
//! [`ANALOG_BELOW`], a vertex survives with probability `a` and weight 1 instead (Russian roulette,
//! unbiased). This keeps optically thick, absorbing boxes finite in time; at albedo 1 no vertex
//! is ever dropped, and at albedo 0 the walk stops at the first collision (its value is 0).

use super::octree::Octree;
use crate::cache::{ControlVariate, Scalar, St};
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::phase::{Phase, ISOTROPIC};
use mcbench_core::task::MediumProbe;
use rand::Rng;

/// Below this product of albedos a vertex survives with probability `a` (weight 1).
pub const ANALOG_BELOW: f64 = 1e-3;

/// The outcome of one free flight from `pos` along `dir`.
pub enum Flight {
    /// The flight left the medium: the background seen along `dir`.
    Escaped(Rgb),
    /// A collision at this point.
    Collided(Vec3),
}

/// One free flight (paper 000 Eq. 7): the distance drawn from `sigma_t(s) exp(-tau(0, s))` along
/// the ray by delta tracking against the scene's majorant (Woodcock; paper 002 Eq. 4-5), so it
/// is exact in heterogeneous media too. Each tentative collision fetches the extinction once
/// and is real with probability `sigma_t / majorant`; in a homogeneous medium (`sigma_t` equal
/// to the majorant) the first tentative collision is real and no acceptance number is drawn.
pub fn free_flight<R: Rng + ?Sized>(probe: &MediumProbe<'_>, pos: Vec3, dir: Vec3, rng: &mut R) -> Flight {
    let Some((t0, t1)) = probe.clip(pos, dir) else {
        return Flight::Escaped(probe.environment(dir));
    };
    let majorant = probe.majorant();
    if majorant.is_nan() || majorant <= 0.0 {
        // `0 <= sigma_t <= majorant`: nothing to collide with.
        return Flight::Escaped(probe.environment(dir));
    }
    let mut s = t0;
    loop {
        s -= (1.0 - rng.gen::<f64>()).ln() / majorant;
        if s >= t1 {
            return Flight::Escaped(probe.environment(dir));
        }
        let x = pos + dir * s;
        let sigma = probe.sigma_t(x);
        if sigma >= majorant || rng.gen::<f64>() * majorant < sigma {
            return Flight::Collided(x);
        }
    }
}

/// One ray-marching "flight" (paper 000 Eq. 8-9, the biased variant): the ray is cut into steps of
/// length `step` from its entry point; at each step the single integral of Eq. 9 over the
/// `4 pi + 1` domain is sampled once, transmission (`kappa_t = exp(-sigma_t dx)`) or scattering
/// (`kappa_s = (1 - exp(-sigma_t dx)) a`) with probabilities proportional to the kappas, weight
/// `kappa_t + kappa_s`; a scattering event sits at the step's far (upstream) end, where Eq. 8
/// evaluates the source term. Returns the flight and its weight; the albedo is inside the weight.
pub fn march<R: Rng + ?Sized>(probe: &MediumProbe<'_>, pos: Vec3, dir: Vec3, step: f64, rng: &mut R) -> (Flight, f64) {
    let Some((t0, t1)) = probe.clip(pos, dir) else {
        return (Flight::Escaped(probe.environment(dir)), 1.0);
    };
    let (albedo, mut weight, mut s) = (probe.albedo(), 1.0, t0);
    while s < t1 {
        let dx = step.min(t1 - s);
        let sigma = probe.sigma_t(pos + dir * (s + 0.5 * dx));
        let kt = (-sigma * dx).exp();
        let ks = (1.0 - kt) * albedo;
        if ks <= 0.0 || rng.gen::<f64>() * (kt + ks) < kt {
            weight *= kt + ks;
            s += dx;
            continue;
        }
        weight *= kt + ks;
        // The far end, nudged inside so the vertex's leaf lookup stays in the box.
        return (Flight::Collided(pos + dir * (s + dx).min(t1 - 1e-12)), weight);
    }
    (Flight::Escaped(probe.environment(dir)), weight)
}

/// How a walk moves between vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Transport {
    /// Free flights of Eq. 7 (unbiased) with the albedo as a vertex weight.
    FreeFlight,
    /// Ray marching of Eq. 8-9 with this step (biased by construction).
    RayMarching(f64),
}

/// The albedo factor of a collision (deterministic weight, then Russian roulette); `None` when
/// the path is absorbed.
pub fn albedo_factor<R: Rng + ?Sized>(albedo: f64, throughput: &mut f64, rng: &mut R) -> Option<f64> {
    if albedo <= 0.0 {
        return None;
    }
    if *throughput >= ANALOG_BELOW {
        *throughput *= albedo;
        return Some(albedo);
    }
    (rng.gen::<f64>() < albedo).then_some(1.0)
}

/// One path of the independent volumetric path tracer (`is0_cv0` on a medium): free flights and
/// phase-function importance sampling, so each vertex's `f / p` is the radiance estimate itself.
pub fn independent_path<R: Rng + ?Sized>(probe: &MediumProbe<'_>, rng: &mut R) -> Rgb {
    let ray = probe.ray();
    let (albedo, phase) = (probe.albedo(), probe.phase());
    let (mut pos, mut dir, mut weight, mut throughput) = (ray.origin, ray.dir, 1.0, 1.0);
    loop {
        match free_flight(probe, pos, dir, rng) {
            Flight::Escaped(l) => return l * weight,
            Flight::Collided(x) => {
                let Some(a) = albedo_factor(albedo, &mut throughput, rng) else { return Rgb::ZERO };
                weight *= a;
                pos = x;
                dir = phase.sample(dir, rng).0;
                probe.scattered_ray();
            }
        }
    }
}

/// How the SMC walk draws directions at a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// `is0`: uniform over the sphere.
    Uniform,
    /// `is1`: the cache PDF (uniform until the cache first refines).
    Cache,
}

/// The snapshot one vertex read before its direction was traced.
pub struct Vertex {
    pos: Vec3,
    st: St,
    /// The leaf the snapshot was read from and the cell of `st` there (the record goes to the
    /// same place unless the leaf has split since).
    leaf: usize,
    cell: usize,
    /// `G` (cached radiance integral times the isotropic phase).
    big_g: Rgb,
    /// Cached radiance `g_L` at the direction (the control variate is `g_L / 4 pi`).
    g_l: Rgb,
    pdf: f64,
    phase: f64,
    factor: f64,
}

impl Vertex {
    /// The forward half of a vertex at collision `x` reached along `dir` (paper 000 Fig. 2,
    /// lines 5-9): find the leaf, draw the direction from its cache, read the snapshot `G` and
    /// `g`. `factor` is the albedo weight the vertex's estimate is multiplied by. Returns the
    /// vertex and the drawn direction.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn read<S: Scalar, R: Rng + ?Sized>(
        tree: &Octree<S>,
        x: Vec3,
        dir: Vec3,
        sampling: Sampling,
        cv: ControlVariate,
        phase: Phase,
        factor: f64,
        rng: &mut R,
    ) -> (Self, Vec3) {
        let leaf = tree.leaf_of(x);
        let cache = tree.cache_of(leaf);
        let draw = match sampling {
            Sampling::Uniform => cache.sample_uniform(rng),
            Sampling::Cache if tree.prefetches() => cache.sample_prefetching(rng),
            Sampling::Cache => cache.sample(rng),
        };
        // The reads of `g` (the cells around the drawn one) start before the direction's
        // trigonometry, which does not depend on them and so runs while they load.
        let g_l = cache.g(cv, draw.st);
        let big_g = cache.integral(cv) * ISOTROPIC;
        let w = cache.domain().direction(draw.st);
        let v = Vertex {
            pos: x,
            st: draw.st,
            leaf,
            // The cell the record would find (a drawn point at the far edge of its cell may
            // round into the next one).
            cell: cache.grid().cell_at(draw.st),
            big_g,
            g_l,
            pdf: draw.pdf,
            phase: phase.eval(dir.dot(w)),
            factor,
        };
        (v, w)
    }

    /// The backward half (Fig. 2, lines 11-13): the estimate `L_i = G + (f - g) / p` with
    /// `f = radiance * phase` from the snapshot, then the record of `radiance` in the leaf now
    /// containing the vertex (which may refine and split). Returns `L_i` times the vertex's factor.
    #[inline]
    pub fn estimate_and_record<S: Scalar>(self, tree: &mut Octree<S>, radiance: Rgb) -> Rgb {
        // `pdf > 0`: uniform, or a cell the sampler can only draw with weight >= 1.
        let li = self.big_g + (radiance * self.phase - self.g_l * ISOTROPIC) / self.pdf;
        tree.add_record_from(self.leaf, self.cell, self.pos, self.st, radiance, self.g_l);
        li * self.factor
    }
}

/// One SMC path (paper 000 Fig. 2 with Eq. 7, unrolled so thick media need no deep recursion):
/// forward, every collision reads its snapshot `G`, draws `w ~ p`, reads `g`; backward, from the
/// deepest radiance up, each vertex estimates `L_i = G + (f - g) / p` with `f = L phase`, and only
/// then records `L` in the leaf now containing it (which may refine and split).
pub fn smc_path<S: Scalar, R: Rng + ?Sized>(
    tree: &mut Octree<S>,
    probe: &MediumProbe<'_>,
    sampling: Sampling,
    cv: ControlVariate,
    transport: Transport,
    rng: &mut R,
    vertices: &mut Vec<Vertex>,
) -> Rgb {
    let ray = probe.ray();
    let (albedo, phase) = (probe.albedo(), probe.phase());
    let (mut pos, mut dir, mut throughput) = (ray.origin, ray.dir, 1.0);
    vertices.clear();
    let splits = tree.splits();
    let mut radiance = loop {
        let (flight, w) = match transport {
            Transport::FreeFlight => (free_flight(probe, pos, dir, rng), 1.0),
            Transport::RayMarching(step) => march(probe, pos, dir, step, rng),
        };
        // The weight of a flight multiplies the radiance it ends in (before the vertex's record).
        match flight {
            Flight::Escaped(l) => break l * w,
            Flight::Collided(x) => {
                let factor = match transport {
                    Transport::FreeFlight => match albedo_factor(albedo, &mut throughput, rng) {
                        Some(f) => f,
                        None => break Rgb::ZERO,
                    },
                    Transport::RayMarching(_) => w,
                };

                let (v, w) = Vertex::read(tree, x, dir, sampling, cv, phase, factor, rng);
                vertices.push(v);
                pos = x;
                dir = w;
                probe.scattered_ray();
            }
        }
    };
    // Cache operations of the path: per vertex one read (the descent to its leaf, G, the drawn
    // direction, g) and one record, and every split its records triggered.
    let reads_and_records = 2 * vertices.len() as u64;
    while let Some(v) = vertices.pop() {
        radiance = v.estimate_and_record(tree, radiance);
    }
    probe.count_cache_ops(reads_and_records + (tree.splits() - splits) as u64);
    radiance
}

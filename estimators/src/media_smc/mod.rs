//! Sequential Monte Carlo adaptation in participating media (paper 000 §4; book: testbeds.md):
//! the 5D [`octree::Octree`] of spherical radiance caches drives the unbiased estimator of Eq. 7
//! at every scattering vertex ([`walk::smc_path`]): `L_i = G + (f - g) / p` with `f = L Phi`,
//! `g` the cached radiance times the isotropic phase `1 / 4 pi` and `G` its integral (§4.5),
//! read from the snapshot before the vertex's record is added.
//!
//! The ids are the surface ids (book: paper-000.md): `is0_cv0`, `is0_cv1`, `is0_cv2`, `is1_cv0`,
//! `is1_cv1`, `is1_cv2` each serve both scene views through [`SurfaceOrMedium`], choosing by what
//! the test bed provides (a hemisphere: paper 001's per-pixel cache; a medium: this module).
//! `is0_cv0` on a medium is the independent path tracer with phase-function sampling (the papers'
//! "MCMC"); it builds no structure at all.
//!
//! One structure is shared by the whole image (paper 000 §4.3: the structure captures the global
//! radiance distribution and is adapted as pixels are rendered): the test bed hands every pixel's
//! task to [`Estimator::estimate_sequence`] and the pixels are interleaved, one path for every
//! pixel per round, so the per-pixel budget is the papers' spp and no pixel sees a structure
//! trained by more than one extra round of the others. Parameter `shared = 0` gives one structure
//! per pixel instead (for comparison). Unbiasedness holds either way: each estimate uses a
//! snapshot fixed before its direction is drawn.

pub mod exact_cache;
pub mod octree;
pub mod params;
pub mod walk;

use crate::cache::{CacheConfig, ControlVariate, Domain, Scalar, Storage};
use mcbench_core::accumulate::RgbMean;
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::Estimator;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::{MediumProbe, Task};
use mcbench_core::testbed::TestBed;
use octree::Octree;
use params::MediaSmcParams;
pub use walk::{Sampling, Transport};

pub mod rm_is1_cv2;

/// The generic medium SMC estimator.
#[derive(Clone, Debug)]
pub struct MediaSmc {
    transport: Transport,
    sampling: Sampling,
    cv: ControlVariate,
    config: CacheConfig,
    storage: Storage,
    shared: bool,
}

impl MediaSmc {
    /// Builds from its parameters: `criterion` (mean records per cell before a split), `max_depth`
    /// (octree depth), `storage` (`f64` / `f32`), `shared` (>= 0.5: one structure per image; below:
    /// one per pixel).
    pub fn from_params(sampling: Sampling, cv: ControlVariate, params: &MediaSmcParams) -> Self {
        let config = CacheConfig {
            domain: Domain::Sphere,
            criterion: params.criterion,
            max_depth: params.max_depth as u32,
            counter_divisor: octree::SPLIT_DIVISOR,
            importance: sampling == Sampling::Cache,
        };
        let (storage, shared) = (params.storage, params.shared >= 0.5);
        MediaSmc { transport: Transport::FreeFlight, sampling, cv, config, storage, shared }
    }

    /// The same estimator over ray-marching steps of length `step` (paper 000 Eq. 8-9: biased).
    pub fn ray_marching(mut self, step: f64) -> Self {
        self.transport = Transport::RayMarching(step);
        self
    }

    fn probes<'t>(tasks: &'t [Task<'t>]) -> Result<Vec<MediumProbe<'t>>, EstimateError> {
        tasks
            .iter()
            .map(|t| t.medium().ok_or_else(|| EstimateError::Refused("the test bed has no medium".into())))
            .collect()
    }

    /// Estimates every task with one structure, interleaving pixels (one path each per round).
    fn run<S: Scalar>(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        let probes = Self::probes(tasks)?;
        let mut tree = Octree::<S>::new(Vec3::default(), 0.5, self.config);
        let mut means = vec![RgbMean::new(); tasks.len()];
        let mut vertices = Vec::new();
        loop {
            let mut any = false;
            for (probe, mean) in probes.iter().zip(&mut means) {
                if !probe.more() {
                    continue;
                }
                any = true;
                probe.start_sample();
                mean.push(walk::smc_path(&mut tree, probe, self.sampling, self.cv, self.transport, rng, &mut vertices));
            }
            if !any {
                break;
            }
        }
        let st = tree.stats();
        for t in tasks {
            t.note("depth", f64::from(st.depth));
            t.note("nodes", st.nodes as f64);
            t.note("leaves", st.leaves as f64);
            t.note("cells", st.cells as f64);
            t.note("bytes", st.bytes as f64);
        }
        finite(tasks, means.iter().map(RgbMean::mean).collect())
    }

    fn dispatch(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        match self.storage {
            Storage::F64 => self.run::<f64>(tasks, rng),
            Storage::F32 => self.run::<f32>(tasks, rng),
        }
    }
}

fn finite(tasks: &[Task<'_>], values: Vec<Rgb>) -> Result<Vec<Rgb>, EstimateError> {
    for (t, v) in tasks.iter().zip(&values) {
        if !v.is_finite() {
            return Err(EstimateError::NonFinite { integral: t.integral(), value: v.0 });
        }
    }
    Ok(values)
}

impl Estimator for MediaSmc {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        Ok(self.dispatch(std::slice::from_ref(task), rng)?[0])
    }
    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        if self.shared {
            self.dispatch(tasks, rng)
        } else {
            tasks.iter().map(|t| self.estimate(t, rng)).collect()
        }
    }
    /// With one structure per pixel (`shared = 0`) each pixel is estimated on its own.
    fn integrals_independent(&self) -> bool {
        !self.shared
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_radiance(bed)
    }
}

/// Refuses (as a skipped pair) media whose integrals are not the radiance under the environment
/// (transmittances, point-light single scattering): these ids trace multiple scattering.
pub fn supports_radiance(bed: &dyn TestBed) -> Result<(), String> {
    match bed.medium().map(|m| m.ray(0).quantity) {
        Some(mcbench_core::testbed::MediumQuantity::Radiance) => Ok(()),
        _ => Err("traces multiple scattering under the environment; this test bed asks for another quantity".into()),
    }
}

/// `is0_cv0` on a medium: the independent volumetric path tracer (free flights, phase sampling).
#[derive(Clone, Copy, Debug, Default)]
pub struct PathTracer;

impl Estimator for PathTracer {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.medium().ok_or_else(|| EstimateError::Refused("the test bed has no medium".into()))?;
        let mut mean = RgbMean::new();
        while task.more() {
            probe.start_sample();
            mean.push(walk::independent_path(&probe, rng));
        }
        Ok(finite(std::slice::from_ref(task), vec![mean.mean()])?[0])
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_radiance(bed)
    }
}

/// One id serving both scene views (media and surfaces share the ids): the surface estimator on test beds with
/// hemispherical integrals, the medium one on test beds with a medium.
pub struct SurfaceOrMedium {
    /// Used when the test bed has a surface view.
    pub surface: Box<dyn Estimator>,
    /// Used when the test bed has a medium view.
    pub medium: Box<dyn Estimator>,
}

impl SurfaceOrMedium {
    fn pick(&self, task: Option<&Task<'_>>) -> &dyn Estimator {
        match task {
            Some(t) if t.hemisphere().is_none() && t.medium().is_some() => self.medium.as_ref(),
            _ => self.surface.as_ref(),
        }
    }
}

impl Estimator for SurfaceOrMedium {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        self.pick(Some(task)).estimate(task, rng)
    }
    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        self.pick(tasks.first()).estimate_sequence(tasks, rng)
    }
    fn integrals_independent(&self) -> bool {
        self.surface.integrals_independent() && self.medium.integrals_independent()
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        match (bed.hemisphere(), bed.medium()) {
            (Some(_), _) => self.surface.supports(bed),
            (None, Some(_)) => self.medium.supports(bed),
            _ => Err("needs surface or medium integrals, which the test bed does not provide".into()),
        }
    }
}

#[cfg(test)]
mod tests;

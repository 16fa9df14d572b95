//! Sequential Monte Carlo adaptation on surfaces (paper 001 §4; book: testbeds.md): one adaptive
//! hemispherical [`RadianceCache`] per estimate (per pixel), started with one cell and adapted over
//! the samples of that estimate.
//!
//! Every sample `k` is estimated from the snapshot of the cache *before* its record is added (§4.6,
//! Fig. 3 lines 12-17): `X_k = G + (f(w_k) - g(w_k)) / p(w_k)` with `w_k ~ p`. Given the past,
//! `E[X_k] = G + integral of (f - g) = F` because `G` is the exact integral of `g` (closed form,
//! [`ControlVariate::integral`]), the reported `p` is exactly the sampling density (integer
//! partial-sum tree), and `p > 0` wherever `f != 0` (inheritance rule, no clamp). The estimate is
//! the compensated average of the `X_k`, so it is unbiased at every sample count.
//!
//! The ids are thin entries over one generic core, [`SmcSurface`]: `is0_cv1`, `is0_cv2`,
//! `is1_cv0`, `is1_cv1`, `is1_cv2` and `brdf_is1_cv2` (the §4.5 variance tracker choosing between
//! BRDF importance sampling and `is1_cv2` from the same sample). Parameters ([`params`]):
//! `criterion` (default 8, paper 001 Table 1), `max_depth` (default 8) and `storage` (`"f64"` or
//! `"f32"`).

pub mod brdf_is1_cv2;
pub mod is0_cv1;
pub mod is0_cv2;
pub mod is1_cv0;
pub mod is1_cv1;
pub mod is1_cv2;
pub mod params;
pub mod variance_tracker;

use crate::cache::{CacheConfig, ControlVariate, RadianceCache, Scalar, Storage};
use crate::media_smc::{MediaSmc, SurfaceOrMedium};
use mcbench_core::accumulate::RgbMean;
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::Estimator;
use mcbench_core::math::{Frame, Rgb};
use mcbench_core::params::{parse, Params};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::{HemisphereProbe, Task};
use params::{CacheSmcParams, SurfaceSmcParams};
use variance_tracker::VarianceTracker;

/// How directions are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// `is0`: uniform over the hemisphere.
    Uniform,
    /// `is1`: the cache PDF (uniform until the first refinement).
    Cache,
    /// `brdf_is1`: the variance tracker of paper 001 §4.5 picks BRDF importance sampling or the
    /// cache PDF for each sample.
    BrdfTracked,
}

/// Which cache snapshot an estimate reads. Only `BeforeRecord` is unbiased; `AfterRecord` exists
/// to show that the unbiasedness test catches the mistake the snapshot rule prevents.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Snapshot {
    BeforeRecord,
    #[cfg_attr(not(test), allow(dead_code))]
    AfterRecord,
}

/// The generic surface SMC estimator (see the module documentation).
#[derive(Clone, Debug)]
pub struct SmcSurface {
    sampling: Sampling,
    cv: ControlVariate,
    config: CacheConfig,
    storage: Storage,
    snapshot: Snapshot,
}

impl SmcSurface {
    /// Builds from its parameters (`criterion`, `max_depth`, `storage`).
    pub fn from_params(sampling: Sampling, cv: ControlVariate, params: &SurfaceSmcParams) -> Self {
        let config = CacheConfig {
            criterion: params.criterion,
            max_depth: params.max_depth as u32,
            ..CacheConfig::surface(sampling != Sampling::Uniform)
        };
        SmcSurface { sampling, cv, config, storage: params.storage, snapshot: Snapshot::BeforeRecord }
    }

    /// The biased control of the tests: estimates read the cache after their own record.
    #[cfg(test)]
    fn reading_after_record(mut self) -> Self {
        self.snapshot = Snapshot::AfterRecord;
        self
    }

    /// The cache configuration.
    pub fn config(&self) -> &CacheConfig {
        &self.config
    }

    fn run<S: Scalar>(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe =
            task.hemisphere().ok_or_else(|| EstimateError::Refused("the test bed has no surface integrals".into()))?;
        let mut state = State::<S> {
            cache: RadianceCache::new(self.config),
            frame: Frame::around(probe.point().normal),
            tracker: VarianceTracker::new(self.config.criterion),
            smc_chosen: 0,
        };
        let mut mean = RgbMean::new();
        while task.more() {
            mean.push(self.step(&mut state, &probe, rng));
        }
        let value = mean.mean();
        let grid = state.cache.grid();
        task.note("cells", grid.cells() as f64);
        task.note("refinements", f64::from(grid.refinements()));
        task.note("cache_bytes", state.cache.bytes() as f64);
        task.note("cell_bytes", grid.cell_bytes() as f64);
        if self.sampling == Sampling::BrdfTracked && mean.count() > 0 {
            task.note("smc_share", state.smc_chosen as f64 / mean.count() as f64);
        }
        if !value.is_finite() {
            return Err(EstimateError::NonFinite { integral: task.integral(), value: value.0 });
        }
        Ok(value)
    }

    /// One sample: draw, evaluate, estimate from the snapshot, then record (and maybe refine).
    fn step<S: Scalar>(&self, state: &mut State<S>, probe: &HemisphereProbe<'_>, rng: &mut StreamRng) -> Rgb {
        if self.sampling == Sampling::BrdfTracked {
            return self.tracked_step(state, probe, rng);
        }
        let cache = &mut state.cache;
        let domain = cache.domain();
        let big_g = cache.integral(self.cv);
        let draw = match self.sampling {
            Sampling::Uniform => cache.sample_uniform(rng),
            _ => cache.sample(rng),
        };
        // `draw.pdf > 0`: uniform, or a tree leaf that can only be drawn when its weight is >= 1.
        let f = probe.integrand(state.frame.to_world(domain.direction(draw.st)));
        let g = cache.g(self.cv, draw.st);
        let (estimate, refined) = match self.snapshot {
            Snapshot::BeforeRecord => {
                let estimate = big_g + (f - g) / draw.pdf;
                (estimate, cache.add_record(draw.cell, f, g))
            }
            Snapshot::AfterRecord => {
                let refined = cache.add_record(draw.cell, f, g);
                (cache.integral(self.cv) + (f - cache.g(self.cv, draw.st)) / draw.pdf, refined)
            }
        };
        // One read (G, the drawn direction, g), one record, and the refinement it may trigger.
        probe.count_cache_ops(2 + u64::from(refined));
        estimate
    }

    /// `brdf_is1_cv2` (paper 001 §4.5-4.6, Fig. 3): the tracker picks the estimator, the direction is
    /// drawn from its density, both estimates are computed from the one sample, only the picked one
    /// contributes, and the record goes into the cache either way.
    fn tracked_step<S: Scalar>(&self, state: &mut State<S>, probe: &HemisphereProbe<'_>, rng: &mut StreamRng) -> Rgb {
        let cache = &mut state.cache;
        let domain = cache.domain();
        let brdf = probe.brdf();
        let big_g = cache.integral(self.cv);
        let use_smc = state.tracker.prefers_smc();
        // The drawn direction, its parameters and cell (the one the record goes to), the cache's
        // pdf; the BRDF's value and pdf come from one call (one power of the lobe for both).
        let (w, st, p_cache) = if use_smc {
            let s = cache.sample(rng);
            let w = state.frame.to_world(domain.direction(s.st));
            (w, Some((s.st, cache.grid().cell_at(s.st))), s.pdf)
        } else {
            let w = brdf.sample_direction(rng);
            // Below the horizon the direction is outside the cache's domain (and f = 0 there).
            let st = domain.st_of(state.frame.to_local(w)).map(|st| (st, cache.grid().cell_at(st)));
            (w, st, st.map_or(0.0, |(_, cell)| cache.pdf_of_cell(cell)))
        };
        let (f_brdf, p_brdf) = brdf.eval_pdf(w);
        let f = probe.integrand_with_brdf(w, f_brdf);
        let (smc, g) = match st {
            // p_cache > 0 on the whole hemisphere (uniform, or every tree leaf >= 1).
            Some((st, _)) if p_cache > 0.0 => {
                let g = cache.g(self.cv, st);
                (big_g + (f - g) / p_cache, g)
            }
            _ => (big_g, Rgb::ZERO),
        };
        // The Phong mixture density is positive wherever f is (cosine lobe for kd > 0, Phong lobe
        // over the support of the glossy term); a zero density comes with f = 0.
        let mcmc = if p_brdf > 0.0 { f / p_brdf } else { Rgb::ZERO };
        let chosen = if use_smc { smc } else { mcmc };
        state.tracker.update(smc, mcmc, chosen);
        state.smc_chosen += u64::from(use_smc);
        // One read (G, the direction or its density, g); a record unless the BRDF drew a direction
        // below the horizon, and the refinement it may trigger.
        let mut ops = 1;
        if let Some((_, cell)) = st {
            ops += 1 + u64::from(cache.add_record(cell, f, g));
        }
        probe.count_cache_ops(ops);
        chosen
    }
}

/// The adaptive state of one estimate.
struct State<S: Scalar> {
    cache: RadianceCache<S>,
    frame: Frame,
    tracker: VarianceTracker,
    smc_chosen: u64,
}

impl Estimator for SmcSurface {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        match self.storage {
            Storage::F64 => self.run::<f64>(task, rng),
            Storage::F32 => self.run::<f32>(task, rng),
        }
    }
}

/// Builds one of the ids serving both scene views (`is0_cv1` ... `is1_cv2`): this module's cache
/// on surfaces, the octree of [`crate::media_smc`] in media, each with its own defaults.
pub fn build_surface_or_medium(
    id: &str,
    (sampling, medium_sampling): (Sampling, crate::media_smc::Sampling),
    cv: ControlVariate,
    params: &Params,
) -> Result<Box<dyn Estimator>, ConfigError> {
    let p = parse::<CacheSmcParams>(id, params)?;
    Ok(Box::new(SurfaceOrMedium {
        surface: Box::new(SmcSurface::from_params(sampling, cv, &p.surface())),
        medium: Box::new(MediaSmc::from_params(medium_sampling, cv, &p.medium())),
    }))
}

#[cfg(test)]
mod tests;

//! The harness's counted view of a test bed for one estimate: it counts samples,
//! rays and fetches against the budget.
//!
//! Estimators reach the scene only through a [`Task`] and its probes, and the probes count every
//! sample, ray and fetch, so no plug-in can forget to count (the argmin `Problem` wrapper idea).

use crate::brdf::DirectionSample;
use crate::budget::{Budget, BudgetKind};
use crate::envmap::EnvFrame;
use crate::math::{Rgb, Vec3};
use crate::testbed::{
    EnvQuantity, EnvSequenceScene, HemisphereScene, ImagePlaneScene, MediumRay, MediumScene, ShadingPoint, TestBed,
};
use rand::Rng;
use serde::{Deserialize, Serialize};
use std::cell::{Cell, RefCell};
use std::time::Instant;

/// The costs of one estimate, counted by the harness.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Costs {
    /// Integrand evaluations (the papers' samples).
    pub samples: u64,
    /// Evaluations of a medium parameter stack (extinction, albedo, noise octaves: one per point).
    pub fetches: u64,
    /// Cheap approximate-extinction evaluations (control variates), counted apart.
    pub cheap_fetches: u64,
    /// Rays traced: camera and incident-radiance queries, shadow rays, and in a medium every
    /// free-flight segment of a path (one per scattering vertex left).
    pub rays: u64,
    /// The shadow (visibility) rays among `rays`: any-hit queries, which a renderer traces more
    /// cheaply than closest-hit ones (0 in cells stored before they were counted apart).
    #[serde(default)]
    pub shadow_rays: u64,
    /// The free-flight segments among `rays`: in a medium, the ray leaving each scattering vertex
    /// (0 in cells stored before they were counted apart). The rest of `rays` less
    /// `shadow_rays` are primary rays (camera and incident-radiance queries).
    #[serde(default)]
    pub free_flights: u64,
    /// Evaluations of the unnormalised target density an adaptive sampler weights, resamples,
    /// moves or adapts its samples by (0 in cells stored before they were counted, and in
    /// estimators without such a target). Paper 004: every evaluation of the product
    /// `p~_n(w) = L_n(w) f(w, w_o) cos(theta)` of some frame, wherever it is made (the candidates
    /// of bidirectional importance sampling, the reweighting of carried particles, each MH
    /// proposal, both frames at a bridge's proposal); there every sample is one, so it equals
    /// `samples`. Paper 003: the integrand value of each population member of PMC-HI (the `f` of
    /// its weight `f / K`) and each pixel sample of PMC-IP (whose luminance adapts the kernel).
    /// Visibility and the rays an evaluation traces are counted in `rays`, not here.
    #[serde(default)]
    pub target_evals: u64,
    /// Operations on an adaptive radiance cache (papers 000 and 001; 0 in cells stored before
    /// they were counted, and in estimators without a cache): one per read of the cache for an
    /// estimate (paper 001: the pixel's cache read for `G`, the drawn direction and `g`; paper
    /// 000: the octree descent to a scattering vertex's leaf and the same reads there), one per
    /// record written (a radiance record into one cell and its partial-sum branch), and one per
    /// refinement (paper 001: the cache doubling its resolution; paper 000: a leaf splitting into
    /// eight, its cache doubled).
    #[serde(default)]
    pub cache_ops: u64,
}

impl std::ops::AddAssign for Costs {
    /// Field by field: the costs of two estimates (or two blocks of them) together.
    fn add_assign(&mut self, b: Costs) {
        self.samples += b.samples;
        self.fetches += b.fetches;
        self.cheap_fetches += b.cheap_fetches;
        self.rays += b.rays;
        self.shadow_rays += b.shadow_rays;
        self.free_flights += b.free_flights;
        self.target_evals += b.target_evals;
        self.cache_ops += b.cache_ops;
    }
}

impl std::ops::Add for Costs {
    type Output = Costs;
    fn add(mut self, b: Costs) -> Costs {
        self += b;
        self
    }
}

/// Under a fetch budget, an estimate also stops after `budget x FETCH_BUDGET_SAMPLE_CAP` samples
/// (rays that fetch nothing cannot spend a fetch budget).
pub const FETCH_BUDGET_SAMPLE_CAP: u64 = 64;

/// How a task decides it is done.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stop {
    /// By its budget: samples, fetches (a stopping rule on the running cost) or wall time.
    Budget,
    /// After exactly this many samples: a fetch budget the harness has converted into a fixed
    /// sample count ([`Task::with_samples`]).
    Samples(u64),
}

/// One estimate of one integral under one budget.
pub struct Task<'a> {
    bed: &'a dyn TestBed,
    integral: usize,
    budget: Budget,
    stop: Stop,
    costs: Cell<Costs>,
    started: Instant,
    diagnostics: RefCell<Vec<(&'static str, f64)>>,
}

impl<'a> Task<'a> {
    /// A task for integral `integral` of `bed` (the harness builds these).
    pub fn new(bed: &'a dyn TestBed, integral: usize, budget: Budget) -> Self {
        Task {
            bed,
            integral,
            budget,
            stop: Stop::Budget,
            costs: Cell::new(Costs::default()),
            started: Instant::now(),
            diagnostics: RefCell::new(Vec::new()),
        }
    }
    /// A task that keeps `budget` (estimators still see it, e.g. ray marching spends a fetch budget
    /// as its step count) but stops after exactly `samples` samples.
    ///
    /// The harness uses it for fetch budgets: stopping an estimate when its fetches run out makes
    /// the number of samples a stopping time that depends on the samples' values (a delta-tracking
    /// ray that collides early is cheap *and* scores 0), so the mean of those samples is biased.
    /// A sample count fixed in advance (calibrated on an independent pilot stream) is not.
    pub fn with_samples(bed: &'a dyn TestBed, integral: usize, budget: Budget, samples: u64) -> Self {
        Task { stop: Stop::Samples(samples.max(1)), ..Task::new(bed, integral, budget) }
    }
    /// The integral index.
    pub fn integral(&self) -> usize {
        self.integral
    }
    /// The budget of this estimate.
    pub fn budget(&self) -> Budget {
        self.budget
    }
    /// Costs so far.
    pub fn costs(&self) -> Costs {
        self.costs.get()
    }
    /// True while the budget is not spent (checked before each sample).
    #[inline]
    pub fn more(&self) -> bool {
        let c = self.costs.get();
        if let Stop::Samples(n) = self.stop {
            return c.samples < n;
        }
        match self.budget.kind {
            BudgetKind::Samples => c.samples < self.budget.amount,
            // A sample cap keeps a ray that fetches nothing (it misses the medium, or its free
            // flights all leave it) from looping forever under a fetch budget.
            BudgetKind::Fetches => {
                c.fetches < self.budget.amount && c.samples < self.budget.amount.saturating_mul(FETCH_BUDGET_SAMPLE_CAP)
            }
            BudgetKind::Micros => (self.started.elapsed().as_micros() as u64) < self.budget.amount,
        }
    }
    /// Records a diagnostic of this estimate (e.g. `cache_bytes`, `cells`, `ess`); the harness
    /// reports its mean per cell in summary.json. A later value under the same name replaces it.
    pub fn note(&self, name: &'static str, value: f64) {
        let mut d = self.diagnostics.borrow_mut();
        match d.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => slot.1 = value,
            None => d.push((name, value)),
        }
    }
    /// The diagnostics recorded so far.
    pub fn diagnostics(&self) -> Vec<(&'static str, f64)> {
        self.diagnostics.borrow().clone()
    }
    /// The hemispherical-integral probe of this integral, when the scene has one.
    pub fn hemisphere(&self) -> Option<HemisphereProbe<'_>> {
        let scene = self.bed.hemisphere()?;
        let point = scene.shading(self.integral);
        let brdf = crate::phong_at::PhongAt::new(point.brdf, point.wo, point.normal);
        Some(HemisphereProbe { point, brdf, scene, task: self })
    }
    /// The counted medium probe of this integral, when the scene has a medium.
    pub fn medium(&self) -> Option<MediumProbe<'_>> {
        let scene = self.bed.medium()?;
        Some(MediumProbe { ray: scene.ray(self.integral), scene, task: self })
    }
    /// The environment-sequence probe of this integral (frame `i % F` of pixel `i / F`), when the
    /// scene has one.
    pub fn env_sequence(&self) -> Option<EnvProbe<'_>> {
        let scene = self.bed.env_sequence()?;
        let frames = scene.frames().max(1);
        let (pixel, frame) = (self.integral / frames, self.integral % frames);
        Some(EnvProbe { scene, task: self, pixel, frame, point: scene.shading(pixel), env: scene.environment(frame) })
    }
    /// The image-plane probe of this integral (pixel), when the scene has one.
    pub fn image_plane(&self) -> Option<ImageProbe<'_>> {
        Some(ImageProbe { scene: self.bed.image_plane()?, task: self })
    }
    /// The counted probe of this integral's generic integrand ([`crate::integrand`]), when the
    /// scene has one.
    pub fn integrand(&self) -> Option<IntegrandProbe<'_>> {
        Some(IntegrandProbe { f: self.bed.integrand()?, task: self })
    }
    /// Counts `n` evaluations of an adaptive sampler's target density ([`Costs::target_evals`])
    /// that no probe counts: the estimator calls it where it evaluates its target.
    pub fn count_target_evals(&self, n: u64) {
        self.count(|c| c.target_evals += n);
    }
    /// Counts `n` radiance-cache operations ([`Costs::cache_ops`]): the estimator calls it where
    /// it reads, writes or refines its cache.
    pub fn count_cache_ops(&self, n: u64) {
        self.count(|c| c.cache_ops += n);
    }
    fn count(&self, f: impl FnOnce(&mut Costs)) {
        let mut c = self.costs.get();
        f(&mut c);
        self.costs.set(c);
    }
}

mod probes;
pub use probes::{EnvProbe, HemisphereProbe, ImageProbe, IntegrandProbe, MediumProbe};

#[cfg(test)]
mod tests {
    use super::Costs;

    /// Costs stored before target evaluations and cache operations were counted still read, as 0.
    #[test]
    fn costs_stored_before_the_new_counts_read_as_zero() {
        let old = r#"{"samples":5,"fetches":2,"cheap_fetches":0,"rays":7,"shadow_rays":1,"free_flights":3}"#;
        let c: Costs = serde_json::from_str(old).expect("reads");
        assert_eq!(c, Costs { samples: 5, fetches: 2, rays: 7, shadow_rays: 1, free_flights: 3, ..Costs::default() });
        assert_eq!((c.target_evals, c.cache_ops), (0, 0));
    }

    /// Adding costs adds every count, field by field.
    #[test]
    fn costs_add_field_by_field() {
        let one = Costs {
            samples: 1,
            fetches: 2,
            cheap_fetches: 3,
            rays: 4,
            shadow_rays: 5,
            free_flights: 6,
            target_evals: 7,
            cache_ops: 8,
        };
        let two = Costs {
            samples: 2,
            fetches: 4,
            cheap_fetches: 6,
            rays: 8,
            shadow_rays: 10,
            free_flights: 12,
            target_evals: 14,
            cache_ops: 16,
        };
        assert_eq!(one + one, two);
        let mut sum = Costs::default();
        sum += one;
        sum += one;
        assert_eq!(sum, two);
    }
}

//! Adaptive directional radiance caches (SPEC §4.1; paper 001 §4, paper 000 §4).
//!
//! One cache type, [`RadianceCache`], parameterised by its [`Domain`] (the hemisphere of a surface
//! point now, the sphere of a medium point later) and by its cell [`Scalar`] (`f64` or `f32`):
//! - [`grid`]: the cells (RGB running means, PDF coefficients, counters), the maintained sums and
//!   refinement;
//! - [`reconstruction`]: the control variates `g` (cv1, cv2) and their integrals `G`;
//! - [`partial_sum_tree`]: the flat `2N - 1` tree that samples cells for `is1`;
//! - [`domain`]: the equal-solid-angle `(s, t)` parameterisations;
//! - [`storage`]: the precision switch.
//!
//! The cache PDF (`is1`, §4.2) picks a cell with probability proportional to its PDF coefficient
//! and then a point uniformly inside it (order 0). The tree holds the coefficients quantised to
//! integers, `q = floor(coefficient * scale) + 1`: integer partial sums are exact, so the
//! probability the cache reports is exactly the one it samples with, and a positive coefficient
//! always gives `q >= 1`, so the inheritance rule (§4.3) carries over to the sampled density. The
//! scale is chosen afresh at every refinement and whenever the coefficients drift far from it.

pub mod domain;
pub mod grid;
pub mod partial_sum_tree;
pub mod reconstruction;
pub mod storage;

pub use domain::{Domain, St};
pub use grid::Grid;
pub use partial_sum_tree::PartialSumTree;
pub use reconstruction::ControlVariate;
pub use storage::{Scalar, Storage};

use crate::math::Rgb;
use rand::Rng;

/// The largest `max_depth` a cache accepts (`4^12` cells on the hemisphere).
pub const MAX_DEPTH_LIMIT: u32 = 12;

/// How a cache adapts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CacheConfig {
    /// The directional domain.
    pub domain: Domain,
    /// Refine when the mean record count per cell reaches this (paper 001 §4.4, Table 1: 8).
    pub criterion: f64,
    /// No refinement beyond this many doublings (paper 001 §5 bounds the depth to bound memory).
    pub max_depth: u32,
    /// Counters are divided by this on refinement (4 on surfaces, 32 for a splitting octree node).
    pub counter_divisor: u32,
    /// Keep the partial-sum tree (needed by `is1` only).
    pub importance: bool,
}

impl CacheConfig {
    /// The surface configuration of paper 001: hemisphere, criterion 8, counters divided by 4.
    pub fn surface(importance: bool) -> Self {
        CacheConfig { domain: Domain::Hemisphere, criterion: 8.0, max_depth: 8, counter_divisor: 4, importance }
    }
}

/// A direction drawn from the cache: its parameters, cell, and density per unit solid angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CacheSample {
    /// Parameters of the direction.
    pub st: St,
    /// The cell it was drawn in.
    pub cell: usize,
    /// Density per unit solid angle (always > 0).
    pub pdf: f64,
}

/// The sampling tree with its quantisation of the PDF coefficients.
#[derive(Clone, Debug)]
struct Tree {
    tree: PartialSumTree,
    scale: f64,
    /// Largest allowed leaf: keeps the total below 2^62.
    cap: u64,
}

impl Tree {
    /// Headroom (as a power of two) between the largest leaf after a rescale and the cap.
    const HEADROOM_BITS: u32 = 12;
    /// A rescale is due when the total falls this many powers of two below the target.
    const DRIFT_BITS: u32 = 16;

    fn target(&self) -> u64 {
        self.cap >> Self::HEADROOM_BITS
    }
    /// `floor(coefficient * scale) + 1` for a positive coefficient (so never 0), 0 otherwise;
    /// `None` above the cap.
    fn quantise(&self, coefficient: f64) -> Option<u64> {
        if coefficient <= 0.0 {
            return Some(0);
        }
        let x = coefficient * self.scale;
        (x < self.cap as f64).then(|| x as u64 + 1)
    }
    /// Rebuilds from the coefficients with a scale mapping the largest one to the target.
    fn rebuild(&mut self, coefficients: impl ExactSizeIterator<Item = f64> + Clone) {
        let n = coefficients.len();
        if self.tree.leaves() != n {
            self.tree = PartialSumTree::new(n);
        }
        self.cap = (1u64 << 62) / n as u64;
        let max = coefficients.clone().fold(0.0f64, f64::max);
        self.scale = if max > 0.0 { self.target() as f64 / max } else { 1.0 };
        let leaves: Vec<u64> = coefficients.map(|c| self.quantise(c).unwrap_or(self.cap)).collect();
        self.tree.rebuild(&leaves);
    }
}

/// An adaptive directional radiance cache (see the module documentation).
#[derive(Clone, Debug)]
pub struct RadianceCache<S: Scalar> {
    config: CacheConfig,
    grid: Grid<S>,
    tree: Option<Tree>,
}

impl<S: Scalar> RadianceCache<S> {
    /// An empty cache at the domain's initial resolution.
    pub fn new(config: CacheConfig) -> Self {
        let grid = Grid::new(config.domain);
        let tree = config.importance.then(|| Tree { tree: PartialSumTree::new(grid.cells()), scale: 1.0, cap: 1 });
        let mut cache = RadianceCache { config, grid, tree };
        cache.rebuild_tree();
        cache
    }
    /// The configuration.
    pub fn config(&self) -> &CacheConfig {
        &self.config
    }
    /// The cells.
    pub fn grid(&self) -> &Grid<S> {
        &self.grid
    }
    /// The domain.
    pub fn domain(&self) -> Domain {
        self.config.domain
    }
    /// The control variate `g` at `st` (snapshot: call before [`RadianceCache::add_record`]).
    pub fn g(&self, cv: ControlVariate, st: St) -> Rgb {
        cv.g(&self.grid, st)
    }
    /// The integral `G` of `g` over the domain (snapshot: call before adding the record).
    pub fn integral(&self, cv: ControlVariate) -> Rgb {
        cv.integral(&self.grid)
    }

    /// Whether [`RadianceCache::sample`] uses the cache PDF: only with a tree, after the first
    /// refinement (before it "the PDF is not relevant", paper 001 §4.3: uniform sampling).
    fn tree_active(&self) -> Option<&Tree> {
        self.tree.as_ref().filter(|t| self.grid.refinements() > 0 && t.tree.total() > 0)
    }

    /// A direction drawn uniformly over the domain.
    pub fn sample_uniform<R: Rng + ?Sized>(&self, rng: &mut R) -> CacheSample {
        let st = St { s: rng.gen(), t: rng.gen() };
        CacheSample { st, cell: self.grid.cell_at(st), pdf: 1.0 / self.domain().measure() }
    }

    /// A direction drawn from the cache PDF (`is1`): a cell through the partial-sum tree, then
    /// uniformly inside the cell; uniform over the domain before the first refinement.
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> CacheSample {
        let Some(tree) = self.tree_active() else {
            return self.sample_uniform(rng);
        };
        let cell = tree.tree.sample(rng).expect("an active tree has a positive total");
        let (i, j) = self.grid.cell_ij(cell);
        let (ns, nt) = self.grid.resolution();
        let st = St { s: (i as f64 + rng.gen::<f64>()) / ns as f64, t: (j as f64 + rng.gen::<f64>()) / nt as f64 };
        CacheSample { st, cell, pdf: self.cell_density(tree, cell) }
    }

    fn cell_density(&self, tree: &Tree, cell: usize) -> f64 {
        let (ns, nt) = self.grid.resolution();
        tree.tree.probability(cell) / self.domain().cell_solid_angle(ns, nt)
    }

    /// The density of [`RadianceCache::sample`] at `st` per unit solid angle.
    pub fn pdf(&self, st: St) -> f64 {
        match self.tree_active() {
            Some(tree) => self.cell_density(tree, self.grid.cell_at(st)),
            None => 1.0 / self.domain().measure(),
        }
    }

    /// Adds the record of integrand sample `f` drawn in `cell`, with `g` the control variate the
    /// estimate used there: the RGB mean gets `f`, the PDF coefficient gets the mean over channels
    /// of `|f - g|` (paper 001 §4.2). Then refines if the criterion is met; returns whether it did.
    pub fn add_record(&mut self, cell: usize, f: Rgb, g: Rgb) -> bool {
        let d = f - g;
        let pdf_sample = (d[0].abs() + d[1].abs() + d[2].abs()) / 3.0;
        let coefficient = self.grid.record(cell, f, pdf_sample);
        if let Some(tree) = &mut self.tree {
            // Rescale when the coefficient overflows the cap or the total drifted far below target.
            let fits = tree.quantise(coefficient).filter(|_| tree.tree.total() >= tree.target() >> Tree::DRIFT_BITS);
            match fits {
                Some(q) => tree.tree.set(cell, q),
                None => self.rebuild_tree(),
            }
        }
        self.refine_if_due()
    }

    /// True when the refinement criterion is met (paper 001 §4.3-4.4): the mean count per cell
    /// reached the criterion, the depth is below `max_depth`, and — before the first refinement —
    /// every initial cell has a non-zero PDF coefficient.
    pub fn criterion_met(&self) -> bool {
        self.grid.refinements() < self.config.max_depth
            && self.grid.mean_count() >= self.config.criterion
            && (self.grid.refinements() > 0 || self.grid.pdf_coefficients().all(|p| p > 0.0))
    }

    /// Refines when [`RadianceCache::criterion_met`]; returns whether it did.
    pub fn refine_if_due(&mut self) -> bool {
        if !self.criterion_met() {
            return false;
        }
        self.refine();
        true
    }

    /// Refines unconditionally (paper 001 Fig. 3 `cache.Refine()`): doubles both resolutions,
    /// divides the counters, rebuilds the sums and the tree, `O(N)`.
    pub fn refine(&mut self) {
        self.grid.refine(self.config.counter_divisor);
        self.rebuild_tree();
    }

    fn rebuild_tree(&mut self) {
        if let Some(tree) = &mut self.tree {
            tree.rebuild(self.grid.pdf_coefficients());
        }
    }

    /// Heap bytes held: the cells plus the tree.
    pub fn bytes(&self) -> usize {
        self.grid.cell_bytes() + self.tree.as_ref().map_or(0, |t| t.tree.bytes())
    }
}

#[cfg(test)]
mod tests;

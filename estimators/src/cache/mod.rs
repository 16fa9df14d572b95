//! Adaptive directional radiance caches (paper 001 §4, paper 000 §4; book: testbeds.md).
//!
//! One cache type, [`RadianceCache`], parameterised by its [`Domain`] (the hemisphere of a surface
//! point now, the sphere of a medium point later) and by its cell [`Scalar`] (`f64` or `f32`):
//! - [`grid`]: the cells (RGB running means, PDF coefficients, counters), the maintained sums and
//!   refinement;
//! - [`reconstruction`]: the control variates `g` (cv1, cv2) and their integrals `G`;
//! - [`cell_sampler`]: samples cells for `is1` (sums of blocks of cells in a flat
//!   [`partial_sum_tree`], the cells' weights recomputed from the coefficients);
//! - [`domain`]: the equal-solid-angle `(s, t)` parameterisations;
//! - [`storage`]: the precision switch;
//! - [`prefetch`]: software prefetch of the lines a draw reads next;
//! - [`huge_pages`]: 2 MiB pages behind large storage (the octree of a medium).
//!
//! The cache PDF (`is1`, §4.2) picks a cell with probability proportional to its PDF coefficient
//! and then a point uniformly inside it (order 0). The [`cell_sampler`] quantises the coefficients
//! to integers, `q = floor(coefficient * scale) + 1`: integer partial sums are exact, so the
//! probability the cache reports is exactly the one it samples with, and a positive coefficient
//! always gives `q >= 1`, so the inheritance rule (§4.3) carries over to the sampled density. The
//! scale is chosen afresh at every refinement and whenever the coefficients drift far from it.

pub mod cell_sampler;
pub mod domain;
pub mod grid;
pub mod huge_pages;
pub mod partial_sum_tree;
pub mod prefetch;
pub mod reconstruction;
pub mod storage;

pub use cell_sampler::CellSampler;
pub use domain::{Domain, St};
pub use grid::Grid;
pub use partial_sum_tree::PartialSumTree;
pub use reconstruction::ControlVariate;
pub use storage::{Scalar, Storage};

use mcbench_core::math::Rgb;
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

/// An adaptive directional radiance cache (see the module documentation).
///
/// Field order is fixed (`repr(C)`, the same 336 bytes in double precision) so that what a vertex
/// of paper 000 Fig. 2 reads (the sampler's scalars, the grid's resolution, pointers and the sum
/// behind `G`) comes first and the polar sums, read only near the poles, come last.
#[derive(Clone, Debug)]
#[repr(C)]
pub struct RadianceCache<S: Scalar> {
    tree: Option<CellSampler>,
    config: CacheConfig,
    grid: Grid<S>,
}

impl<S: Scalar> RadianceCache<S> {
    /// An empty cache at the domain's initial resolution.
    pub fn new(config: CacheConfig) -> Self {
        let grid = Grid::new(config.domain);
        let tree = config.importance.then(|| CellSampler::new(grid.pdf_slice()));
        RadianceCache { config, grid, tree }
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
    fn tree_active(&self) -> Option<&CellSampler> {
        self.tree.as_ref().filter(|t| self.grid.refinements() > 0 && t.total() > 0)
    }

    /// A direction drawn uniformly over the domain.
    pub fn sample_uniform<R: Rng + ?Sized>(&self, rng: &mut R) -> CacheSample {
        let st = St { s: rng.gen(), t: rng.gen() };
        CacheSample { st, cell: self.grid.cell_at(st), pdf: 1.0 / self.domain().measure() }
    }

    /// A direction drawn from the cache PDF (`is1`): a cell through the partial-sum tree, then
    /// uniformly inside the cell; uniform over the domain before the first refinement.
    #[inline]
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> CacheSample {
        self.draw::<false, R>(rng)
    }

    /// [`RadianceCache::sample`] (the same direction for the same random numbers) prefetching the
    /// lines the draw and then `g` read, for a cache among more storage than the CPU caches hold
    /// (a leaf of a large octree): see [`CellSampler::sample_weighted_prefetching`].
    #[inline]
    pub fn sample_prefetching<R: Rng + ?Sized>(&self, rng: &mut R) -> CacheSample {
        self.draw::<true, R>(rng)
    }

    #[inline(always)]
    fn draw<const PREFETCH: bool, R: Rng + ?Sized>(&self, rng: &mut R) -> CacheSample {
        let Some(tree) = self.tree_active() else {
            return self.sample_uniform(rng);
        };
        let coefficients = self.grid.pdf_slice();
        let (cell, q) = if PREFETCH {
            // While the block's coefficients are scanned, its cells' RGB and those of the rows
            // above and below (the bilinear `g` reads two rows) load.
            tree.sample_weighted_prefetching(coefficients, rng, |r| {
                let ns = self.grid.resolution().0;
                self.grid.prefetch_cells(r.start, r.len());
                self.grid.prefetch_cells(r.start + ns, r.len());
                self.grid.prefetch_cells(r.start.wrapping_sub(ns), r.len());
            })
        } else {
            tree.sample_weighted(coefficients, rng)
        }
        .expect("an active tree has a positive total");
        let (i, j) = self.grid.cell_ij(cell);
        let (ns, nt) = self.grid.resolution();
        let st = St { s: (i as f64 + rng.gen::<f64>()) / ns as f64, t: (j as f64 + rng.gen::<f64>()) / nt as f64 };
        // The drawn cell's weight from the scan: the density of `cell_density`, one quantisation fewer.
        CacheSample { st, cell, pdf: tree.probability_of_weight(q) / self.domain().cell_solid_angle(ns, nt) }
    }

    fn cell_density(&self, tree: &CellSampler, cell: usize) -> f64 {
        let (ns, nt) = self.grid.resolution();
        tree.probability(self.grid.pdf_coefficient(cell)) / self.domain().cell_solid_angle(ns, nt)
    }

    /// The density of [`RadianceCache::sample`] at `st` per unit solid angle.
    pub fn pdf(&self, st: St) -> f64 {
        self.pdf_of_cell(self.grid.cell_at(st))
    }

    /// The density of [`RadianceCache::sample`] per unit solid angle in cell `cell`.
    pub fn pdf_of_cell(&self, cell: usize) -> f64 {
        match self.tree_active() {
            Some(tree) => self.cell_density(tree, cell),
            None => 1.0 / self.domain().measure(),
        }
    }

    /// Adds the record of integrand sample `f` drawn in `cell`, with `g` the control variate the
    /// estimate used there: the RGB mean gets `f`, the PDF coefficient gets the mean over channels
    /// of `|f - g|` (paper 001 §4.2). Then refines if the criterion is met; returns whether it did.
    #[inline]
    pub fn add_record(&mut self, cell: usize, f: Rgb, g: Rgb) -> bool {
        let d = f - g;
        let pdf_sample = (d[0].abs() + d[1].abs() + d[2].abs()) / 3.0;
        let old = self.grid.pdf_coefficient(cell);
        let coefficient = self.grid.record(cell, f, pdf_sample);
        if let Some(tree) = &mut self.tree {
            // Rescale when the coefficient overflows the cap or the total drifted far below target.
            if !tree.update(cell, old, coefficient) {
                self.rebuild_tree();
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
    #[cold]
    #[inline(never)]
    pub fn refine(&mut self) {
        self.grid.refine(self.config.counter_divisor);
        self.rebuild_tree();
    }

    fn rebuild_tree(&mut self) {
        if let Some(tree) = &mut self.tree {
            tree.rebuild(self.grid.pdf_slice());
        }
    }

    /// The heap buffers of the cache: the cells' and, with `is1`, the block sums'.
    pub fn storage_spans(&self) -> impl Iterator<Item = huge_pages::Span> + '_ {
        self.grid.storage_spans().into_iter().chain(self.tree.as_ref().map(|t| t.storage_span()))
    }

    /// Heap bytes held: the cells plus the tree.
    pub fn bytes(&self) -> usize {
        self.grid.cell_bytes() + self.tree.as_ref().map_or(0, |t| t.bytes())
    }
}

#[cfg(test)]
mod tests;

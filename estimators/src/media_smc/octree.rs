//! The 5D structure of paper 000 §4.3 (Fig. 1c-f): a spatial octree whose leaves hold spherical
//! [`RadianceCache`]s.
//!
//! It starts as one node whose cache has two cells (in `s`). A leaf refines when its cache's
//! criterion is met (mean record count per cell, §4.4; the root additionally waits until both of
//! its cells have a non-zero PDF coefficient, which guarantees every later PDF is positive, §4.3):
//! the cache doubles its resolution in `s` and `t`, its counters are divided by 32 (the
//! dimensionality of the split) but never rounded down to zero, and the node splits into eight
//! children each holding a copy of that doubled cache. Only leaves hold caches, so a cache's
//! resolution is tied to its depth.
//!
//! Past 4 MiB of cells, and again after every 1/16 of growth, the octree asks for 2 MiB pages
//! behind its buffers ([`crate::cache::huge_pages`]); the contents, hence results, are unchanged.

use crate::cache::huge_pages::{self, span_of, HUGE_PAGE};
use crate::cache::{CacheConfig, RadianceCache, Scalar, St};
use mcbench_core::math::{Rgb, Vec3};

/// Counters are divided by the dimensionality of a split: 2 x 2 directional x 8 spatial = 32.
pub const SPLIT_DIVISOR: u32 = 32;

/// The storage, in bytes of cells (4 MiB), from which the octree asks for huge pages behind it
/// (see [`huge_pages`]): past the 1 MiB L2, where each link of a vertex's chain of loads misses
/// and a 4 KiB page per link also misses the TLB.
const HUGE_PAGES_FROM: usize = 2 * HUGE_PAGE;

/// The storage, in bytes of cells, from which a vertex's draw prefetches (see
/// [`RadianceCache::sample_prefetching`]): the 1 MiB L2.
const PREFETCH_FROM: usize = 1 << 20;

/// One node, 32 bytes, so the descent of [`Octree::leaf_of`] walks a compact array (the caches
/// live apart, in [`Octree::caches`]).
#[derive(Clone, Copy, Debug)]
struct Node {
    center: Vec3,
    /// Index of the first of eight consecutive children, 0 for a leaf.
    children: u32,
    /// A leaf's cache (index into the caches), unused for an inner node.
    cache: u32,
}

/// The size report of paper 000 Table 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OctreeStats {
    /// Deepest level (root = 0).
    pub depth: u32,
    /// Nodes, inner and leaves.
    pub nodes: usize,
    /// Leaves (= radiance caches).
    pub leaves: usize,
    /// Directional cells over all caches.
    pub cells: usize,
    /// Heap bytes: caches (cells + partial-sum trees) plus the nodes.
    pub bytes: usize,
}

/// The octree of spherical caches over an axis-aligned cube.
#[derive(Clone, Debug)]
pub struct Octree<S: Scalar> {
    nodes: Vec<Node>,
    /// Depth of each node (root = 0); the half-size is `half / 2^depth`.
    depths: Vec<u8>,
    half: f64,
    caches: Vec<RadianceCache<S>>,
    leaves: usize,
    /// Leaf splits so far, counted (not derived from `leaves`: a path reads it twice).
    splits: usize,
    cells: usize,
    depth: u32,
    /// The cell count at which the storage is next backed with huge pages (1/16 more than at the
    /// last time, so the share of storage growth left on small pages stays small).
    next_huge_pages: usize,
}

impl<S: Scalar> Octree<S> {
    /// Bytes per cell: RGB and counter, PDF coefficient.
    const CELL_BYTES: usize = 4 * std::mem::size_of::<S>() + 4;

    /// One node covering the cube of centre `center` and half-size `half`, holding an empty cache
    /// (two cells on the sphere). `config.counter_divisor` is set to [`SPLIT_DIVISOR`].
    pub fn new(center: Vec3, half: f64, config: CacheConfig) -> Self {
        let config = CacheConfig { counter_divisor: SPLIT_DIVISOR, ..config };
        let cache = RadianceCache::new(config);
        let cells = cache.grid().cells();
        Octree {
            nodes: vec![Node { center, children: 0, cache: 0 }],
            depths: vec![0],
            half,
            caches: vec![cache],
            leaves: 1,
            splits: 0,
            cells,
            depth: 0,
            next_huge_pages: HUGE_PAGES_FROM / Self::CELL_BYTES,
        }
    }

    /// The index of the leaf containing `p` (points outside are clamped to the nearest leaf),
    /// `O(depth)`.
    pub fn leaf_of(&self, p: Vec3) -> usize {
        self.leaf_below(0, p)
    }

    /// The leaf containing `p` among the descendants of node `i` (which must contain `p`, or be
    /// the root): the descent from the root passes through `i`, so this is [`Octree::leaf_of`].
    #[inline]
    fn leaf_below(&self, mut i: usize, p: Vec3) -> usize {
        loop {
            let n = &self.nodes[i];
            if n.children == 0 {
                return i;
            }
            let c = n.center;
            let k = usize::from(p.x >= c.x) | usize::from(p.y >= c.y) << 1 | usize::from(p.z >= c.z) << 2;
            i = n.children as usize + k;
        }
    }

    /// Whether the storage outgrew the L2, so that a draw from a leaf's cache should prefetch
    /// ([`RadianceCache::sample_prefetching`]; the drawn direction is the same either way).
    #[inline]
    pub fn prefetches(&self) -> bool {
        self.cells * Self::CELL_BYTES >= PREFETCH_FROM
    }

    /// Leaf splits so far (each turns one leaf into eight), `O(1)`.
    pub fn splits(&self) -> usize {
        self.splits
    }

    /// The cache of leaf `leaf`.
    pub fn cache_of(&self, leaf: usize) -> &RadianceCache<S> {
        &self.caches[self.nodes[leaf].cache as usize]
    }

    /// The cache of the leaf containing `p`.
    pub fn cache_at(&self, p: Vec3) -> &RadianceCache<S> {
        self.cache_of(self.leaf_of(p))
    }

    /// Adds the record of incoming radiance `radiance` from direction `st` at `p`, with `g` the
    /// control variate the estimate used, to the leaf now containing `p` (it may have split since
    /// the estimate read its snapshot: paper 000 Fig. 2, line 12). Splits the leaf when its cache
    /// refined; returns whether it did.
    pub fn add_record(&mut self, p: Vec3, st: St, radiance: Rgb, g: Rgb) -> bool {
        let leaf = self.leaf_of(p);
        let cell = self.cache_of(leaf).grid().cell_at(st);
        self.record_in(leaf, cell, radiance, g)
    }

    /// [`Octree::add_record`] for a vertex that read its snapshot from leaf `leaf` and drew cell
    /// `cell` there: when that leaf has not split since, the record goes to the same cell without a
    /// second descent; otherwise the descent resumes at `leaf` (whose children tile it). The cell
    /// and leaf are the ones [`Octree::add_record`] finds, so the result is the same.
    pub fn add_record_from(&mut self, leaf: usize, cell: usize, p: Vec3, st: St, radiance: Rgb, g: Rgb) -> bool {
        if self.nodes[leaf].children == 0 {
            return self.record_in(leaf, cell, radiance, g);
        }
        let leaf = self.leaf_below(leaf, p);
        let cell = self.cache_of(leaf).grid().cell_at(st);
        self.record_in(leaf, cell, radiance, g)
    }

    fn record_in(&mut self, leaf: usize, cell: usize, radiance: Rgb, g: Rgb) -> bool {
        let cache = &mut self.caches[self.nodes[leaf].cache as usize];
        let before = cache.grid().cells();
        if !cache.add_record(cell, radiance, g) {
            return false;
        }
        self.cells += cache.grid().cells() - before;
        self.split(leaf);
        if self.cells >= self.next_huge_pages {
            self.back_with_huge_pages();
        }
        true
    }

    /// Asks for huge pages behind every buffer of the octree (the nodes, the caches and their
    /// cells); the mapping changes, the contents do not.
    #[cold]
    #[inline(never)]
    fn back_with_huge_pages(&mut self) {
        self.next_huge_pages = self.cells + self.cells / 16;
        let own = [span_of(&self.nodes), span_of(&self.depths), span_of(&self.caches)];
        huge_pages::back_with_huge_pages(own.into_iter().chain(self.caches.iter().flat_map(|c| c.storage_spans())));
    }

    /// Replaces leaf `i` by eight children, each holding a copy of its (already doubled) cache: the
    /// first child keeps the leaf's cache, the seven others get clones appended.
    fn split(&mut self, i: usize) {
        let slot = self.nodes[i].cache;
        let (center, depth) = (self.nodes[i].center, self.depths[i] + 1);
        let first = self.nodes.len();
        let h = self.half / f64::from(1u32 << depth);
        for k in 0..8 {
            let sign = |bit: usize| if k >> bit & 1 == 1 { h } else { -h };
            let c = Vec3::new(center.x + sign(0), center.y + sign(1), center.z + sign(2));
            let cache = if k == 0 {
                slot
            } else {
                self.caches.push(self.caches[slot as usize].clone());
                (self.caches.len() - 1) as u32
            };
            self.nodes.push(Node { center: c, children: 0, cache });
            self.depths.push(depth);
        }
        self.nodes[i].children = u32::try_from(first).expect("fewer than 2^32 nodes");
        self.leaves += 7;
        self.splits += 1;
        self.cells += 7 * self.caches[slot as usize].grid().cells();
        self.depth = self.depth.max(u32::from(depth));
    }

    /// The Table 1 report, `O(1)` except for the bytes (`O(leaves)`).
    pub fn stats(&self) -> OctreeStats {
        let cache_bytes: usize = self.caches.iter().map(|c| c.bytes() + std::mem::size_of::<RadianceCache<S>>()).sum();
        OctreeStats {
            depth: self.depth,
            nodes: self.nodes.len(),
            leaves: self.leaves,
            cells: self.cells,
            bytes: cache_bytes + self.nodes.len() * (std::mem::size_of::<Node>() + 1),
        }
    }

    /// Checks the structural invariants (tests): children tile their parent, every leaf owns one
    /// cache and no two leaves share one, a leaf at depth `d` has `2 x 4^d` cells, the counts are
    /// consistent.
    pub fn check_invariants(&self) -> Result<(), String> {
        let (mut leaves, mut cells) = (0, 0);
        let mut owner = vec![usize::MAX; self.caches.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            let (depth, first) = (u32::from(self.depths[i]), n.children as usize);
            if first == 0 {
                let slot = n.cache as usize;
                if slot >= self.caches.len() || owner[slot] != usize::MAX {
                    return Err(format!("leaf {i} has cache {slot}, missing or shared"));
                }
                owner[slot] = i;
                leaves += 1;
                let c = &self.caches[slot];
                cells += c.grid().cells();
                if c.grid().cells() != 2 << (2 * depth) {
                    return Err(format!("leaf {i} at depth {depth} has {} cells", c.grid().cells()));
                }
            } else if first > i {
                let half = self.half / f64::from(1u32 << depth);
                for k in 0..8 {
                    let ch = &self.nodes[first + k];
                    let off = ch.center - n.center;
                    let ok = u32::from(self.depths[first + k]) == depth + 1
                        && [off.x, off.y, off.z].iter().all(|o| (o.abs() - half / 2.0).abs() < 1e-15);
                    if !ok {
                        return Err(format!("child {k} of node {i} does not tile it"));
                    }
                }
            } else {
                return Err(format!("node {i} points to children before it"));
            }
        }
        if leaves != self.leaves || cells != self.cells || leaves != self.caches.len() || 7 * self.splits + 1 != leaves
        {
            return Err(format!("counts {leaves}/{cells} vs maintained {}/{}", self.leaves, self.cells));
        }
        Ok(())
    }
}

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

use crate::cache::{CacheConfig, RadianceCache, Scalar, St};
use crate::math::{Rgb, Vec3};

/// Counters are divided by the dimensionality of a split: 2 x 2 directional x 8 spatial = 32.
pub const SPLIT_DIVISOR: u32 = 32;

#[derive(Clone, Debug)]
struct Node<S: Scalar> {
    center: Vec3,
    half: f64,
    depth: u32,
    /// Index of the first of eight consecutive children, 0 for a leaf.
    children: usize,
    cache: Option<RadianceCache<S>>,
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
    nodes: Vec<Node<S>>,
    leaves: usize,
    cells: usize,
    depth: u32,
}

impl<S: Scalar> Octree<S> {
    /// One node covering the cube of centre `center` and half-size `half`, holding an empty cache
    /// (two cells on the sphere). `config.counter_divisor` is set to [`SPLIT_DIVISOR`].
    pub fn new(center: Vec3, half: f64, config: CacheConfig) -> Self {
        let config = CacheConfig { counter_divisor: SPLIT_DIVISOR, ..config };
        let cache = RadianceCache::new(config);
        let cells = cache.grid().cells();
        Octree {
            nodes: vec![Node { center, half, depth: 0, children: 0, cache: Some(cache) }],
            leaves: 1,
            cells,
            depth: 0,
        }
    }

    /// The index of the leaf containing `p` (points outside are clamped to the nearest leaf),
    /// `O(depth)`.
    pub fn leaf_of(&self, p: Vec3) -> usize {
        let mut i = 0;
        while self.nodes[i].children != 0 {
            let c = self.nodes[i].center;
            let k = usize::from(p.x >= c.x) | usize::from(p.y >= c.y) << 1 | usize::from(p.z >= c.z) << 2;
            i = self.nodes[i].children + k;
        }
        i
    }

    /// The cache of the leaf containing `p`.
    pub fn cache_at(&self, p: Vec3) -> &RadianceCache<S> {
        self.nodes[self.leaf_of(p)].cache.as_ref().expect("leaves hold caches")
    }

    /// Adds the record of incoming radiance `radiance` from direction `st` at `p`, with `g` the
    /// control variate the estimate used, to the leaf now containing `p` (it may have split since
    /// the estimate read its snapshot: paper 000 Fig. 2, line 12). Splits the leaf when its cache
    /// refined; returns whether it did.
    pub fn add_record(&mut self, p: Vec3, st: St, radiance: Rgb, g: Rgb) -> bool {
        let leaf = self.leaf_of(p);
        let cache = self.nodes[leaf].cache.as_mut().expect("leaves hold caches");
        let before = cache.grid().cells();
        let cell = cache.grid().cell_at(st);
        if !cache.add_record(cell, radiance, g) {
            return false;
        }
        self.cells += cache.grid().cells() - before;
        self.split(leaf);
        true
    }

    /// Replaces leaf `i` by eight children, each holding a copy of its (already doubled) cache.
    fn split(&mut self, i: usize) {
        let cache = self.nodes[i].cache.take().expect("leaves hold caches");
        let (center, half, depth) = (self.nodes[i].center, self.nodes[i].half, self.nodes[i].depth + 1);
        let first = self.nodes.len();
        let h = half / 2.0;
        for k in 0..8 {
            let sign = |bit: usize| if k >> bit & 1 == 1 { h } else { -h };
            let c = Vec3::new(center.x + sign(0), center.y + sign(1), center.z + sign(2));
            self.nodes.push(Node { center: c, half: h, depth, children: 0, cache: Some(cache.clone()) });
        }
        self.nodes[i].children = first;
        self.leaves += 7;
        self.cells += 7 * cache.grid().cells();
        self.depth = self.depth.max(depth);
    }

    /// The Table 1 report, `O(1)` except for the bytes (`O(leaves)`).
    pub fn stats(&self) -> OctreeStats {
        let cache_bytes: usize = self.nodes.iter().filter_map(|n| n.cache.as_ref()).map(|c| c.bytes()).sum();
        OctreeStats {
            depth: self.depth,
            nodes: self.nodes.len(),
            leaves: self.leaves,
            cells: self.cells,
            bytes: cache_bytes + self.nodes.len() * std::mem::size_of::<Node<S>>(),
        }
    }

    /// Checks the structural invariants (tests): children tile their parent, only leaves hold
    /// caches, a leaf at depth `d` has `2 x 4^d` cells, the counts are consistent.
    pub fn check_invariants(&self) -> Result<(), String> {
        let (mut leaves, mut cells) = (0, 0);
        for (i, n) in self.nodes.iter().enumerate() {
            match (&n.cache, n.children) {
                (Some(c), 0) => {
                    leaves += 1;
                    cells += c.grid().cells();
                    if c.grid().cells() != 2 << (2 * n.depth) {
                        return Err(format!("leaf {i} at depth {} has {} cells", n.depth, c.grid().cells()));
                    }
                }
                (None, first) if first > i => {
                    for k in 0..8 {
                        let ch = &self.nodes[first + k];
                        let off = ch.center - n.center;
                        let ok = (ch.half - n.half / 2.0).abs() < 1e-15
                            && ch.depth == n.depth + 1
                            && [off.x, off.y, off.z].iter().all(|o| (o.abs() - ch.half).abs() < 1e-15);
                        if !ok {
                            return Err(format!("child {k} of node {i} does not tile it"));
                        }
                    }
                }
                _ => return Err(format!("node {i} is neither a leaf with a cache nor an inner node")),
            }
        }
        if leaves != self.leaves || cells != self.cells {
            return Err(format!("counts {leaves}/{cells} vs maintained {}/{}", self.leaves, self.cells));
        }
        Ok(())
    }
}

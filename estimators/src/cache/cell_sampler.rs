//! The sampler of the cache PDF over cells (paper 001 §4.2; `is1`): a cell is drawn with
//! probability proportional to its quantised PDF coefficient `q = floor(coefficient * scale) + 1`
//! (0 for a zero coefficient), by inversion of the cumulative sums in cell order.
//!
//! Paper 001 describes a flat partial-sum tree of `2N - 1` nodes. This sampler draws the same cell
//! for the same random number with a fraction of the memory: the tree ([`PartialSumTree`]) holds
//! the sums of blocks of `B` consecutive cells (`B = 128 bytes / coefficient size`: 16 cells in
//! double precision, 32 in single), and the `q` of the cells themselves are not stored but
//! recomputed from the coefficients the grid already holds (one multiplication each). Drawing
//! `x` uniformly in `[0, total)`, descending the block tree and then scanning the block's cells
//! subtracting each `q` (from whichever end of the block is nearer to `x`, so a draw reads a
//! quarter of the block on average) finds the cell whose cumulative range holds `x`, exactly what the descent
//! of a full tree over cells in order finds (its leaves are in order: the domains' cell counts are
//! powers of two). Integer sums are exact, so a cell is drawn with probability exactly
//! `q / total`, the probability [`CellSampler::probability`] reports.
//!
//! Memory per cell: 16 bytes for the full `u64` tree, `16 / B` here (1 byte in double precision,
//! 0.5 in single). Time: the scan reads one 128-byte run of coefficients (two cache lines) instead
//! of the `log2 B` deepest levels of the tree, each on its own cache line in a large cache.

use super::huge_pages::Span;
use super::partial_sum_tree::PartialSumTree;
use super::storage::Scalar;
use rand::Rng;

/// Bytes of coefficients per block.
const BLOCK_BYTES: usize = 128;

/// The block sums and the quantisation of the PDF coefficients (see the module documentation).
#[derive(Clone, Debug)]
#[repr(C)]
pub struct CellSampler {
    /// The root of `blocks`, kept beside the other fields so a draw can start its random number
    /// before the tree's first line arrives.
    total: u64,
    scale: f64,
    /// `cap` as a float (exact: a power of two over a power of two).
    cap_f64: f64,
    /// Largest allowed `q`: keeps the total below 2^62.
    cap: u64,
    blocks: PartialSumTree,
    cells: usize,
    /// `log2` of the cells per block (a power of two; the whole grid when it is smaller): a cell's
    /// block by a shift, not a division.
    block_shift: u32,
}

impl CellSampler {
    /// Bytes of block sums prefetched before a descent: the levels above 64 blocks (the whole tree
    /// up to 1 024 cells in double precision).
    const PREFETCH_TREE_BYTES: usize = 512;
    /// Headroom (as a power of two) between the largest `q` after a rescale and the cap.
    const HEADROOM_BITS: u32 = 12;
    /// A rescale is due when the total falls this many powers of two below the target.
    const DRIFT_BITS: u32 = 16;

    /// A sampler over `coefficients` stored as `S`.
    pub fn new<S: Scalar>(coefficients: &[S]) -> Self {
        let mut s = CellSampler {
            blocks: PartialSumTree::new(1),
            block_shift: 0,
            cells: 0,
            scale: 1.0,
            cap: 1,
            cap_f64: 1.0,
            total: 0,
        };
        s.rebuild(coefficients);
        s
    }

    fn target(&self) -> u64 {
        self.cap >> Self::HEADROOM_BITS
    }

    /// `floor(coefficient * scale) + 1` for a positive coefficient (so never 0), 0 otherwise;
    /// `None` above the cap.
    #[inline]
    fn quantise(&self, coefficient: f64) -> Option<u64> {
        if coefficient <= 0.0 {
            return Some(0);
        }
        let x = coefficient * self.scale;
        // 0 < x < cap < 2^62 here, where the conversion through i64 truncates exactly as one to
        // u64 would, in fewer instructions (no unsigned fix-up).
        (x < self.cap_f64).then(|| x as i64 as u64 + 1)
    }

    /// The weight of a cell with this coefficient: its `q`, or the cap when it overflowed at the
    /// last rebuild (only possible for a scale that overflowed: coefficients below ~1e-290).
    #[inline]
    fn weight(&self, coefficient: f64) -> u64 {
        self.quantise(coefficient).unwrap_or(self.cap)
    }

    /// Rebuilds from the coefficients with a scale mapping the largest one to the target, `O(N)`.
    pub fn rebuild<S: Scalar>(&mut self, coefficients: &[S]) {
        let n = coefficients.len();
        self.cells = n;
        let block = (BLOCK_BYTES / std::mem::size_of::<S>()).min(n.next_power_of_two());
        self.block_shift = block.trailing_zeros();
        // A power-of-two block count, so the descent visits blocks in order.
        let blocks = n.div_ceil(block).next_power_of_two();
        if self.blocks.leaves() != blocks {
            self.blocks = PartialSumTree::new(blocks);
        }
        self.cap = (1u64 << 62) / n as u64;
        self.cap_f64 = self.cap as f64;
        let max = coefficients.iter().map(|c| c.get()).fold(0.0f64, f64::max);
        self.scale = if max > 0.0 { self.target() as f64 / max } else { 1.0 };
        let mut sums = vec![0u64; blocks];
        for (b, chunk) in coefficients.chunks(block).enumerate() {
            sums[b] = chunk.iter().map(|c| self.weight(c.get())).sum();
        }
        self.blocks.rebuild(&sums);
        self.total = self.blocks.total();
    }

    /// The sum of every cell's weight.
    pub fn total(&self) -> u64 {
        self.total
    }

    /// The probability of drawing a cell whose coefficient is `coefficient`.
    pub fn probability(&self, coefficient: f64) -> f64 {
        self.probability_of_weight(self.weight(coefficient))
    }

    /// Updates one cell's coefficient from `old` to `new`; `false` when a rebuild is due instead
    /// (the new weight overflows the cap, or the total drifted far below the target), in which
    /// case nothing was changed.
    #[inline]
    pub fn update(&mut self, cell: usize, old: f64, new: f64) -> bool {
        let Some(q) = self.quantise(new).filter(|_| self.total() >= self.target() >> Self::DRIFT_BITS) else {
            return false;
        };
        let b = cell >> self.block_shift;
        let old = self.weight(old);
        self.blocks.set(b, self.blocks.weight(b) - old + q);
        self.total = self.total - old + q;
        true
    }

    /// Draws a cell with probability `q / total` (`coefficients` are the ones the sampler was
    /// built and updated with); `None` when every weight is zero. Consumes one `gen_range`.
    #[inline]
    pub fn sample<S: Scalar, R: Rng + ?Sized>(&self, coefficients: &[S], rng: &mut R) -> Option<usize> {
        self.sample_weighted(coefficients, rng).map(|(cell, _)| cell)
    }

    /// [`CellSampler::sample`] with the drawn cell's weight `q`, which the scan has just computed
    /// (so its probability, [`CellSampler::probability_of_weight`], needs no second quantisation).
    #[inline]
    pub fn sample_weighted<S: Scalar, R: Rng + ?Sized>(&self, coefficients: &[S], rng: &mut R) -> Option<(usize, u64)> {
        self.draw::<false, S, R>(coefficients, rng, |_| {})
    }

    /// [`CellSampler::sample_weighted`] for storage larger than the caches (the same cell for the
    /// same random numbers): the block sums are prefetched before the descent, the block's
    /// coefficients before the scan, and `block_found` gets the range of cells the scan is about
    /// to read (to prefetch what the caller reads after the draw). For a small cache, whose lines
    /// are in L1 already, the prefetches are only extra instructions.
    #[inline]
    pub fn sample_weighted_prefetching<S: Scalar, R: Rng + ?Sized>(
        &self,
        coefficients: &[S],
        rng: &mut R,
        block_found: impl FnOnce(std::ops::Range<usize>),
    ) -> Option<(usize, u64)> {
        self.draw::<true, S, R>(coefficients, rng, block_found)
    }

    #[inline(always)]
    fn draw<const PREFETCH: bool, S: Scalar, R: Rng + ?Sized>(
        &self,
        coefficients: &[S],
        rng: &mut R,
        block_found: impl FnOnce(std::ops::Range<usize>),
    ) -> Option<(usize, u64)> {
        if PREFETCH {
            self.blocks.prefetch(Self::PREFETCH_TREE_BYTES);
        }
        let total = self.total();
        if total == 0 {
            return None;
        }
        let (b, x) = self.blocks.find(rng.gen_range(0..total));
        let start = b << self.block_shift;
        let range = start..(start + (1 << self.block_shift)).min(self.cells);
        let cells = &coefficients[range.clone()];
        if PREFETCH {
            super::prefetch::lines(cells, BLOCK_BYTES);
            block_found(range);
        }
        let sum = self.blocks.weight(b);
        let (i, q) = if x < sum / 2 { self.scan_up(cells, x) } else { self.scan_down(cells, sum - x) };
        Some((start + i, q))
    }

    /// The probability of drawing a cell of weight `q` (its [`CellSampler::probability`]).
    #[inline]
    pub fn probability_of_weight(&self, q: u64) -> f64 {
        match self.total() {
            0 => 0.0,
            total => q as f64 / total as f64,
        }
    }

    /// The first cell `i` whose cumulative range `[prefix_i, prefix_i + q_i)` holds `x`, and its `q`.
    #[inline]
    fn scan_up<S: Scalar>(&self, cells: &[S], mut x: u64) -> (usize, u64) {
        for (i, c) in cells.iter().enumerate() {
            let q = self.weight(c.get());
            if x < q {
                return (i, q);
            }
            x -= q;
        }
        unreachable!("a block's cells sum to the block's weight")
    }

    /// The same cell found from the block's end with `r = sum - x` in `(0, sum]`: the cell with
    /// `suffix_{i+1} < r <= suffix_i` (equivalent to `prefix_i <= x < prefix_{i+1}`; a cell of
    /// weight zero has `suffix_i = suffix_{i+1}` and is never returned, as going up).
    #[inline]
    fn scan_down<S: Scalar>(&self, cells: &[S], mut r: u64) -> (usize, u64) {
        for (i, c) in cells.iter().enumerate().rev() {
            let q = self.weight(c.get());
            if r <= q {
                return (i, q);
            }
            r -= q;
        }
        unreachable!("a block's cells sum to the block's weight")
    }

    /// Heap bytes held.
    pub fn bytes(&self) -> usize {
        self.blocks.bytes()
    }
    /// The heap buffer of the block sums.
    pub fn storage_span(&self) -> Span {
        self.blocks.storage_span()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::rng::stream;

    /// The block sampler draws exactly the cell the full tree over the cells' `q` draws, for the
    /// same random stream, in both precisions, with zeros, and after updates.
    #[test]
    fn draws_the_cells_of_the_full_tree() {
        fn check<S: Scalar>(n: usize) {
            let mut coefficients: Vec<S> =
                (0..n).map(|i| S::put(if i % 5 == 2 { 0.0 } else { ((i * 7919) % 1000 + 1) as f64 * 1e-3 })).collect();
            let mut sampler = CellSampler::new(&coefficients);
            for k in 0..n / 3 {
                let cell = (k * 37) % n;
                let old = coefficients[cell].get();
                coefficients[cell] = S::put(old * 3.0 + 0.25);
                assert!(sampler.update(cell, old, coefficients[cell].get()));
            }
            let leaves: Vec<u64> = coefficients.iter().map(|c| sampler.weight(c.get())).collect();
            let full = PartialSumTree::from_weights(&leaves);
            assert_eq!(full.total(), sampler.total());
            let (mut a, mut b) = (stream(1, "cells"), stream(1, "cells"));
            for _ in 0..20_000 {
                let (cell, q) = sampler.sample_weighted(&coefficients, &mut a).unwrap();
                assert_eq!(Some(cell), full.sample(&mut b));
                assert_eq!(q, full.weight(cell));
                assert_eq!(sampler.probability(coefficients[cell].get()), full.probability(cell));
                assert_eq!(sampler.probability_of_weight(q), full.probability(cell));
            }
        }
        for n in [1, 2, 8, 16, 32, 128, 2048] {
            check::<f64>(n);
            check::<f32>(n);
        }
        assert_eq!(CellSampler::new(&[0.0f64; 4]).sample(&[0.0f64; 4], &mut stream(2, "z")), None);
    }
}

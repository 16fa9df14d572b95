//! The flat tree of partial sums that samples the cache PDF (paper 001 §4.2, after Veach 1997).
//!
//! A complete binary tree over `N` leaves stored in one array of `2N - 1` nodes (node `k` has
//! children `2k + 1` and `2k + 2`, leaf `i` is node `N - 1 + i`), each node holding the sum of its
//! children. Updating a leaf walks one branch (`O(log N)`); sampling draws `x` uniformly in
//! `[0, root)` and descends: left when `x` is below the left child's sum, otherwise subtract it and
//! go right (`O(log N)`).
//!
//! Weights are unsigned integers. Integer sums are exact, so every node is exactly the sum of its
//! leaves, `x` is exactly uniform (`gen_range`), and a leaf is drawn with probability exactly
//! `w_i / root` — the probability [`PartialSumTree::probability`] reports. (With floating-point
//! sums a leaf much smaller than its sibling can be unreachable, `fl(a + b) = a`, while its
//! reported probability is positive: a bias. The cache quantises its PDF coefficients instead; see
//! [`super::RadianceCache`].)

use super::huge_pages::{span_of, Span};
use rand::Rng;

/// A flat partial-sum tree over integer weights.
#[derive(Clone, Debug)]
pub struct PartialSumTree {
    nodes: Vec<u64>,
    leaves: usize,
}

impl PartialSumTree {
    /// A tree of `leaves >= 1` zero weights.
    pub fn new(leaves: usize) -> Self {
        assert!(leaves >= 1, "a partial-sum tree needs at least one leaf");
        PartialSumTree { nodes: vec![0; 2 * leaves - 1], leaves }
    }
    /// A tree over `weights` (built bottom-up in `O(N)`). The caller keeps the total below
    /// `u64::MAX`.
    pub fn from_weights(weights: &[u64]) -> Self {
        let mut t = Self::new(weights.len());
        t.rebuild(weights);
        t
    }
    /// Replaces every weight (`weights.len()` must equal the leaf count), `O(N)`.
    pub fn rebuild(&mut self, weights: &[u64]) {
        assert_eq!(weights.len(), self.leaves, "one weight per leaf");
        let first = self.leaves - 1;
        self.nodes[first..].copy_from_slice(weights);
        for k in (0..first).rev() {
            self.nodes[k] = self.nodes[2 * k + 1] + self.nodes[2 * k + 2];
        }
    }
    /// Number of leaves `N`.
    pub fn leaves(&self) -> usize {
        self.leaves
    }
    /// The sum of all weights (the root).
    pub fn total(&self) -> u64 {
        self.nodes[0]
    }
    /// The weight of leaf `i`.
    pub fn weight(&self, i: usize) -> u64 {
        self.nodes[self.leaves - 1 + i]
    }
    /// Sets the weight of leaf `i`, updating the `log2(2N)` nodes of its branch.
    pub fn set(&mut self, i: usize, w: u64) {
        let mut k = self.leaves - 1 + i;
        let old = self.nodes[k];
        if old == w {
            return;
        }
        loop {
            // Every ancestor holds at least `old`, so neither form can underflow.
            self.nodes[k] = if w > old { self.nodes[k] + (w - old) } else { self.nodes[k] - (old - w) };
            if k == 0 {
                break;
            }
            k = (k - 1) / 2;
        }
    }
    /// The probability with which [`PartialSumTree::sample`] returns leaf `i` (0 when the total is 0).
    pub fn probability(&self, i: usize) -> f64 {
        match self.total() {
            0 => 0.0,
            total => self.weight(i) as f64 / total as f64,
        }
    }
    /// Draws a leaf with probability `w_i / total`, or `None` when every weight is zero. Leaves of
    /// weight zero are never returned.
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> Option<usize> {
        let total = self.total();
        if total == 0 {
            return None;
        }
        Some(self.find(rng.gen_range(0..total)).0)
    }
    /// The leaf whose range of the cumulative sums holds `x < total`, and `x` minus the sum of the
    /// leaves before it in the descent (the offset inside that leaf's range).
    #[inline]
    pub fn find(&self, mut x: u64) -> (usize, u64) {
        let mut k = 0;
        while k < self.leaves - 1 {
            let left = self.nodes[2 * k + 1];
            if x < left {
                k = 2 * k + 1;
            } else {
                x -= left;
                k = 2 * k + 2;
            }
        }
        (k - (self.leaves - 1), x)
    }
    /// Heap bytes held.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<u64>()
    }
    /// Requests the lines of the first `max_bytes` bytes of nodes (the levels nearest the root)
    /// ahead of a descent, which otherwise waits for one level before reading the next.
    #[inline]
    pub fn prefetch(&self, max_bytes: usize) {
        super::prefetch::lines(&self.nodes, max_bytes);
    }
    /// The heap buffer of the nodes.
    pub fn storage_span(&self) -> Span {
        span_of(&self.nodes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::rng::stream;
    use mcbench_core::samplers::testing::sampler_alpha;
    use mcbench_core::stats::chi_square_gof;

    /// Chi-square of the tree sampler against its reported probabilities, on a non-power-of-two
    /// tree with weights spanning ten orders of magnitude and some zeros (book: statistics.md).
    #[test]
    fn chi_square_partial_sum_tree_sampler() {
        let weights: Vec<u64> =
            (0..37u64).map(|i| if i % 7 == 3 { 0 } else { (i * i * 7919 + 13) % 1000 + 1 }).collect();
        let mut tree = PartialSumTree::from_weights(&weights);
        // Exercise `set` too: the sampled tree must be the one the updates produced.
        tree.set(5, 4000);
        tree.set(6, 0);
        tree.set(6, 17);
        let mut rng = stream(21, "partial-sum tree");
        let mut counts = vec![0u64; tree.leaves()];
        for _ in 0..300_000 {
            counts[tree.sample(&mut rng).unwrap()] += 1;
        }
        let probs: Vec<f64> = (0..tree.leaves()).map(|i| tree.probability(i)).collect();
        for (i, &c) in counts.iter().enumerate() {
            if probs[i] == 0.0 {
                assert_eq!(c, 0, "zero-weight leaf {i} was drawn");
            }
        }
        let chi = chi_square_gof(&counts, &probs).unwrap();
        assert!(chi.p_value > sampler_alpha(), "p = {}", chi.p_value);
    }

    #[test]
    fn nodes_are_exact_sums_and_tiny_leaves_stay_reachable() {
        let mut tree = PartialSumTree::new(8);
        assert_eq!(tree.sample(&mut stream(1, "t")), None);
        tree.set(3, 1);
        tree.set(4, 1 << 60);
        assert_eq!(tree.total(), (1 << 60) + 1);
        tree.set(4, 5);
        assert_eq!(tree.total(), 6);
        assert_eq!(tree.probability(3), 1.0 / 6.0);
        // A leaf 2^-60 of its sibling: drawn exactly when x = 0, i.e. reachable, never lost.
        tree.set(4, 1 << 60);
        let mut rng = stream(2, "t");
        assert!((0..1000).all(|_| tree.sample(&mut rng).is_some_and(|i| i == 3 || i == 4)));
        assert_eq!(tree.bytes(), 15 * 8);
    }
}

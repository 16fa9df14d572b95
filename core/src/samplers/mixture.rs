//! Deterministic mixture sampling (paper 003 §4.3, after Hesterberg 1995): for `N` draws from a
//! mixture with weights `alpha_k`, component `k` gets `floor(N alpha_k)` draws and the
//! `R = N - sum_k floor(N alpha_k)` remaining draws are taken i.i.d. from the residual
//! distribution `(N alpha_k - floor(N alpha_k)) / R`. Then `E[n_k] = N alpha_k` exactly, so
//! weighting every sample by `f / K` with the full mixture `K = sum_k alpha_k h_k` (paper 003
//! Eq. 8) stays unbiased, with less variance than drawing components at random.

use rand::Rng;

/// Draws per component for `n` samples with weights `alphas` (non-negative, summing to 1 up to
/// rounding). Components with `alpha_k = 0` never get a draw.
pub fn dms_counts<R: Rng + ?Sized>(alphas: &[f64], n: usize, rng: &mut R) -> Vec<usize> {
    let total: f64 = alphas.iter().sum();
    let mut counts = Vec::with_capacity(alphas.len());
    let mut residual = Vec::with_capacity(alphas.len());
    for &a in alphas {
        let target = n as f64 * a / total;
        let base = target.floor();
        counts.push(base as usize);
        residual.push(target - base);
    }
    let assigned: usize = counts.iter().sum();
    let rest = n.saturating_sub(assigned);
    let rsum: f64 = residual.iter().sum();
    for _ in 0..rest {
        // Rounding can leave rsum = 0 with draws to place: fall back to the weights themselves.
        let weights = if rsum > 0.0 { &residual } else { &alphas.to_vec() };
        counts[pick(weights, rng)] += 1;
    }
    counts
}

/// [`dms_counts`] for many components (paper 003 §4.3: one component per pixel): the same
/// `floor(n alpha_k)` plus i.i.d. residual draws, each residual draw a binary search in the
/// cumulative residual table (`O(n log K)` instead of `O(n K)`). `alphas` must sum to 1 up to
/// rounding; components with `alpha_k = 0` never get a draw.
pub fn dms_allocate<R: Rng + ?Sized>(alphas: &[f64], n: usize, rng: &mut R) -> Vec<usize> {
    let total: f64 = alphas.iter().sum();
    let mut counts = Vec::with_capacity(alphas.len());
    let mut cumulative = Vec::with_capacity(alphas.len());
    let mut acc = 0.0;
    for &a in alphas {
        let target = n as f64 * a / total;
        let base = target.floor();
        counts.push(base as usize);
        acc += target - base;
        cumulative.push(acc);
    }
    let rest = n.saturating_sub(counts.iter().sum());
    for _ in 0..rest {
        let k = if acc > 0.0 {
            // The first entry whose cumulative residual exceeds u has positive residual mass; a
            // u rounded up to the total falls on the last entry with mass.
            let u = rng.gen::<f64>() * acc;
            let k = cumulative.partition_point(|&c| c <= u);
            if k < alphas.len() {
                k
            } else {
                (0..alphas.len())
                    .rev()
                    .find(|&j| cumulative[j] > if j == 0 { 0.0 } else { cumulative[j - 1] })
                    .unwrap_or(0)
            }
        } else {
            // Rounding left no residual mass: fall back to the weights themselves.
            pick(alphas, rng)
        };
        counts[k] += 1;
    }
    counts
}

/// Index drawn with probability proportional to `weights` (at least one positive).
pub fn pick<R: Rng + ?Sized>(weights: &[f64], rng: &mut R) -> usize {
    let total: f64 = weights.iter().sum();
    let mut u = rng.gen::<f64>() * total;
    let mut last = 0;
    for (k, &w) in weights.iter().enumerate() {
        if w > 0.0 {
            if u < w {
                return k;
            }
            u -= w;
            last = k;
        }
    }
    last
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    #[test]
    fn counts_are_floor_plus_residual_with_the_right_means() {
        let alphas = [0.37, 0.05, 0.5, 0.08];
        let mut rng = stream(3, "dms");
        let n = 8;
        let reps = 40_000;
        let mut sums = [0.0f64; 4];
        for _ in 0..reps {
            let c = dms_counts(&alphas, n, &mut rng);
            assert_eq!(c.iter().sum::<usize>(), n);
            for k in 0..4 {
                let t = n as f64 * alphas[k];
                assert!(c[k] as f64 >= t.floor() && (c[k] as f64) <= t.floor() + (n - 5) as f64, "{c:?}");
                sums[k] += c[k] as f64;
            }
        }
        for k in 0..4 {
            // Extra draws are Binomial(3, p_k): standard error of the mean below 0.01.
            let mean = sums[k] / reps as f64;
            assert!((mean - n as f64 * alphas[k]).abs() < 0.04, "component {k}: mean {mean}");
        }
        assert_eq!(dms_counts(&[0.0, 1.0, 0.0], 5, &mut rng), vec![0, 5, 0]);
    }

    #[test]
    fn many_component_allocation_has_the_right_means_and_skips_zero_weights() {
        let mut rng = stream(4, "dms many");
        let k = 300;
        let mut alphas: Vec<f64> = (0..k).map(|i| if i % 7 == 0 { 0.0 } else { 1.0 + (i % 5) as f64 }).collect();
        let t: f64 = alphas.iter().sum();
        alphas.iter_mut().for_each(|a| *a /= t);
        let n = 1000;
        let reps = 4000;
        let mut sums = vec![0.0f64; k];
        for _ in 0..reps {
            let c = dms_allocate(&alphas, n, &mut rng);
            assert_eq!(c.iter().sum::<usize>(), n);
            for j in 0..k {
                let target = n as f64 * alphas[j];
                assert!(c[j] as f64 >= target.floor(), "{j}: {} < {target}", c[j]);
                if alphas[j] == 0.0 {
                    assert_eq!(c[j], 0);
                }
                sums[j] += c[j] as f64;
            }
        }
        for j in 0..k {
            // Extra draws: at most Binomial(k, r_j) per repetition; the mean over 4000 reps has a
            // standard error below 0.02.
            let mean = sums[j] / reps as f64;
            assert!(
                (mean - n as f64 * alphas[j]).abs() < 0.1,
                "component {j}: mean {mean} vs {}",
                n as f64 * alphas[j]
            );
        }
    }
}

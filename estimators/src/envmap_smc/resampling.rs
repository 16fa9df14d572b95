//! Resampling schemes and the effective sample size in log space (paper 004 §3 Step 1a):
//! multinomial, residual, stratified and systematic resampling, each giving offspring counts
//! with `E[count_i] = N W_i` (tested beside the code).

use rand::Rng;

/// A resampling scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheme {
    /// N independent draws from the weights.
    Multinomial,
    /// `floor(N W_i)` copies, the remainder multinomially from the residual weights.
    Residual,
    /// One uniform draw in each of the N strata of [0, 1).
    Stratified,
    /// One uniform draw shifted through the N strata (the default: lowest variance here).
    Systematic,
}

impl Scheme {
    /// Parses `multinomial`, `residual`, `stratified` or `systematic`, or the codes 0..3 used in
    /// numeric parameters (in that order).
    pub fn from_code(code: usize) -> Option<Scheme> {
        [Scheme::Multinomial, Scheme::Residual, Scheme::Stratified, Scheme::Systematic].get(code).copied()
    }
}

/// Normalised weights `W_i = exp(l_i - logsumexp(l))` and `logsumexp(l)` of log weights; `None`
/// when every weight is zero (all `-inf`) or any is NaN or `+inf`.
pub fn normalise_log_weights(log_w: &[f64]) -> Option<(Vec<f64>, f64)> {
    if log_w.iter().any(|l| l.is_nan() || *l == f64::INFINITY) {
        return None;
    }
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        return None;
    }
    // Relative to the largest weight: `l - max` is exact (Sterbenz) for weights within a factor 2
    // in log value, so weights of log size -1e4 normalise to full precision instead of losing
    // |l| eps to the rounding of `lse` (the `stability` case smc-log-weights-underflow).
    let sum: f64 = log_w.iter().map(|l| (l - max).exp()).sum();
    let ln_sum = sum.ln();
    Some((log_w.iter().map(|l| ((l - max) - ln_sum).exp()).collect(), max + ln_sum))
}

/// `log(sum_i exp(l_i))`, `-inf` for an empty or all-zero set.
pub fn log_sum_exp(log_w: &[f64]) -> f64 {
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        return max;
    }
    max + log_w.iter().map(|l| (l - max).exp()).sum::<f64>().ln()
}

/// Effective sample size `1 / sum W_i^2` (Liu and Chen 1998) of log weights, computed in log space
/// (`exp(2 lse(l) - lse(2 l))`): 0 when every weight is zero.
pub fn effective_sample_size(log_w: &[f64]) -> f64 {
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY || max.is_nan() {
        return 0.0;
    }
    // Shifted by the largest log weight (the ESS is scale-free) so large |l| cost no precision.
    let shifted: Vec<f64> = log_w.iter().map(|l| l - max).collect();
    let a = log_sum_exp(&shifted);
    let doubled: Vec<f64> = shifted.iter().map(|l| 2.0 * l).collect();
    (2.0 * a - log_sum_exp(&doubled)).exp()
}

/// Draws `n` ancestor indices from normalised weights `w` (summing to 1) with `scheme`.
pub fn resample<R: Rng + ?Sized>(scheme: Scheme, w: &[f64], n: usize, rng: &mut R) -> Vec<usize> {
    let mut out = Vec::with_capacity(n);
    match scheme {
        Scheme::Multinomial => {
            let cdf = Cumulative::new(w);
            for _ in 0..n {
                out.push(cdf.pick(rng.gen::<f64>()));
            }
        }
        Scheme::Stratified => {
            let u: Vec<f64> = (0..n).map(|k| (k as f64 + rng.gen::<f64>()) / n as f64).collect();
            sweep(w, &u, &mut out);
        }
        Scheme::Systematic => {
            let u0 = rng.gen::<f64>();
            let u: Vec<f64> = (0..n).map(|k| (k as f64 + u0) / n as f64).collect();
            sweep(w, &u, &mut out);
        }
        Scheme::Residual => {
            let mut residual = Vec::with_capacity(w.len());
            for (i, wi) in w.iter().enumerate() {
                let copies = (n as f64 * wi).floor() as usize;
                out.extend(std::iter::repeat_n(i, copies.min(n - out.len().min(n))));
                residual.push(n as f64 * wi - copies as f64);
            }
            let rest = n.saturating_sub(out.len());
            let total: f64 = residual.iter().sum();
            let cdf = Cumulative::new(if total > 0.0 { &residual } else { w });
            for _ in 0..rest {
                out.push(cdf.pick(if total > 0.0 { rng.gen::<f64>() * total } else { rng.gen::<f64>() }));
            }
        }
    }
    out
}

/// The cumulative sums of the positive weights of `w` (accumulated in index order, exactly as a
/// linear scan would), for `O(log N)` inverse-CDF draws instead of an `O(N)` scan per draw.
struct Cumulative {
    /// Running sum after each positive weight.
    acc: Vec<f64>,
    /// The index of that weight.
    index: Vec<usize>,
}

impl Cumulative {
    fn new(w: &[f64]) -> Self {
        let (mut acc, mut index, mut sum) = (Vec::with_capacity(w.len()), Vec::with_capacity(w.len()), 0.0);
        for (i, wi) in w.iter().enumerate() {
            if *wi > 0.0 {
                sum += wi;
                acc.push(sum);
                index.push(i);
            }
        }
        Cumulative { acc, index }
    }
    /// The index whose cumulative interval contains `u` (in the units of `w`'s sum): the first
    /// positive weight with `u < acc`, else the last positive one (rounding past the end, or a
    /// NaN `u`), else 0; never an index of zero weight when one is positive.
    fn pick(&self, u: f64) -> usize {
        let k = if u.is_nan() { self.acc.len() } else { self.acc.partition_point(|&a| a <= u) };
        match self.index.get(k) {
            Some(&i) => i,
            None => self.index.last().copied().unwrap_or(0),
        }
    }
}

/// Inverse-CDF sweep of sorted points `u` in [0, 1) through the weights.
fn sweep(w: &[f64], u: &[f64], out: &mut Vec<usize>) {
    let (mut acc, mut i, mut last) = (0.0, 0usize, 0usize);
    for &uk in u {
        while i < w.len() && acc + w[i] <= uk {
            acc += w[i];
            if w[i] > 0.0 {
                last = i;
            }
            i += 1;
        }
        if i < w.len() && w[i] > 0.0 {
            out.push(i);
        } else {
            out.push(last); // rounding past the end of the weights
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::stats::{holm_bonferroni, one_sample_t};

    /// The binary-search draw returns exactly the index a linear scan of the cumulative weights
    /// returns (zero weights skipped, rounding past the end to the last positive weight).
    #[test]
    fn cumulative_pick_matches_the_linear_scan() {
        let scan = |w: &[f64], u: f64| {
            let (mut acc, mut last) = (0.0, 0);
            for (i, wi) in w.iter().enumerate() {
                if *wi > 0.0 {
                    acc += wi;
                    last = i;
                    if u < acc {
                        return i;
                    }
                }
            }
            last
        };
        let mut rng = mcbench_core::rng::stream(5, "cumulative pick");
        for n in [1usize, 2, 7, 64] {
            let w: Vec<f64> = (0..n).map(|i| if i % 3 == 1 { 0.0 } else { rng.gen::<f64>() }).collect();
            let cdf = Cumulative::new(&w);
            let total: f64 = w.iter().sum();
            for u in (0..200).map(|k| total * k as f64 / 199.0).chain([0.0, total, 2.0 * total, f64::NAN]) {
                assert_eq!(cdf.pick(u), scan(&w, u), "n {n} u {u}");
            }
        }
        assert_eq!(Cumulative::new(&[0.0, 0.0]).pick(0.5), 0);
    }

    const SCHEMES: [Scheme; 4] = [Scheme::Multinomial, Scheme::Residual, Scheme::Stratified, Scheme::Systematic];

    /// Smallest Holm-adjusted p-value of one-sample t-tests of `mean count_i = N W_i` over `reps`
    /// resamplings (indices whose count never varies must match exactly, up to 1e-3).
    fn offspring_p(
        w: &[f64],
        n: usize,
        reps: usize,
        seed: u64,
        mut draw: impl FnMut(&mut mcbench_core::rng::StreamRng) -> Vec<usize>,
    ) -> f64 {
        let mut rng = mcbench_core::rng::stream(seed, "resampling");
        let (mut sum, mut sum2) = (vec![0.0; w.len()], vec![0.0; w.len()]);
        for _ in 0..reps {
            let idx = draw(&mut rng);
            assert_eq!(idx.len(), n);
            let mut c = vec![0.0; w.len()];
            for i in idx {
                c[i] += 1.0;
            }
            for i in 0..w.len() {
                sum[i] += c[i];
                sum2[i] += c[i] * c[i];
            }
        }
        let mut ps = Vec::new();
        for i in 0..w.len() {
            let mean = sum[i] / reps as f64;
            let var = (sum2[i] / reps as f64 - mean * mean).max(0.0) * reps as f64 / (reps - 1) as f64;
            let expect = n as f64 * w[i];
            if var == 0.0 {
                ps.push(if (mean - expect).abs() < 1e-3 { 1.0 } else { 0.0 });
            } else {
                ps.push(one_sample_t(mean, (var / reps as f64).sqrt(), reps as u64, expect).p_value);
            }
        }
        holm_bonferroni(&ps).into_iter().fold(1.0, f64::min)
    }

    fn weights() -> Vec<f64> {
        let raw = [0.0, 1e-6, 0.05, 0.3, 2.0, 0.11, 0.7, 0.0, 1.3];
        let total: f64 = raw.iter().sum();
        raw.iter().map(|x| x / total).collect()
    }

    /// Unbiased offspring counts: over 40 000 resamplings the mean count of every index is
    /// `N W_i` (Holm-Bonferroni over indices at alpha 1e-3, Sidak-corrected over the 4 schemes),
    /// for weights with zeros, a tiny and a dominant entry.
    #[test]
    fn offspring_counts_are_unbiased_for_every_scheme() {
        let w = weights();
        let alpha = mcbench_core::stats::sidak_alpha(1e-3, SCHEMES.len());
        for (s, scheme) in SCHEMES.iter().enumerate() {
            let p = offspring_p(&w, 7, 40_000, 100 + s as u64, |r| resample(*scheme, &w, 7, r));
            assert!(p > alpha, "{scheme:?}: smallest Holm-adjusted p = {p}");
        }
    }

    /// Teeth: a biased scheme (systematic with the offset fixed at 0.5, i.e. rounding N W_i to the
    /// nearest cumulative stratum) is flagged by the same test.
    #[test]
    fn the_offspring_test_flags_a_biased_scheme() {
        let w = weights();
        let p = offspring_p(&w, 7, 40_000, 7, |_| {
            let u: Vec<f64> = (0..7).map(|k| (k as f64 + 0.5) / 7.0).collect();
            let mut out = Vec::new();
            sweep(&w, &u, &mut out);
            out
        });
        assert!(p < 1e-6, "p = {p}");
    }

    #[test]
    fn ess_in_log_space_survives_underflow_and_zero_weights() {
        let l = [-1e4, -1e4 - 0.5, f64::NEG_INFINITY, -1e4];
        let ess = effective_sample_size(&l);
        let w = [1.0, (-0.5f64).exp(), 0.0, 1.0];
        let direct = w.iter().sum::<f64>().powi(2) / w.iter().map(|x| x * x).sum::<f64>();
        assert!((ess - direct).abs() < 1e-9, "{ess} vs {direct}");
        assert_eq!(effective_sample_size(&[f64::NEG_INFINITY; 3]), 0.0);
        assert!(normalise_log_weights(&[f64::NEG_INFINITY; 3]).is_none());
        assert!(normalise_log_weights(&[0.0, f64::NAN]).is_none());
        let (wn, lse) = normalise_log_weights(&[-800.0, -800.0]).unwrap();
        assert!((wn[0] - 0.5).abs() < 1e-12 && (lse - (-800.0 + 2f64.ln())).abs() < 1e-12);
    }
}

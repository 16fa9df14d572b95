//! How PMC-IP combines its sub-images (paper 003 §4.4): the initial image and one sub-image per
//! adaptive iteration, each an unbiased estimate of every pixel (Eq. 3 with `p = h_p`, §4.1),
//! summed with per-pixel weights `w_t(p)` that add up to 1.
//!
//! The whole estimate stays unbiased when each weight is *committed before its sub-image is
//! drawn*: `w_t(p)` may depend on anything sampled earlier, and on the kernel of iteration `t`
//! (hence on the expected counts `E[n_t(p)] = N_t alpha_p`, §4.3), but not on the samples it
//! weights nor on anything they influence later (the later allocations do depend on them, through
//! `sigma_p^2`, which is why pooling every sample of a pixel is biased). Then
//! `E[w_t sub_t] = E[w_t E[sub_t | before t]] = I_p E[w_t]`, and the weights sum to 1.
//!
//! - [`Combine::Fixed`]: each sub-image's share of the planned budget, `N_t / N` (2/10, 4/10,
//!   4/10 at 2+4+4). Constant, so unbiased. The initial image alone then costs
//!   `(s_0 / spp)^2 sigma_p^2 / s_0` in every pixel, so no allocation can gain more than
//!   `spp / s_0` in `Err` over uniform sampling at `spp` (5 at 2+4+4).
//! - [`Combine::Unweighted`]: "the unweighted average of three sub-images (initial and two
//!   iterations)", the paper's literal combination (§4.4): `1 / (T + 1)` each. Constant, so
//!   unbiased; at 2+4+4 the initial image alone costs `sigma^2 / 18` per pixel, which caps the
//!   gain at 1.8.
//! - [`Combine::InverseVariance`]: weights from each sub-image's variance. Every sub-image draws
//!   the same per-sample sampler (§4.4: "they all used the same per-sample parameters"), so
//!   sub-image `t` of pixel `p` has variance `sigma_p^2 / n_t(p)` and inverse-variance weights are
//!   proportional to its expected count `e_t(p)`. They are committed one sub-image at a time: of
//!   the weight still unassigned, `R_t(p)`, sub-image `t` takes `R_t e_t / (e_t + E^_t)`, where
//!   `E^_t` is the expected count of the later sub-images predicted with the current kernel; the
//!   last takes all that is left. The initial image's weight cannot look at its own samples, so
//!   its prediction is a *separate estimate*: the kernel weight pixel `p` would get if its
//!   luminance had the mean variance and mean of its (up to 8) neighbours' initial samples,
//!   normalised against the other pixels' own weights. Pixel `p`'s initial samples enter none of that, so the initial weight is independent
//!   of the initial sub-image it weights.
//! - [`Combine::Pooled`]: the plain mean of every sample a pixel received, over the initial image
//!   and all iterations: sub-image `t` weighs `n_t(p) / sum_s n_s(p)`, its *realised* count,
//!   known only at the end. This is the other reading of §4.4 ("it is not clear that the samples
//!   from one iteration are any better than those from another" fits a per-sample average as
//!   well as an average of sub-images), and it escapes the unweighted average's bound. It breaks
//!   the rule above: the later counts depend on the pixel's earlier samples (through
//!   `sigma_p^2`), so the initial image's weight is correlated with its value and the estimate may
//!   be biased. Nothing corrects that; the unbiasedness tests measure it.

use super::ip::{Allocation, PmcIp};
use mcbench_core::math::Rgb;
use mcbench_core::stats::Moments;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How the sub-images are combined (parameter `combine` of `pmc_ip`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(inline)]
pub enum Combine {
    /// Each sub-image weighted by its share of the planned budget, `N_t / N`.
    #[default]
    Fixed,
    /// The paper's unweighted average of the sub-images, `1 / (T + 1)` each (§4.4).
    Unweighted,
    /// Per-pixel weights proportional to each sub-image's expected count, committed before it is
    /// drawn; the initial image's from its neighbours' samples.
    InverseVariance,
    /// The plain mean of every sample of the pixel (weights `n_t(p) / sum_s n_s(p)`, known only
    /// at the end): the per-sample reading of §4.4, which may be biased (the later counts depend
    /// on the earlier samples).
    Pooled,
}

/// The weights of the sub-images of one run, committed one sub-image at a time.
pub struct SubImageWeights {
    combine: Combine,
    /// Samples per pixel of the initial image.
    s0: usize,
    /// Population sizes `N_t` of the adaptive iterations.
    populations: Vec<usize>,
    /// Samples of the whole image, `N`.
    total: usize,
    /// Samples reserved for every pixel in every iteration.
    min_samples: usize,
    /// The weight not yet assigned, per pixel.
    remaining: Vec<f64>,
}

impl SubImageWeights {
    /// The weights of a run over `pixels` pixels: `s0` initial samples per pixel, then the
    /// populations `populations` (summing with the initial image to `total`).
    pub fn new(ip: &PmcIp, pixels: usize, s0: usize, populations: Vec<usize>, total: usize) -> Self {
        SubImageWeights {
            combine: ip.combine,
            s0,
            populations,
            total,
            min_samples: ip.min_samples,
            remaining: vec![1.0; pixels],
        }
    }

    fn pixels(&self) -> usize {
        self.remaining.len()
    }

    /// Expected samples of pixel `p` in population `t` under kernel weight `alpha` (§4.3, as
    /// [`PmcIp::allocate`] reserves them).
    fn expected(&self, t: usize, alpha: f64) -> f64 {
        let n = self.populations[t];
        let m = if n >= self.min_samples * self.pixels() { self.min_samples } else { 0 };
        m as f64 + (n - m * self.pixels()) as f64 * alpha
    }

    /// Commits `e / (e + later)` of what pixel `p` has left (all of it for the last sub-image).
    fn commit(&mut self, p: usize, e: f64, later: f64, last: bool) -> f64 {
        let w = if last {
            self.remaining[p]
        } else if e + later > 0.0 {
            self.remaining[p] * (e / (e + later))
        } else {
            0.0
        };
        self.remaining[p] -= w;
        w
    }

    /// The weights of the initial image, given every pixel's statistics after it and each pixel's
    /// neighbours (indices into `stats`).
    ///
    /// Under [`Combine::Pooled`] the weights are the counts `s0`, not yet normalised: see
    /// [`SubImageWeights::population`].
    pub fn initial(&mut self, ip: &PmcIp, stats: &[Moments], neighbours: &[Vec<usize>]) -> Vec<f64> {
        let iterations = self.populations.len();
        match self.combine {
            Combine::Pooled => vec![self.s0 as f64; self.pixels()],
            Combine::Fixed => vec![(self.s0 * self.pixels()) as f64 / self.total as f64; self.pixels()],
            Combine::Unweighted => vec![1.0 / (iterations + 1) as f64; self.pixels()],
            Combine::InverseVariance => {
                let raw: Vec<f64> = stats.iter().map(|m| ip.raw_weight(m)).collect();
                // Sums of the other pixels' own weights, without pixel p's (exactly: prefix and
                // suffix sums, no subtraction).
                let mut before = vec![0.0; raw.len() + 1];
                for (p, r) in raw.iter().enumerate() {
                    before[p + 1] = before[p] + r;
                }
                let mut after = vec![0.0; raw.len() + 1];
                for p in (0..raw.len()).rev() {
                    after[p] = after[p + 1] + raw[p];
                }
                (0..self.pixels())
                    .map(|p| {
                        let own = neighbourhood_weight(ip, stats, &neighbours[p]);
                        let alpha = own / (before[p] + after[p + 1] + own);
                        let later: f64 = (0..iterations).map(|t| self.expected(t, alpha)).sum();
                        self.commit(p, self.s0 as f64, later, iterations == 0)
                    })
                    .collect()
            }
        }
    }

    /// The weights of the sub-image of adaptive iteration `t`, drawn with kernel weights `alpha`
    /// and allocation `a`.
    ///
    /// Under [`Combine::Pooled`] they are the realised counts `n_t(p)`, not normalised: the run
    /// adds `n_t(p)` times the sub-image (the mean of its samples, [`pooled_mean`]) and divides
    /// each pixel by its total count at the end.
    pub fn population(&mut self, t: usize, alpha: &[f64], a: &Allocation) -> Vec<f64> {
        let iterations = self.populations.len();
        match self.combine {
            Combine::Pooled => a.counts.iter().map(|&n| n as f64).collect(),
            Combine::Fixed => vec![self.populations[t] as f64 / self.total as f64; self.pixels()],
            Combine::Unweighted => vec![1.0 / (iterations + 1) as f64; self.pixels()],
            Combine::InverseVariance => (0..self.pixels())
                .map(|p| {
                    let later: f64 = (t + 1..iterations).map(|s| self.expected(s, alpha[p])).sum();
                    self.commit(p, a.expected[p], later, t + 1 == iterations)
                })
                .collect(),
        }
    }
}

/// The mean of `count` samples whose sum is `sum` (0 without samples): a sub-image under
/// [`Combine::Pooled`], whatever the allocation guarantees.
pub fn pooled_mean(sum: Rgb, count: usize) -> Rgb {
    if count > 0 {
        sum / count as f64
    } else {
        Rgb::ZERO
    }
}

/// The kernel weight (before normalisation) of a pixel predicted from its neighbours: the mean
/// of their sample variances (within each neighbour, so an edge between two flat regions does not
/// count as noise) and the mean of their means; `eps` alone without neighbours.
fn neighbourhood_weight(ip: &PmcIp, stats: &[Moments], neighbours: &[usize]) -> f64 {
    let (mut var, mut nv, mut mean, mut nm) = (0.0, 0usize, 0.0, 0usize);
    for m in neighbours.iter().map(|&q| &stats[q]) {
        if m.count() >= 2 {
            var += m.variance();
            nv += 1;
        }
        if m.count() >= 1 {
            mean += m.mean();
            nm += 1;
        }
    }
    ip.raw_weight_of(if nv > 0 { var / nv as f64 } else { 0.0 }, if nm > 0 { mean / nm as f64 } else { 0.0 })
}

/// The up to 8 neighbours of each of `pixels` (image indices, row-major in a `width x height`
/// image) among `pixels` themselves, as positions in `pixels`.
pub fn neighbours(pixels: &[usize], width: usize, height: usize) -> Vec<Vec<usize>> {
    let mut at = vec![None; width * height];
    for (k, &i) in pixels.iter().enumerate() {
        if i < at.len() {
            at[i] = Some(k);
        }
    }
    pixels
        .iter()
        .map(|&i| {
            if i >= at.len() {
                return Vec::new();
            }
            let (x, y) = ((i % width) as isize, (i / width) as isize);
            let mut n = Vec::with_capacity(8);
            for dy in -1..=1isize {
                for dx in -1..=1isize {
                    let (nx, ny) = (x + dx, y + dy);
                    if (dx, dy) == (0, 0) || nx < 0 || ny < 0 || nx >= width as isize || ny >= height as isize {
                        continue;
                    }
                    n.extend(at[ny as usize * width + nx as usize]);
                }
            }
            n
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::params::Params;

    #[test]
    fn neighbours_stay_inside_the_image_and_leave_the_pixel_out() {
        let n = neighbours(&(0..12).collect::<Vec<_>>(), 4, 3);
        assert_eq!(n[0], vec![1, 4, 5]);
        assert_eq!(n[5], vec![0, 1, 2, 4, 6, 8, 9, 10]);
        assert_eq!(n[11], vec![6, 7, 10]);
        // Pixels not in the list are no one's neighbours.
        let n = neighbours(&[0, 5, 7], 4, 3);
        assert_eq!(n, vec![vec![1], vec![0], Vec::<usize>::new()]);
    }

    /// Every rule's weights add up to 1 per pixel and are not negative; the fixed and unweighted
    /// ones are the constants of §4.4.
    #[test]
    fn weights_sum_to_one_per_pixel() {
        let mut stats = vec![Moments::new(); 6];
        for (p, m) in stats.iter_mut().enumerate() {
            m.extend([0.1 * p as f64, 0.5 + (p % 3) as f64]);
        }
        let nb = neighbours(&(0..6).collect::<Vec<_>>(), 3, 2);
        for combine in ["fixed", "unweighted", "inverse_variance"] {
            let mut params = Params::new();
            params.0.insert("combine".into(), mcbench_core::params::ParamValue::Text(combine.into()));
            let ip = PmcIp::from_params(&params).unwrap();
            let mut w = SubImageWeights::new(&ip, 6, 2, vec![12, 12], 36);
            let mut sum = w.initial(&ip, &stats, &nb);
            let mut rng = mcbench_core::rng::stream(1, "sub-images");
            for t in 0..2 {
                let alpha = ip.weights(&stats);
                let a = ip.allocate(&alpha, 12, &mut rng);
                let wt = w.population(t, &alpha, &a);
                if combine == "fixed" {
                    assert!(wt.iter().all(|x| *x == 12.0 / 36.0));
                }
                for (s, x) in sum.iter_mut().zip(wt) {
                    assert!(x >= 0.0);
                    *s += x;
                }
            }
            for s in sum {
                assert!((s - 1.0).abs() < 1e-12, "{combine}: {s}");
            }
        }
    }
}

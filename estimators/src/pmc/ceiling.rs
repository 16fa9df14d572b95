//! The ceiling of image-plane sampling (paper 003 §4): the smallest perceptual error
//! `Err = mean_p e_p^2 / tvi(L_p)` (§4.4) that any allocation of the same number of pixel samples
//! can reach, against uniform sampling's, when each pixel's variance is known exactly.
//!
//! With `n_p` samples of pixel `p` at uniform footprint positions (the per-sample sampler of
//! both `uniform_image` and `pmc_ip`, §4.1) and `sigma_p^2` the variance of one of them, an
//! allocation fixed in advance has `Err = mean_p a_p / n_p` with `a_p = sigma_p^2 / tvi(L_p)`.
//! Minimising it at a fixed total `N = spp P` with at least `floor` samples per pixel (Lagrange
//! multipliers) gives `n_p = max(floor, lambda sqrt(a_p))`: samples in proportion to the
//! perceptually weighted standard deviation ("water-filling"), not to the variance of §4.2. The
//! gain `Err_uniform / Err_best` is the most any image-plane sampler with this per-sample sampler
//! can gain in `Err`; at equal time per sample it is also the most it can gain in P-Eff
//! (`1 / (T Err)`, §4.4).
//!
//! [`schedule_ceiling`] adds PMC-IP's structure: `s_0` uniform samples per pixel first (the
//! initial image, §4.2), whose sub-image is either pooled with the rest (the best any weighting
//! can do) or weighted by a constant (the combinations of [`super::sub_images`]).

use mcbench_core::perception::tvi;

/// The best `Err` an allocation can reach, beside uniform sampling's.
#[derive(Clone, Debug, PartialEq)]
pub struct Ceiling {
    /// `Err` of uniform sampling at `spp`: `mean_p a_p / spp`.
    pub err_uniform: f64,
    /// The smallest `Err` any allocation of the same total reaches.
    pub err_best: f64,
    /// `err_uniform / err_best`: the largest gain in `Err`, and in P-Eff at equal time per sample.
    pub gain: f64,
    /// Samples per pixel of the best allocation (real numbers: whole counts do no better).
    pub samples: Vec<f64>,
}

/// `a_p = sigma_p^2 / tvi(L_p)` of every pixel.
fn perceptual_variances(variance: &[f64], luminance: &[f64]) -> Vec<f64> {
    assert_eq!(variance.len(), luminance.len(), "one variance and one luminance per pixel");
    variance.iter().zip(luminance).map(|(v, l)| v.max(0.0) / tvi(*l)).collect()
}

/// The counts `n_p >= floor` summing to `budget` that minimise `sum a_p / n_p`:
/// `n_p = max(floor, lambda sqrt(a_p))`, `lambda` found by moving the pixels below the floor to
/// it until none is left (the free set only shrinks).
fn water_fill(a: &[f64], budget: f64, floor: f64) -> Vec<f64> {
    let p = a.len() as f64;
    assert!(budget >= floor * p, "a budget of {budget} cannot give {p} pixels {floor} samples each");
    let c: Vec<f64> = a.iter().map(|x| x.sqrt()).collect();
    let mut free: Vec<bool> = c.iter().map(|&x| x > 0.0).collect();
    loop {
        let fixed = free.iter().filter(|f| !**f).count() as f64;
        let total: f64 = c.iter().zip(&free).filter(|(_, f)| **f).map(|(x, _)| x).sum();
        let lambda = if total > 0.0 { (budget - floor * fixed) / total } else { 0.0 };
        let mut changed = false;
        for (x, f) in c.iter().zip(free.iter_mut()) {
            if *f && lambda * x < floor {
                *f = false;
                changed = true;
            }
        }
        if !changed {
            let n: Vec<f64> = c.iter().zip(&free).map(|(x, f)| if *f { lambda * x } else { floor }).collect();
            // Nothing free (every pixel noiseless): spread the budget evenly.
            return if total > 0.0 { n } else { vec![budget / p; a.len()] };
        }
    }
}

/// `mean_p a_p / n_p`, a pixel with no variance counting 0 whatever its count.
fn err(a: &[f64], n: &[f64]) -> f64 {
    a.iter().zip(n).map(|(a, n)| if *a > 0.0 { a / n } else { 0.0 }).sum::<f64>() / a.len().max(1) as f64
}

/// The ceiling of any allocation of `spp` samples per pixel on average, with at least `floor`
/// per pixel, given each pixel's variance of one pixel sample (`variance`, channel mean) and its
/// luminance (`luminance`, the reference's, as in `Err`).
pub fn allocation_ceiling(variance: &[f64], luminance: &[f64], spp: f64, floor: f64) -> Ceiling {
    let a = perceptual_variances(variance, luminance);
    let samples = water_fill(&a, spp * a.len() as f64, floor);
    let err_uniform = err(&a, &vec![spp; a.len()]);
    let err_best = err(&a, &samples);
    Ceiling { err_uniform, err_best, gain: err_uniform / err_best, samples }
}

/// The ceiling of PMC-IP's schedule: `s0` uniform samples per pixel first, then the rest of
/// `spp` per pixel allocated at will with at least `floor` per pixel. The initial sub-image is
/// pooled with the rest (`initial_weight = None`: weights proportional to the counts, the best
/// any combination does) or weighted by the constant `c_0` (`Some(c_0)`; the later sub-images
/// share `1 - c_0`, at best as `(1 - c_0)^2 sigma_p^2 / k_p` for `k_p` later samples).
pub fn schedule_ceiling(
    variance: &[f64],
    luminance: &[f64],
    spp: f64,
    s0: f64,
    initial_weight: Option<f64>,
    floor: f64,
) -> Ceiling {
    let Some(c0) = initial_weight else {
        return allocation_ceiling(variance, luminance, spp, s0 + floor);
    };
    let a = perceptual_variances(variance, luminance);
    let later: Vec<f64> = a.iter().map(|x| x * (1.0 - c0) * (1.0 - c0)).collect();
    let k = water_fill(&later, (spp - s0) * a.len() as f64, floor);
    let initial: Vec<f64> = a.iter().map(|x| x * c0 * c0).collect();
    let err_uniform = err(&a, &vec![spp; a.len()]);
    let err_best = err(&initial, &vec![s0; a.len()]) + err(&later, &k);
    Ceiling { err_uniform, err_best, gain: err_uniform / err_best, samples: k.iter().map(|x| x + s0).collect() }
}

#[cfg(test)]
#[path = "ceiling_tests.rs"]
mod tests;

//! `pmc_ip`: Population Monte Carlo image-plane sampling (paper 003 §4, Fig. 3).
//!
//! The kernel is a mixture with one component per pixel, uniform over the pixel's footprint
//! (§4.1): `K(x) = sum_p alpha_p h_p(x)`. The initial image takes `initial` (2) samples in every
//! pixel; each of the `iterations` (2) following populations spends an equal share of the rest of
//! the image budget (`N_t` samples, 4 per pixel on average for 2 + 4 + 4 = 10 spp) and adapts the
//! weights to the perceptually weighted variance seen so far (§4.2):
//! `alpha_p ∝ eps + sigma_p^2 / tvi(L_p)` (`eps` = 0.01, Ferwerda tvi, `sigma_p^2` the sample
//! variance and `L_p` the mean of the luminance of every sample of pixel `p` so far). Samples are
//! allocated by deterministic mixture sampling (§4.3): `floor(N alpha_p)` per pixel plus i.i.d.
//! residual draws.
//!
//! Estimate (Eq. 3 per pixel, p(x) = h_p(x), "each pixel as an individual integral"): every
//! sample of pixel `p` is weighted by its own pixel component's density, so the sub-image of an
//! iteration is the mean of that pixel's samples. Two decisions keep the whole estimate unbiased
//! (not only each sub-image given its allocation):
//! - the sub-images are combined with weights fixed in advance, their share of the planned
//!   budget (`N_t / N`: 2/10, 4/10, 4/10), never with the realised counts: those depend on the
//!   earlier samples of the same pixel (through `sigma_p^2`), and pooling every sample of a pixel
//!   would correlate the weight of the first sub-image with its value (a bias). The paper averages
//!   its sub-images unweighted (§4.4); fixed shares give the initial 2-spp image less weight and
//!   are just as unbiased;
//! - a sub-image is the mean of its samples only where the allocation guarantees at least one
//!   (`min_samples` per pixel are reserved in every iteration, default 1: a defensive uniform
//!   share of the kernel, Hesterberg 1995, which the paper's `eps` serves). Where it does not
//!   (`min_samples = 0`, or fewer samples than pixels), the sub-image is the Horvitz-Thompson
//!   estimate `sum f / E[n_p]` with `E[n_p] = N alpha_p` exact under DMS: unbiased, and zero when
//!   no sample lands, but noisier (its count varies).
//!
//! Options beyond the paper's defaults (each default is the behaviour above):
//! - `combine` ([`Combine`], [`super::sub_images`]): how the sub-images are combined: `fixed`
//!   (the shares above), `unweighted` (the paper's literal average, §4.4) or `inverse_variance`
//!   (per-pixel weights from each sub-image's variance, committed before it is drawn); `pooled`
//!   (the plain mean of every sample of the pixel, the per-sample reading of §4.4: its weights
//!   are the realised counts, which depend on the earlier samples, so it is biased and declared so:
//!   the unbiasedness tests treat it as a control);
//! - `allocate` ([`Allocate`]): what the kernel weights follow, `variance` (§4.2:
//!   `sigma_p^2 / tvi(L_p)`) or `std_dev` (`sigma_p / sqrt(tvi(L_p))`: the allocation that
//!   minimises `Err = mean sigma_p^2 / (n_p tvi(L_p))` for a fixed total, by Lagrange
//!   multipliers, when `sigma_p` is known; see [`super::ceiling`]);
//! - `luminance_scale`: cd/m^2 per unit of radiance as the kernel's `tvi` sees it (§4.2 reads
//!   luminance in cd/m^2, Ferwerda et al. 1996, and the paper does not give its scene units):
//!   `L_p` and `sigma_p` are multiplied by it before weighting. The default 1 reads radiance as
//!   cd/m^2, as the harness's `Err` does (book: outputs.md).
//!
//! Each estimate notes `alpha_perplexity` (normalised perplexity `exp(H(alpha)) / P` of the
//! kernel weights, 1 = uniform, mean over iterations) and `ht_share` (share of pixel-iterations
//! estimated by Horvitz-Thompson).

pub use super::sub_images::Combine;
use super::sub_images::{neighbours, pooled_mean, SubImageWeights};
use mcbench_core::budget::BudgetKind;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{check_count, check_range, parse, ParamSet, ParamSpec, Params};
use mcbench_core::perception::{luminance, tvi};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::mixture::dms_allocate;
use mcbench_core::stats::Moments;
use mcbench_core::task::{ImageProbe, Task};
use mcbench_core::testbed::Needs;
use rand::Rng;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "pmc_ip",
    paper: "003",
    label: "PMC-IP",
    bias: Bias::Unbiased,
    needs: Needs::IMAGE_PLANE,
    samplers: &[],
    summary: "PMC image-plane sampler: per-pixel mixture, alpha ∝ eps + sigma^2/tvi(L), DMS allocation (§4)",
    build: |p| Ok(Box::new(PmcIp::from_params(p)?)),
    params: ParamSpec::of::<PmcIpParams>().display("PMC-IP").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// Parameters of `pmc_ip`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PmcIpParams {
    /// Samples per pixel of the initial (uniform) image (1 to 2^20).
    pub initial: usize,
    /// Adaptive iterations after the initial image (1 to 4096).
    pub iterations: usize,
    /// The defensive constant of §4.2 added to every pixel's weight (1e-12 to 1e12).
    pub eps: f64,
    /// Samples reserved for every pixel in every iteration (0 to 1024).
    pub min_samples: usize,
    /// How the sub-images are combined (paper 003 §4.4): `fixed` (each its share of the planned
    /// budget), `unweighted` (the paper's average), `inverse_variance` or `pooled` (the mean of
    /// every sample of the pixel; may be biased).
    pub combine: Combine,
    /// What the kernel weights follow (§4.2): `variance` (`sigma^2 / tvi(L)`) or `std_dev`
    /// (`sigma / sqrt(tvi(L))`).
    pub allocate: Allocate,
    /// cd/m^2 per unit of radiance in the kernel's tvi weighting (1e-6 to 1e6).
    pub luminance_scale: f64,
}

impl Default for PmcIpParams {
    fn default() -> Self {
        PmcIpParams {
            initial: 2,
            iterations: 2,
            eps: 0.01,
            min_samples: 1,
            combine: Combine::Fixed,
            allocate: Allocate::Variance,
            luminance_scale: 1.0,
        }
    }
}

/// What PMC-IP's kernel weights follow (parameter `allocate` of `pmc_ip`, paper 003 §4.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(inline)]
pub enum Allocate {
    /// `alpha_p ∝ eps + sigma_p^2 / tvi(L_p)`: "proportional to the perceptually-weighted
    /// variance at each pixel" (§4.2).
    #[default]
    Variance,
    /// `alpha_p ∝ eps + sigma_p / sqrt(tvi(L_p))`: samples in proportion to the perceptually
    /// weighted standard deviation, the allocation that minimises `Err` (§4.4) at a fixed total.
    StdDev,
}

impl ParamSet for PmcIpParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_count("initial", self.initial, 1 << 20)?;
        check_count("iterations", self.iterations, 4096)?;
        check_range("eps", self.eps, 1e-12, 1e12)?;
        check_range("min_samples", self.min_samples as f64, 0.0, 1024.0)?;
        check_range("luminance_scale", self.luminance_scale, 1e-6, 1e6)?;
        Ok(())
    }
}

/// The configured sampler.
#[derive(Clone, Debug, PartialEq)]
pub struct PmcIp {
    /// Samples per pixel of the initial (uniform) image.
    pub initial: u64,
    /// Adaptive iterations after the initial image.
    pub iterations: usize,
    /// The defensive constant of §4.2.
    pub eps: f64,
    /// Samples reserved for every pixel in every iteration.
    pub min_samples: usize,
    /// How the sub-images are combined.
    pub combine: Combine,
    /// What the kernel weights follow.
    pub allocate: Allocate,
    /// cd/m^2 per unit of radiance in the tvi weighting.
    pub luminance_scale: f64,
}

/// The allocation of one population (§4.3).
#[derive(Clone, Debug, PartialEq)]
pub struct Allocation {
    /// Samples per pixel.
    pub counts: Vec<usize>,
    /// Expected samples per pixel, `N alpha~_p` (the kernel weight times the population size).
    pub expected: Vec<f64>,
    /// Whether the allocation guarantees pixel `p` at least one sample.
    pub guaranteed: Vec<bool>,
}

/// Everything one run leaves behind (for the experiment's maps, paper Fig. 4).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    /// The final estimate per pixel.
    pub estimate: Vec<Rgb>,
    /// The initial (uniform) sub-image.
    pub initial_image: Vec<Rgb>,
    /// The kernel weights `alpha~_p` (summing to 1) of each adaptive iteration.
    pub alpha: Vec<Vec<f64>>,
    /// Samples per pixel of each population, the initial one first.
    pub counts: Vec<Vec<usize>>,
    /// Pixel-iterations estimated by Horvitz-Thompson.
    pub horvitz_thompson: usize,
}

impl PmcIp {
    /// Builds from its parameters.
    pub fn new(p: &PmcIpParams) -> Self {
        PmcIp {
            initial: p.initial as u64,
            iterations: p.iterations,
            eps: p.eps,
            min_samples: p.min_samples,
            combine: p.combine,
            allocate: p.allocate,
            luminance_scale: p.luminance_scale,
        }
    }

    /// Parses `initial` (default 2), `iterations` (2), `eps` (0.01), `min_samples` (1),
    /// `combine` (`fixed`), `allocate` (`variance`) and `luminance_scale` (1) as [`PmcIpParams`]
    /// and builds.
    pub fn from_params(p: &Params) -> Result<Self, ConfigError> {
        Ok(PmcIp::new(&parse::<PmcIpParams>("pmc_ip", p)?))
    }

    /// The kernel weights of §4.2 from each pixel's luminance statistics,
    /// `alpha_p ∝` [`PmcIp::raw_weight`]. Every weight is positive and finite.
    pub fn weights(&self, stats: &[Moments]) -> Vec<f64> {
        let raw: Vec<f64> = stats.iter().map(|m| self.raw_weight(m)).collect();
        let total: f64 = raw.iter().sum();
        raw.iter().map(|a| a / total).collect()
    }

    /// One pixel's kernel weight before normalisation (§4.2), from the luminance statistics of
    /// its samples: `eps + s^2 sigma^2 / tvi(s L)` (`allocate = variance`) or
    /// `eps + s sigma / sqrt(tvi(s L))` (`std_dev`), with `s` the luminance scale, `L` the mean
    /// and `sigma^2` the sample variance (0 with fewer than two samples).
    pub fn raw_weight(&self, m: &Moments) -> f64 {
        let var = if m.count() >= 2 { m.variance() } else { 0.0 };
        let mean = if m.count() >= 1 { m.mean() } else { 0.0 };
        self.raw_weight_of(var, mean)
    }

    /// [`PmcIp::raw_weight`] of a pixel whose luminance has variance `var` and mean `mean`.
    pub fn raw_weight_of(&self, var: f64, mean: f64) -> f64 {
        let s = self.luminance_scale;
        let v = match self.allocate {
            Allocate::Variance => s * s * var / tvi(s * mean),
            Allocate::StdDev => s * var.max(0.0).sqrt() / tvi(s * mean).sqrt(),
        };
        self.eps + if v.is_finite() && v > 0.0 { v } else { 0.0 }
    }

    /// Allocates a population of `n` samples over the pixels with weights `alpha`: `min_samples`
    /// per pixel first (when `n` allows it), the rest by deterministic mixture sampling.
    pub fn allocate<R: Rng + ?Sized>(&self, alpha: &[f64], n: usize, rng: &mut R) -> Allocation {
        let pixels = alpha.len();
        let m = if n >= self.min_samples * pixels { self.min_samples } else { 0 };
        let rest = n - m * pixels;
        let extra = dms_allocate(alpha, rest, rng);
        let counts = extra.iter().map(|e| m + e).collect();
        let expected = alpha.iter().map(|a| m as f64 + rest as f64 * a).collect();
        let guaranteed = alpha.iter().map(|a| m + (rest as f64 * a).floor() as usize >= 1).collect();
        Allocation { counts, expected, guaranteed }
    }

    /// One PMC-IP run over the pixels of `probes` with `spp` samples per pixel on average.
    pub fn run(&self, probes: &[ImageProbe<'_>], spp: u64, rng: &mut StreamRng) -> Trace {
        let pixels = probes.len();
        let total = spp as usize * pixels;
        let s0 = self.initial.min(spp) as usize;
        let rest = total - s0 * pixels;
        let iterations = if rest > 0 { self.iterations.min(rest) } else { 0 };
        let populations = (0..iterations).map(|t| rest / iterations + usize::from(t < rest % iterations)).collect();
        let mut weights = SubImageWeights::new(self, pixels, s0, populations, total);
        let mut stats = vec![Moments::default(); pixels];
        let mut trace = Trace { estimate: vec![Rgb::ZERO; pixels], ..Trace::default() };
        // The initial image: s0 uniform samples per pixel.
        for (p, probe) in probes.iter().enumerate() {
            let sum = sample_pixel(probe, s0, &mut stats[p], rng);
            trace.initial_image.push(if s0 > 0 { sum / s0 as f64 } else { Rgb::ZERO });
        }
        let layout = match (self.combine, probes.first()) {
            (Combine::InverseVariance, Some(first)) => {
                let (w, h) = first.resolution();
                neighbours(&probes.iter().map(|p| p.pixel()).collect::<Vec<_>>(), w, h)
            }
            _ => Vec::new(),
        };
        let share = weights.initial(self, &stats, &layout);
        for (p, sub) in trace.initial_image.iter().enumerate() {
            trace.estimate[p] += *sub * share[p];
        }
        trace.counts.push(vec![s0; pixels]);
        for t in 0..iterations {
            let n = rest / iterations + usize::from(t < rest % iterations);
            let alpha = self.weights(&stats);
            let a = self.allocate(&alpha, n, rng);
            let share = weights.population(t, &alpha, &a);
            let mut kernel = Vec::with_capacity(pixels);
            for (p, probe) in probes.iter().enumerate() {
                let sum = sample_pixel(probe, a.counts[p], &mut stats[p], rng);
                let sub = if self.combine == Combine::Pooled {
                    pooled_mean(sum, a.counts[p])
                } else if a.guaranteed[p] {
                    sum / a.counts[p] as f64
                } else {
                    trace.horvitz_thompson += 1;
                    sum / a.expected[p]
                };
                trace.estimate[p] += sub * share[p];
                kernel.push(a.expected[p] / n as f64);
            }
            trace.alpha.push(kernel);
            trace.counts.push(a.counts);
        }
        if self.combine == Combine::Pooled {
            // The weights were the realised counts: normalise by each pixel's total.
            for (e, m) in trace.estimate.iter_mut().zip(&stats) {
                *e = *e / m.count() as f64;
            }
        }
        trace
    }
}

/// `n` samples of one pixel at uniform footprint positions: their sum, with the luminance of
/// each recorded in `stats`.
fn sample_pixel(probe: &ImageProbe<'_>, n: usize, stats: &mut Moments, rng: &mut StreamRng) -> Rgb {
    let mut sum = Rgb::ZERO;
    for _ in 0..n {
        let (u, v): (f64, f64) = (rng.gen(), rng.gen());
        let x = probe.sample(u, v, rng);
        // The pixel value is the target the kernel adapts to (through its luminance statistics).
        probe.count_target_evals(1);
        stats.push(luminance(x));
        sum += x;
    }
    sum
}

/// The image-plane probes of a sequence of tasks under a sample budget, or why not.
pub fn image_probes<'a>(tasks: &'a [Task<'a>], id: &str) -> Result<(Vec<ImageProbe<'a>>, u64), EstimateError> {
    let Some(first) = tasks.first() else { return Ok((Vec::new(), 0)) };
    let budget = first.budget();
    if budget.kind != BudgetKind::Samples || tasks.iter().any(|t| t.budget() != budget) {
        return Err(EstimateError::Refused(format!("{id} needs the same sample budget (spp) for every pixel")));
    }
    let probes = tasks
        .iter()
        .map(|t| t.image_plane().ok_or_else(|| EstimateError::Refused(format!("{id} needs an image-plane scene"))))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((probes, budget.amount))
}

/// Normalised perplexity `exp(H(alpha)) / K` of weights summing to 1.
pub fn normalised_perplexity(alpha: &[f64]) -> f64 {
    let h: f64 = alpha.iter().filter(|&&a| a > 0.0).map(|&a| -a * a.ln()).sum();
    h.exp() / alpha.len().max(1) as f64
}

impl Estimator for PmcIp {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        Ok(self.estimate_sequence(std::slice::from_ref(task), rng)?[0])
    }
    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        let (probes, spp) = image_probes(tasks, "pmc_ip")?;
        if probes.is_empty() {
            return Ok(Vec::new());
        }
        let trace = self.run(&probes, spp, rng);
        let iterations = trace.alpha.len();
        let perplexity = if iterations > 0 {
            trace.alpha.iter().map(|a| normalised_perplexity(a)).sum::<f64>() / iterations as f64
        } else {
            1.0
        };
        let ht = trace.horvitz_thompson as f64 / (iterations * probes.len()).max(1) as f64;
        for t in tasks {
            t.note("alpha_perplexity", perplexity);
            t.note("ht_share", ht);
        }
        Ok(trace.estimate)
    }
    /// `pooled` is declared biased (its weights are counts drawn from the earlier samples); every
    /// other combination keeps the entry's unbiased declaration.
    fn bias(&self) -> Option<mcbench_core::estimator::Bias> {
        (self.combine == Combine::Pooled).then_some(mcbench_core::estimator::Bias::Biased)
    }
}

#[cfg(test)]
#[path = "ip_options_tests.rs"]
mod options_tests;
#[cfg(test)]
#[path = "ip_tests.rs"]
mod tests;

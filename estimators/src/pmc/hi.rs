//! `pmc_hi` and `pmc_hi_feedback`: Population Monte Carlo for hemispheric integrals (paper 003
//! §5). Each iteration draws a population of `N = 2m` directions from the mixture kernel of
//! Eq. 7 by deterministic mixture sampling, weights each by `w = f / K` with the full mixture
//! (Eq. 8), and adapts: `alpha_k` = share of the population's weight drawn from component `k`
//! (Eq. 9), the cone's axis = weighted mean direction and its half-angle = weighted standard
//! deviation of the angles to it (§5.2). Iteration 0 has no cone and equal other weights;
//! `alpha_cone = 0.2` at iteration 1 (the rest scaled by 0.8). The estimate averages the weights
//! of all iterations (Eq. 1 over every sample).
//!
//! Departure from Eq. 9, needed for unbiasedness: the BRDF and light weights are mixed with a
//! defensive share `delta` (default 0.1, Hesterberg 1995) so that the BRDF component, whose cosine
//! part covers the whole hemisphere, never gets weight 0 (otherwise one unlucky population could
//! leave part of the integrand's support unsampled forever, a bias).
//!
//! `pmc_hi_feedback` (§6.1) runs the budget as `passes` image-plane iterations at the same pixel;
//! each pass after the first starts from the weights adapted by the previous one instead of the
//! default ones. All samples of all passes are averaged.

use super::kernel::{Cone, Kernel};
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::{check_count, check_range, parse, ParamSet, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::mixture::dms_counts;
use mcbench_core::task::{HemisphereProbe, Task};
use mcbench_core::testbed::Needs;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Registry entry of `pmc_hi`.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "pmc_hi",
    paper: "003",
    label: "PMC-HI",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE.and(Needs::AREA_LIGHTS),
    samplers: &["brdf", "rect_light", "cone", "mixture"],
    summary: "PMC for hemispheric integrals: BRDF + per-light + cone mixture adapted per population (Eq. 7-9)",
    build: |p| Ok(Box::new(PmcHi::from_params(&parse::<PmcHiParams>("pmc_hi", p)?))),
    params: ParamSpec::of::<PmcHiParams>().display("PMC-HI").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// Registry entry of `pmc_hi_feedback`.
pub static FEEDBACK: EstimatorEntry = EstimatorEntry {
    id: "pmc_hi_feedback",
    paper: "003",
    label: "PMC-HI + feedback",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE.and(Needs::AREA_LIGHTS),
    samplers: &["brdf", "rect_light", "cone", "mixture"],
    summary: "PMC-HI whose weights start from the previous image-plane pass (paper 003 §6.1)",
    build: |p| Ok(Box::new(PmcHi::from_params(&parse::<PmcHiFeedbackParams>("pmc_hi_feedback", p)?.into()))),
    params: ParamSpec::of::<PmcHiFeedbackParams>().display("PMC-HI with feedback").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The configured estimator.
#[derive(Clone, Debug)]
pub struct PmcHi {
    /// Population size per iteration (0: `2m`).
    pub population: usize,
    /// Defensive share of the BRDF and light components.
    pub delta: f64,
    /// Image-plane passes (1 for plain `pmc_hi`).
    pub passes: usize,
    /// Smallest cone half-angle (radians).
    pub min_beta: f64,
}

/// Parameters of `pmc_hi`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PmcHiParams {
    /// Directions per population (1 to 2^20; unset: `2m`, m the mixture's components: the BRDF,
    /// one per light and the cone).
    pub population: Option<usize>,
    /// Defensive share of the BRDF and light components (1e-6 to 1).
    pub delta: f64,
    /// Image-plane passes at the same pixel, each after the first starting from the weights the
    /// previous one adapted (1 to 64).
    pub passes: usize,
}

impl Default for PmcHiParams {
    fn default() -> Self {
        PmcHiParams { population: None, delta: 0.1, passes: 1 }
    }
}

impl ParamSet for PmcHiParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        if let Some(n) = self.population {
            check_count("population", n, 1 << 20)?;
        }
        check_range("delta", self.delta, 1e-6, 1.0)?;
        check_count("passes", self.passes, 64)?;
        Ok(())
    }
}

/// Parameters of `pmc_hi_feedback`: those of `pmc_hi`, two passes by default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PmcHiFeedbackParams {
    /// Directions per population (1 to 2^20; unset: `2m`, m the mixture's components: the BRDF,
    /// one per light and the cone).
    pub population: Option<usize>,
    /// Defensive share of the BRDF and light components (1e-6 to 1).
    pub delta: f64,
    /// Image-plane passes at the same pixel, each after the first starting from the weights the
    /// previous one adapted (1 to 64).
    pub passes: usize,
}

impl Default for PmcHiFeedbackParams {
    fn default() -> Self {
        PmcHiFeedbackParams { passes: 2, ..PmcHiParams::default().into() }
    }
}

impl From<PmcHiParams> for PmcHiFeedbackParams {
    fn from(p: PmcHiParams) -> Self {
        PmcHiFeedbackParams { population: p.population, delta: p.delta, passes: p.passes }
    }
}

impl From<PmcHiFeedbackParams> for PmcHiParams {
    fn from(p: PmcHiFeedbackParams) -> Self {
        PmcHiParams { population: p.population, delta: p.delta, passes: p.passes }
    }
}

impl ParamSet for PmcHiFeedbackParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        PmcHiParams::from(self.clone()).validate(owner)
    }
}

impl PmcHi {
    /// Builds from its parameters.
    pub fn from_params(p: &PmcHiParams) -> Self {
        PmcHi { population: p.population.unwrap_or(0), delta: p.delta, passes: p.passes, min_beta: 0.02 }
    }
}

/// What one run of PMC-HI leaves behind (for feedback and diagnostics).
#[derive(Clone, Debug, Default)]
pub struct Adapted {
    /// Final weights.
    pub alpha: Vec<f64>,
    /// Final cone.
    pub cone: Option<Cone>,
}

/// Running sums of one estimate.
struct Sums {
    sum: Rgb,
    n: u64,
    perplexity: f64,
    ess: f64,
    populations: u64,
}

impl PmcHi {
    /// Default initial weights: no cone, the others equal.
    fn initial(m: usize) -> Vec<f64> {
        let mut a = vec![1.0 / (m - 1) as f64; m];
        a[m - 1] = 0.0;
        a
    }

    /// One PMC-HI run of up to `budget` samples starting from `start`.
    fn run(
        &self,
        probe: &HemisphereProbe<'_>,
        task: &Task<'_>,
        start: &Adapted,
        budget: u64,
        s: &mut Sums,
        rng: &mut StreamRng,
    ) -> Adapted {
        let point = *probe.point();
        let lights = probe.lights();
        let m = lights.len() + 2;
        let n_pop = if self.population > 0 { self.population } else { 2 * m };
        let mut kernel = Kernel::new(&point, lights, start.alpha.clone(), start.cone);
        if kernel.cone.is_none() {
            kernel.alpha[m - 1] = 0.0;
        }
        let mut spent = 0u64;
        let mut iteration = 0usize;
        while spent < budget && task.more() {
            let size = n_pop.min((budget - spent) as usize);
            let counts = dms_counts(&kernel.alpha, size, rng);
            let mut pop: Vec<(usize, Vec3, f64)> = Vec::with_capacity(size);
            for (k, &c) in counts.iter().enumerate() {
                for _ in 0..c {
                    let w = kernel.sample(k, rng);
                    let pdf = kernel.pdf(w);
                    let f = probe.integrand(w);
                    // The target of the population's weight f / K (Eq. 8) and of the adaptation.
                    task.count_target_evals(1);
                    spent += 1;
                    // K > 0 at every sample drawn from a component with alpha_k > 0, except on a
                    // null set (a lobe sample exactly at the lobe's edge); there f/K := 0.
                    let weight = if pdf > 0.0 { f / pdf } else { Rgb::ZERO };
                    s.sum += weight;
                    s.n += 1;
                    pop.push((k, w, weight.mean().max(0.0)));
                }
            }
            self.diagnose(&pop, s);
            self.adapt(&mut kernel, &pop, iteration == 0 && start.cone.is_none());
            iteration += 1;
        }
        Adapted { alpha: kernel.alpha, cone: kernel.cone }
    }

    /// Normalised perplexity `exp(H) / N` and normalised ESS `(sum w)^2 / (N sum w^2)`.
    fn diagnose(&self, pop: &[(usize, Vec3, f64)], s: &mut Sums) {
        let total: f64 = pop.iter().map(|p| p.2).sum();
        if total <= 0.0 || pop.is_empty() {
            return;
        }
        let n = pop.len() as f64;
        let h: f64 = pop.iter().map(|p| p.2 / total).filter(|&q| q > 0.0).map(|q| -q * q.ln()).sum();
        let sq: f64 = pop.iter().map(|p| p.2 * p.2).sum();
        s.perplexity += h.exp() / n;
        s.ess += total * total / (n * sq);
        s.populations += 1;
    }

    /// Eq. 9 with the defensive share, and the cone from the population (§5.2).
    fn adapt(&self, k: &mut Kernel<'_>, pop: &[(usize, Vec3, f64)], first: bool) {
        let m = k.components();
        let total: f64 = pop.iter().map(|p| p.2).sum();
        if !(total > 0.0 && total.is_finite()) {
            return; // nothing learnt (e.g. a fully shadowed point): keep the kernel
        }
        let mut share = vec![0.0; m];
        for &(c, _, w) in pop {
            share[c] += w / total;
        }
        let mean = pop.iter().fold(Vec3::default(), |a, p| a + p.1 * p.2);
        let axis = mean.normalize();
        let var: f64 = pop.iter().map(|p| p.2 / total * p.1.dot(axis).clamp(-1.0, 1.0).acos().powi(2)).sum();
        let beta = var.sqrt().clamp(self.min_beta, std::f64::consts::FRAC_PI_2);
        k.cone = axis.x.is_finite().then_some(Cone { axis, cos_max: beta.cos() });
        let cone_weight = if k.cone.is_none() {
            0.0
        } else if first {
            0.2
        } else {
            share[m - 1].min(1.0 - self.delta)
        };
        let rest: f64 = share[..m - 1].iter().sum();
        let defensive = self.delta / (m - 1) as f64;
        for (a, s) in k.alpha.iter_mut().zip(&share).take(m - 1) {
            let eq9 = if rest > 0.0 { s / rest } else { 1.0 / (m - 1) as f64 };
            *a = (1.0 - cone_weight) * ((1.0 - self.delta) * eq9 + defensive);
        }
        k.alpha[m - 1] = cone_weight;
    }
}

impl Estimator for PmcHi {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.hemisphere().ok_or_else(|| EstimateError::Refused("pmc_hi needs a surface".into()))?;
        let m = probe.lights().len() + 2;
        let mut s = Sums { sum: Rgb::ZERO, n: 0, perplexity: 0.0, ess: 0.0, populations: 0 };
        let budget = task.budget().amount;
        let mut state = Adapted { alpha: Self::initial(m), cone: None };
        let mut last = state.clone();
        for pass in 0..self.passes {
            let share = budget / self.passes as u64 + u64::from((pass as u64) < budget % self.passes as u64);
            last = self.run(&probe, task, &state, share.max(1), &mut s, rng);
            // Feedback (§6.1): the next pass starts from these weights; the cone needs a
            // population of its own, so it restarts empty.
            let mut alpha = last.alpha.clone();
            let cone = alpha[m - 1];
            alpha[m - 1] = 0.0;
            alpha.iter_mut().for_each(|a| *a /= 1.0 - cone);
            state = Adapted { alpha, cone: None };
        }
        // The adapted weights of the last kernel, cone included (paper 003 Fig. 7's maps).
        let names = ["alpha_brdf", "alpha_light0", "alpha_light1"];
        for (k, name) in names.iter().enumerate().take(m - 1) {
            task.note(name, last.alpha[k]);
        }
        task.note("alpha_cone", last.alpha[m - 1]);
        if s.populations > 0 {
            task.note("perplexity", s.perplexity / s.populations as f64);
            task.note("ess", s.ess / s.populations as f64);
        }
        Ok(if s.n > 0 { s.sum / s.n as f64 } else { Rgb::ZERO })
    }
    fn supports(&self, bed: &dyn mcbench_core::testbed::TestBed) -> Result<(), String> {
        match bed.hemisphere() {
            Some(h) if !h.lights().is_empty() => Ok(()),
            _ => Err("pmc_hi needs a scene with area lights".into()),
        }
    }
}

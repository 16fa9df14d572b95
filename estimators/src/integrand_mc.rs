//! Estimators of any generic integrand ([`mcbench_core::integrand`]): they only sample the
//! domain and evaluate `f`, so they run on every test bed that provides
//! [`Needs::INTEGRAND`], a researcher's included.
//!
//! - `integrand_mc`: plain Monte Carlo, `measure x mean f(x_k)` over points of density
//!   `1 / measure`;
//! - `integrand_antithetic`: the same in antithetic pairs (each point followed by its image
//!   under the domain's measure-keeping reflection, [`mcbench_core::Domain::reflect`]): every
//!   point is distributed like a plain one, so the mean stays unbiased whatever the budget;
//! - `integrand_clamped_mc`: a biased control, plain Monte Carlo with each contribution clamped
//!   at `clamp` times the mean of all the estimate's contributions (a firefly clamp relative to
//!   the estimate): never above the plain mean, and below it whenever one contribution exceeds
//!   that ceiling, so biased low on every integrand whose values spread that far.

use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{check_range, parse, NoParams, ParamSet, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::{IntegrandProbe, Task};
use mcbench_core::testbed::Needs;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The samplers the domains draw from (the cube's coordinates are plain uniforms).
const SAMPLERS: &[&str] = &["uniform_hemisphere", "cosine_hemisphere"];

/// Registry entry of plain Monte Carlo.
pub static MC: EstimatorEntry = EstimatorEntry {
    id: "integrand_mc",
    paper: "harness",
    label: "plain MC",
    bias: Bias::Unbiased,
    needs: Needs::INTEGRAND,
    samplers: SAMPLERS,
    summary: "plain Monte Carlo of a generic integrand: points of density 1/measure, measure x mean f",
    build: |p| {
        parse::<NoParams>("integrand_mc", p)?;
        Ok(Box::new(Plain { clamp: None }))
    },
    params: ParamSpec::NONE.display("plain MC").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// Registry entry of antithetic Monte Carlo.
pub static ANTITHETIC: EstimatorEntry = EstimatorEntry {
    id: "integrand_antithetic",
    paper: "harness",
    label: "antithetic MC",
    bias: Bias::Unbiased,
    needs: Needs::INTEGRAND,
    samplers: SAMPLERS,
    summary: "antithetic pairs of a generic integrand: each point and its reflection (1 - x, -w)",
    build: |p| {
        parse::<NoParams>("integrand_antithetic", p)?;
        Ok(Box::new(Antithetic))
    },
    params: ParamSpec::NONE.display("antithetic MC").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// Registry entry of the clamped control.
pub static CLAMPED: EstimatorEntry = EstimatorEntry {
    id: "integrand_clamped_mc",
    paper: "harness",
    label: "clamped MC (biased control)",
    bias: Bias::Biased,
    needs: Needs::INTEGRAND,
    samplers: SAMPLERS,
    summary: "biased control: plain MC with each contribution clamped at `clamp` x the estimate's mean (default 1.25)",
    build: |p| Ok(Box::new(Plain { clamp: Some(parse::<ClampParams>("integrand_clamped_mc", p)?.clamp) })),
    params: ParamSpec::of::<ClampParams>().display("clamped MC (biased control)").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// Parameters of `integrand_clamped_mc`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ClampParams {
    /// Ceiling of one contribution as a multiple of the mean of all contributions (1 to 1000).
    pub clamp: f64,
}

impl Default for ClampParams {
    fn default() -> Self {
        ClampParams { clamp: 1.25 }
    }
}

impl ParamSet for ClampParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        check_range(&format!("{owner}.clamp"), self.clamp, 1.0, 1000.0).map(|_| ())
    }
}

fn probe<'a>(task: &'a Task<'a>) -> Result<IntegrandProbe<'a>, EstimateError> {
    task.integrand().ok_or_else(|| EstimateError::Refused("needs a generic integrand".into()))
}

/// Plain Monte Carlo, with the relative clamp of the control when `clamp` is set.
pub struct Plain {
    /// The control's ceiling relative to the estimate's plain mean.
    pub clamp: Option<f64>,
}

impl Estimator for Plain {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let f = probe(task)?;
        let domain = f.domain();
        let mut x = vec![0.0; domain.dim()];
        let (mut sum, mut n, mut kept) = (0.0, 0u64, Vec::new());
        while task.more() {
            domain.sample(rng, &mut x);
            let v = domain.measure() * f.eval(&x);
            if self.clamp.is_some() {
                kept.push(v);
            }
            sum += v;
            n += 1;
        }
        let mean = sum / n.max(1) as f64;
        Ok(Rgb([match self.clamp {
            Some(k) => kept.iter().map(|v| v.min(k * mean.abs())).sum::<f64>() / n.max(1) as f64,
            None => mean,
        }; 3]))
    }
}

/// Antithetic pairs.
pub struct Antithetic;

impl Estimator for Antithetic {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let f = probe(task)?;
        let domain = f.domain();
        let mut x = vec![0.0; domain.dim()];
        let (mut sum, mut n) = (0.0, 0u64);
        while task.more() {
            if n % 2 == 0 {
                domain.sample(rng, &mut x);
            } else {
                domain.reflect(&mut x);
            }
            sum += domain.measure() * f.eval(&x);
            n += 1;
        }
        Ok(Rgb([sum / n.max(1) as f64; 3]))
    }
}

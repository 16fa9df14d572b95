//! `uniform`: independent uniform sampling of the hemisphere, the sweep's baseline; and
//! `clamped_uniform`, the same with every sample clamped at `clamp`, a biased control the sweep's
//! unbiasedness tests must flag. Both come with the crate, so it needs no estimator of the papers.

use mcbench::{Bias, Checks, ConfigError, EstimateError, Estimator, EstimatorEntry, Needs, Rgb, StreamRng, Task};
use mcbench_core::math::Frame;
use mcbench_core::params::{check_range, parse, NoParams, ParamSet, ParamSpec, Params};
use mcbench_core::samplers::uniform_hemisphere;
use serde::{Deserialize, Serialize};

/// The baseline's registry entry.
pub static UNIFORM: EstimatorEntry = EstimatorEntry {
    id: "uniform",
    paper: "example",
    label: "uniform hemisphere sampling",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    samplers: &["uniform_hemisphere"],
    summary: "independent uniform sampling of the hemisphere",
    build: |params| {
        parse::<NoParams>(UNIFORM.id, params)?;
        Ok(Box::new(Uniform { clamp: f64::INFINITY }))
    },
    checks: Checks::DEFAULT,
    params: ParamSpec::NONE,
};

/// Parameters of `clamped_uniform`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ClampParams {
    /// Largest value a sample may contribute, per channel (0.001 to 1000).
    pub clamp: f64,
}

impl Default for ClampParams {
    fn default() -> Self {
        ClampParams { clamp: 1.0 }
    }
}

impl ParamSet for ClampParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_range("clamp", self.clamp, 0.001, 1000.0).map(|_| ())
    }
}

/// The biased control's registry entry.
pub static CLAMPED: EstimatorEntry = EstimatorEntry {
    id: "clamped_uniform",
    paper: "example",
    label: "uniform hemisphere sampling, clamped",
    bias: Bias::Biased,
    needs: Needs::SURFACE,
    samplers: &["uniform_hemisphere"],
    summary: "uniform hemisphere sampling with every sample clamped (a biased control)",
    build: build_clamped,
    checks: Checks::DEFAULT,
    params: ParamSpec::of::<ClampParams>(),
};

fn build_clamped(params: &Params) -> Result<Box<dyn Estimator>, ConfigError> {
    let p: ClampParams = parse(CLAMPED.id, params)?;
    Ok(Box::new(Uniform { clamp: p.clamp }))
}

/// The estimator: the mean of `min(f / p, clamp)` (no clamp: `clamp` infinite).
pub struct Uniform {
    clamp: f64,
}

impl Estimator for Uniform {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.hemisphere().ok_or_else(|| EstimateError::Refused("needs a surface".into()))?;
        let frame = Frame::around(probe.point().normal);
        let (mut sum, mut n) = (Rgb::ZERO, 0u64);
        while task.more() {
            let wi = frame.to_world(uniform_hemisphere::sample_local(rng));
            let Rgb(v) = probe.integrand(wi) / uniform_hemisphere::pdf(1.0);
            sum += Rgb(v.map(|c| c.min(self.clamp)));
            n += 1;
        }
        Ok(sum / n.max(1) as f64)
    }
}

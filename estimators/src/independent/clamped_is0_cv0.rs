//! `clamped_is0_cv0`: a deliberately biased control. Uniform hemisphere sampling with every
//! sample's contribution `f / p` clamped per channel at `clamp` (a "firefly clamp"). Its only
//! purpose is to prove that the unbiasedness test can fail: every run of the suite must flag it.

use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSet, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::uniform_hemisphere;
use mcbench_core::task::Task;
use mcbench_core::testbed::Needs;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "clamped_is0_cv0",
    paper: "harness",
    label: "clamped independent MC (biased control)",
    bias: Bias::Biased,
    needs: Needs::SURFACE,
    samplers: &["uniform_hemisphere"],
    summary: "biased control: is0_cv0 with each sample clamped at `clamp` (default 2)",
    build: |p| Ok(Box::new(ClampedIs0Cv0 { clamp: parse::<ClampedParams>("clamped_is0_cv0", p)?.clamp })),
    params: ParamSpec::of::<ClampedParams>()
        .display("clamped independent MC (biased control)")
        .words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// Parameters of `clamped_is0_cv0`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ClampedParams {
    /// Per-channel ceiling of one sample's contribution `f / p` (> 0).
    pub clamp: f64,
}

impl Default for ClampedParams {
    fn default() -> Self {
        ClampedParams { clamp: 2.0 }
    }
}

impl ParamSet for ClampedParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        if self.clamp <= 0.0 {
            return Err(ConfigError::invalid(format!("{owner}.clamp"), self.clamp, "must be > 0"));
        }
        Ok(())
    }
}

/// The estimator.
pub struct ClampedIs0Cv0 {
    /// Per-channel ceiling of one sample's contribution.
    pub clamp: f64,
}

impl Estimator for ClampedIs0Cv0 {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        super::average(task, rng, |probe, frame, rng| {
            let local = uniform_hemisphere::sample_local(rng);
            (probe.integrand(frame.to_world(local)) / uniform_hemisphere::pdf(local.z)).map(|c| c.min(self.clamp))
        })
    }
}

//! `clamped_is0_cv0`: a deliberately biased control. Uniform hemisphere sampling with every
//! sample's contribution `f / p` clamped per channel at `clamp` (a "firefly clamp"). Its only
//! purpose is to prove that the unbiasedness test can fail (SPEC §6 "Teeth").

use crate::error::EstimateError;
use crate::estimator::{Bias, Estimator};
use crate::math::Rgb;
use crate::registry::{Checks, EstimatorEntry};
use crate::rng::StreamRng;
use crate::samplers::uniform_hemisphere;
use crate::task::Task;
use crate::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "clamped_is0_cv0",
    paper: "harness",
    label: "clamped independent MC (biased control)",
    bias: Bias::Biased,
    needs: Needs::SURFACE,
    samplers: &["uniform_hemisphere"],
    summary: "biased control: is0_cv0 with each sample clamped at `clamp` (default 2)",
    build: |p| {
        p.reject_unknown("clamped_is0_cv0", &["clamp"])?;
        let clamp = p.f64("clamp", 2.0)?;
        if clamp <= 0.0 {
            return Err(crate::error::ConfigError::invalid("clamped_is0_cv0.clamp", clamp, "must be > 0"));
        }
        Ok(Box::new(ClampedIs0Cv0 { clamp }))
    },
    checks: Checks::DEFAULT,
};

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

//! The estimator plug-in trait (book: extending.md).

use crate::error::EstimateError;
use crate::math::Rgb;
use crate::rng::StreamRng;
use crate::task::Task;
use crate::testbed::TestBed;
use serde::{Deserialize, Serialize};

/// What the papers claim of an estimator's expectation (and what the harness then tests).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Bias {
    /// Expectation equals the integral at every budget.
    Unbiased,
    /// Only consistent (self-normalised ratios, exponentiated log estimates).
    Consistent,
    /// Biased by construction (controls such as ray marching or clamping).
    Biased,
}

impl Bias {
    /// The name used in tables.
    pub fn name(self) -> &'static str {
        match self {
            Bias::Unbiased => "unbiased",
            Bias::Consistent => "consistent",
            Bias::Biased => "biased",
        }
    }
}

/// An estimator: given a [`Task`] (one integral, one budget, counted access to the scene) and its
/// own random stream, return an estimate. Adaptive state lives inside one call.
///
/// A minimal estimator, the independent uniform-hemisphere average:
/// ```
/// use estimators::{estimator::Estimator, error::EstimateError, math::{Frame, Rgb}, rng::StreamRng,
///                  samplers::uniform_hemisphere, task::Task};
///
/// struct Uniform;
/// impl Estimator for Uniform {
///     fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
///         let probe = task.hemisphere().ok_or(EstimateError::Refused("needs a surface".into()))?;
///         let frame = Frame::around(probe.point().normal);
///         let (mut sum, mut n) = (Rgb::ZERO, 0.0);
///         while task.more() {
///             let wi = frame.to_world(uniform_hemisphere::sample_local(rng));
///             sum += probe.integrand(wi) / uniform_hemisphere::pdf(1.0);
///             n += 1.0;
///         }
///         Ok(sum / n)
///     }
/// }
/// ```
pub trait Estimator: Send + Sync {
    /// One estimate of `task.integral()` spending `task.budget()` (loop while `task.more()`).
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError>;

    /// Estimates of a whole sequence of integrals (the frames of one pixel, see
    /// [`TestBed::sequence_length`]), in order, from one random stream: estimators that carry state
    /// from frame to frame (paper 004's SMC) override this. Each task still counts its own costs.
    /// The default estimates each task independently with [`Estimator::estimate`].
    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        tasks.iter().map(|t| self.estimate(t, rng)).collect()
    }

    /// Whether the estimates of one sequence's integrals are independent of each other: no state
    /// (an adaptive structure, a sample allocation, particles) carried from one task to the next,
    /// as with the default [`Estimator::estimate_sequence`]. The unbiasedness tests then count
    /// each integral's test as an independent chance of finding a bias spread over the image
    /// (integrals of different sequences always are: each sequence has its own stream). The
    /// default, `false`, treats a sequence as one chance, which is never wrong, only less powerful.
    fn integrals_independent(&self) -> bool {
        false
    }

    /// Whether this configured estimator can run on `bed` beyond the static needs of its registry
    /// entry; `Err(reason)` makes the harness skip the pair and report the reason.
    fn supports(&self, _bed: &dyn TestBed) -> Result<(), String> {
        Ok(())
    }

    /// The exact moments of one sample (channel 0) of this configured estimator on `task`'s
    /// integral under `task`'s budget, where a theory gives them (paper 002 §3.4 for the
    /// transmittance trackers, see [`crate::media::moments`]); `None` (the default) otherwise. An
    /// estimate averaging `n` independent samples has the moments `mean_of(n)` of these.
    fn sample_moments(&self, _task: &Task<'_>) -> Option<crate::media::moments::EstimateMoments> {
        None
    }

    /// Whether this configuration is *valid* on `bed` (e.g. a terminating particle model whose
    /// sampling density makes `r > 2/(a+1)` somewhere): an error here is bad input (exit 2), not a
    /// skipped pair, because the user asked for something that cannot be computed.
    fn validate(&self, _bed: &dyn TestBed) -> Result<(), crate::error::ConfigError> {
        Ok(())
    }
}

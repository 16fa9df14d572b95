//! Paper 004 (Ghosh, Doucet and Heidrich 2006): sequential Monte Carlo sampling of the product of
//! a dynamic environment map and the BRDF (book: testbeds.md).
//!
//! - [`resampling`]: multinomial, residual, stratified and systematic resampling; ESS in log space;
//! - [`mh`]: the Metropolis-Hastings mixture kernel of Eq. 6-8;
//! - [`engine`]: bidirectional importance sampling, Algorithm 1 and Algorithm 2 in log space;
//! - [`drift`]: when the carried `L_ns` is estimated afresh (a fixed schedule, or the drift rule);
//! - the estimators: [`bidirectional_is`], [`bidirectional_is_sn`] (biased control), [`smc`],
//!   [`smc_bridge`], [`smc_path`], [`smc_adaptive`], and their parameters ([`params`]).
//!
//! Every estimator takes a sample budget N (particles per pixel and frame) and runs whole pixel
//! sequences through [`mcbench_core::estimator::Estimator::estimate_sequence`].

pub mod bidirectional_is;
pub mod bidirectional_is_sn;
pub mod drift;
pub mod engine;
pub mod mh;
pub mod params;
pub mod resampling;
#[allow(clippy::module_inception)] // the estimator id of paper 004 Algorithm 1 is `smc`
pub mod smc;
pub mod smc_adaptive;
pub mod smc_bridge;
pub mod smc_path;
#[cfg(test)]
mod tests;

use engine::Config;
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::Estimator;
use mcbench_core::math::Rgb;
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;

/// A configured paper 004 estimator.
pub struct SmcEstimator(pub Config);

impl Estimator for SmcEstimator {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        // A lone frame: the sequence of one.
        Ok(engine::run_sequence(&self.0, std::slice::from_ref(task), rng)?[0])
    }
    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        engine::run_sequence(&self.0, tasks, rng)
    }
    /// `L_ns` estimated afresh (every `recompute` frames, or by the drift rule of [`drift`], which
    /// decides from the carried estimate) makes the estimate a self-normalised mean times an
    /// independent normaliser: consistent, not unbiased. Without either the entry's declaration
    /// stands.
    fn bias(&self) -> Option<mcbench_core::estimator::Bias> {
        (self.0.drift > 0.0 || self.0.recompute > 0).then_some(mcbench_core::estimator::Bias::Consistent)
    }
}

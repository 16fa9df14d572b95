//! Paper 004 (Ghosh, Doucet and Heidrich 2006): sequential Monte Carlo sampling of the product of
//! a dynamic environment map and the BRDF (SPEC §4.4).
//!
//! - [`resampling`]: multinomial, residual, stratified and systematic resampling; ESS in log space;
//! - [`mh`]: the Metropolis-Hastings mixture kernel of Eq. 6-8;
//! - [`engine`]: bidirectional importance sampling, Algorithm 1 and Algorithm 2 in log space;
//! - the estimators: [`bidirectional_is`], [`bidirectional_is_sn`] (biased control), [`smc`],
//!   [`smc_bridge`], [`smc_path`], [`smc_adaptive`].
//!
//! Every estimator takes a sample budget N (particles per pixel and frame) and runs whole pixel
//! sequences through [`crate::estimator::Estimator::estimate_sequence`].

pub mod bidirectional_is;
pub mod bidirectional_is_sn;
pub mod engine;
pub mod mh;
pub mod resampling;
#[allow(clippy::module_inception)] // the estimator id of paper 004 Algorithm 1 is `smc`
pub mod smc;
pub mod smc_adaptive;
pub mod smc_bridge;
pub mod smc_path;
#[cfg(test)]
mod tests;

use crate::error::ConfigError;
use crate::error::EstimateError;
use crate::estimator::Estimator;
use crate::math::Rgb;
use crate::params::Params;
use crate::rng::StreamRng;
use crate::task::Task;
use engine::{Config, Transition};
use mh::MhKernel;
use resampling::Scheme;

/// Parameters every paper 004 estimator accepts.
pub const COMMON: &[&str] = &["candidates", "cone", "p_independent", "resampling", "threshold"];

/// Reads the common parameters: `candidates` (M, default `m`), `cone` (local-move half-angle in
/// degrees, 3), `p_independent` (share of environment-map proposals, 0.5), `resampling` (0
/// multinomial, 1 residual, 2 stratified, 3 systematic: default), `threshold` (ESS share, 0.5).
pub fn config(
    params: &Params,
    owner: &str,
    extra: &[&str],
    m: usize,
    transition: Option<Transition>,
) -> Result<Config, ConfigError> {
    let known: Vec<&str> = COMMON.iter().chain(extra).copied().collect();
    params.reject_unknown(owner, &known)?;
    let candidates = params.count("candidates", m, 1 << 20)?;
    let cone = params.f64_in("cone", 3.0, 1e-3, 90.0)?;
    let p_independent = params.f64_in("p_independent", 0.5, 0.0, 1.0)?;
    let code = params.f64_in("resampling", 3.0, 0.0, 3.0)?;
    let scheme = Scheme::from_code(code as usize).filter(|_| code.fract() == 0.0).ok_or_else(|| {
        ConfigError::invalid(
            format!("{owner}.resampling"),
            code,
            "0 multinomial, 1 residual, 2 stratified, 3 systematic",
        )
    })?;
    let threshold = params.f64_in("threshold", 0.5, 0.0, 1.0)?;
    Ok(Config { candidates, kernel: MhKernel::new(cone, p_independent), scheme, threshold, transition })
}

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
}

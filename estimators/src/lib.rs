//! # estimators
//!
//! The papers' half of `mcbench`: the estimator families of the five papers with their biased
//! controls, and the test beds they run on, built on the plug-in API of `mcbench-core`.
//! [`builtins`] lists them all.
//!
//! No I/O, plotting or CLI lives here (that is the `mcbench` crate, in `harness/`).
#![warn(missing_docs)]

pub mod builtins;
pub mod cache;
pub mod independent;
pub mod media;
pub mod media_smc;
pub mod pmc;
#[cfg(test)]
mod repository;
pub mod single_scatter;
pub mod smc;
pub mod smc_surface;
pub mod testbeds;
pub mod tracking;

// The plug-in API's modules under their former paths, for the crates not yet moved to
// `mcbench-core`.
pub use mcbench_core::{
    accumulate, brdf, budget, envmap, error, estimator, lighting, math, memo, parallel, params, perception, phase,
    quadrature, references, rng, samplers, stats, task, testbed,
};
/// The registry entries and the built-in lists under their former path.
pub mod registry {
    pub use crate::builtins::*;
    pub use mcbench_core::entry::*;
}

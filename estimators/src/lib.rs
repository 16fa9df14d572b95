//! # estimators
//!
//! The library half of `mcbench`, a convergence-study harness for adaptive Monte Carlo rendering
//! estimators: the plug-in traits ([`testbed::TestBed`], [`estimator::Estimator`],
//! [`budget::Budget`]), the registries, the analytic test beds with their references, samplers,
//! the estimator families, and the small statistics the harness and the sampler tests share.
//!
//! No I/O, plotting or CLI lives here (that is the `mcbench` crate, in `harness/`).
#![warn(missing_docs)]

pub mod accumulate;
pub mod brdf;
pub mod budget;
pub mod cache;
pub mod envmap;
pub mod error;
pub mod estimator;
pub mod independent;
pub mod lighting;
pub mod math;
pub mod media;
pub mod media_smc;
pub mod memo;
pub mod parallel;
pub mod params;
pub mod perception;
pub mod phase;
pub mod pmc;
pub mod quadrature;
pub mod references;
pub mod registry;
pub mod rng;
pub mod samplers;
pub mod single_scatter;
pub mod smc;
pub mod smc_surface;
pub mod stats;
pub mod task;
pub mod testbed;
pub mod testbeds;
pub mod tracking;

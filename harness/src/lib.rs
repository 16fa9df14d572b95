//! # mcbench
//!
//! A convergence-study harness for Monte Carlo estimators. Plug in an estimator and a test bed (a
//! scene whose integrals have exact or stored reference values) and get budget sweeps over
//! repetitions run in parallel on reproducible streams, RMSE / efficiency / FoM against samples,
//! fetches and time, convergence-slope fits with intervals, unbiasedness tests with their power,
//! the result files of the book's contract chapter, log-log plots and a report, and a command line with config files,
//! resume, shards and merge.
//!
//! Pipeline: [`config`] -> [`plan`] -> [`runner`] -> [`metrics`] / [`analysis`] -> [`output`] /
//! [`plot`] / [`report`] / [`html`]; [`execute`] ties them together, [`cli`] is the command line,
//! [`shard`] and [`merge`] split a sweep over machines and join it again, [`conformance`] is the
//! check every plug-in goes through. Names are looked up in a [`Registry`], a value you build in
//! `main`.
//!
//! ## Quick start: your own estimator, from your own crate
//!
//! ```no_run
//! use mcbench::{Bias, Checks, EstimateError, Estimator, EstimatorEntry, Needs, ParamSpec, Registry, Rgb, StreamRng, Task};
//!
//! /// Independent uniform-hemisphere sampling of a surface integral.
//! struct Uniform;
//!
//! impl Estimator for Uniform {
//!     fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
//!         use mcbench::mcbench_core::{math::Frame, samplers::uniform_hemisphere};
//!         let probe = task.hemisphere().ok_or(EstimateError::Refused("needs a surface".into()))?;
//!         let frame = Frame::around(probe.point().normal);
//!         let (mut sum, mut n) = (Rgb::ZERO, 0.0);
//!         while task.more() {
//!             let wi = frame.to_world(uniform_hemisphere::sample_local(rng));
//!             sum += probe.integrand(wi) / uniform_hemisphere::pdf(1.0);
//!             n += 1.0;
//!         }
//!         Ok(sum / n)
//!     }
//! }
//!
//! static UNIFORM: EstimatorEntry = EstimatorEntry {
//!     id: "my_uniform",
//!     paper: "mine",
//!     label: "uniform hemisphere sampling",
//!     bias: Bias::Unbiased,
//!     needs: Needs::SURFACE,
//!     samplers: &["uniform_hemisphere"],
//!     summary: "independent uniform sampling of the hemisphere",
//!     build: |params| {
//!         mcbench_core::params::parse::<mcbench_core::params::NoParams>("my_uniform", params)?;
//!         Ok(Box::new(Uniform))
//!     },
//!     params: ParamSpec::NONE,
//!     checks: Checks::DEFAULT,
//! };
//!
//! fn main() {
//!     // The whole CLI (run, list, plot, shards, merge, conformance) over the papers' plug-ins
//!     // (crate `mcbench-papers`, for their test beds) and this one:
//!     // `cargo run -- run --config my-sweep.toml`.
//!     std::process::exit(mcbench::cli::main_with(Registry::new().with_catalog(mcbench_papers::catalog()).with_estimator(&UNIFORM)));
//! }
//! ```
#![warn(missing_docs)]

pub mod analysis;
mod budget_pilot;
pub mod calibration;
pub mod cell;
pub mod claim_check;
pub mod claim_spec;
pub mod claims;
pub mod cli;
pub mod config;
pub mod conformance;
pub mod console;
pub mod cost_model;
pub mod cputime;
pub mod declare;
pub mod error;
pub mod execute;
pub mod folder;
mod folder_lock;
pub mod guarded;
pub mod html;
pub mod integrals;
pub mod interleave;
pub mod limits;
pub mod listing;
mod made_dirs;
pub mod merge;
pub mod metrics;
pub mod output;
pub mod packed;
pub mod phases;
pub mod plan;
pub mod plot;
pub mod plugins;
pub mod progress;
pub mod references;
pub mod registry;
pub mod report;
pub mod resume;
pub mod rmse_band;
pub mod roundoff;
pub mod runner;
pub mod selection;
pub mod sensitivity;
pub mod shard;
pub mod store;
pub mod unbiasedness;
pub mod verdict;
pub mod wording;

/// The plug-in API (`mcbench-core`), for crates that depend on the harness alone.
pub use mcbench_core;
pub use mcbench_core::{
    BedCase, Bias, Budget, CaseRole, Catalog, Checks, ConfigError, EstimateError, Estimator, EstimatorEntry, Exemption,
    Needs, ParamSpec, Reference, Rgb, StreamRng, Task, TestBed, TestBedEntry,
};
pub use registry::{Experiment, Registry};

//! # mcbench
//!
//! A convergence-study harness for Monte Carlo estimators. Plug in an estimator and a test bed (a
//! scene whose integrals have exact or stored reference values) and get budget sweeps over
//! repetitions run in parallel on reproducible streams, RMSE / efficiency / FoM against samples,
//! fetches and time, convergence-slope fits with intervals, unbiasedness tests with their power,
//! the result files of the book's contract chapter, log-log plots and a report, and a command line with config files,
//! resume, shards and merge.
//!
//! Pipeline: [`config`] (a sweep from a config file or an experiment) -> [`plan`] (built test beds
//! and estimators, every bad name refused before anything is written) -> [`run`] (the cells of the
//! sweep, filled in parallel; [`run::execute`] ties the stages together) -> [`store`] (the cell
//! store and the results folder) -> [`analysis`] (metrics, fits, unbiasedness tests, claims) ->
//! [`output`] (result files, report, plots, HTML pages). [`cli`] is the command line; names are
//! looked up in a [`Registry`], a value you build in `main`.
//!
//! | folder | stage |
//! |---|---|
//! | [`config`] | sweeps, config files, experiments declared as TOML, claim specs, input bounds |
//! | [`plan`] | the plan of a sweep, the cost model, the budget pilot |
//! | [`run`] | runner, cells, interleaving, progress, CPU time and phases, resume, shards and merge |
//! | [`store`] | the cell store, packed cells, results folders and their lock, stored references |
//! | [`analysis`] | metrics, slope fits, unbiasedness tests, speed-ups, claim checks, RMSE bands |
//! | [`output`] | `summary.csv`/`summary.json`, `integrals.csv`, report, console, plots, HTML, listings |
//! | [`unbiasedness`], [`calibration`], [`sensitivity`], [`conformance`] | the built-in experiments and the plug-in check |
//! | [`compare`] | two runs compared: changes with intervals and verdicts, baselines |
//! | [`ingest`] | estimates another program wrote, read from files and analysed as a run |
//! | [`export`] | a built-in test bed written as another renderer's scene, with its reference image |
//! | [`registry`], [`plugins`], [`selection`] | names looked up, what a user's crate adds to built-in checks, the entries a run is limited to |
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
pub mod calibration;
pub mod cli;
pub mod compare;
pub mod config;
pub mod conformance;
pub mod error;
pub mod export;
pub mod ingest;
pub mod output;
pub mod plan;
pub mod plugins;
pub mod registry;
pub mod run;
pub mod selection;
pub mod sensitivity;
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

//! # experiments
//!
//! The `mcbench` harness: budget sweeps over (test bed x estimator x budget x repetitions) run in
//! parallel with reproducible streams, SPEC §5 metrics and slope fits, SPEC §6 tests, the SPEC §8
//! result files, plots and reports, and the named experiments of SPEC §7. Pipeline:
//! [`config`] -> [`plan`] -> [`runner`] -> [`metrics`] / [`analysis`] -> [`output`] / [`plot`] /
//! [`report`]; [`execute`] ties them together and [`cli`] is the binary's front; [`shard`] and [`merge`] split a
//! sweep over machines and join it again (SPEC §12).
#![warn(missing_docs)]

pub mod analysis;
pub mod cell;
pub mod cli;
pub mod config;
pub mod conformance;
pub mod console;
pub mod cputime;
pub mod error;
pub mod execute;
pub mod folder;
pub mod guarded;
pub mod limits;
pub mod merge;
pub mod metrics;
pub mod output;
pub mod plan;
pub mod plot;
pub mod progress;
pub mod report;
pub mod runner;
pub mod shard;
pub mod suite;

/// The README's code blocks, compiled and run as doc tests.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;

//! # mcbench-papers
//!
//! The estimators of five adaptive Monte Carlo rendering papers with their biased controls, and
//! the test beds they run on, as plug-ins of `mcbench-core`; [`builtins`] lists them all and hands
//! them to a harness registry as one [`mcbench_core::Catalog`] ([`catalog`]):
//! `mcbench::Registry::new().with_catalog(mcbench_papers::catalog())`.
//!
//! One module per family, named like the experiment that measures it: [`independent`] (the
//! baseline and the clamped control), [`surface_smc`] (paper 001's adaptive surface estimators
//! with [`cache`], their radiance cache), [`media_smc`] (paper 000 in a medium), [`tracking`] and
//! [`single_scatter`] (paper 002's trackers with their moment theory, and its single-scattering
//! estimators), [`pmc`] (paper 003), [`envmap_smc`] (paper 004), [`integrand_mc`] (estimators of any generic integrand); and
//! [`testbeds`], the test beds with their references, and [`export`], two of them as Mitsuba 3 scenes.
//!
//! No I/O, plotting or CLI lives here (that is the `mcbench` crate, in `harness/`).
#![warn(missing_docs)]

pub mod built_in_references;
pub mod builtins;
pub mod cache;
pub mod envmap_smc;
pub mod export;
pub mod independent;
pub mod integrand_mc;
pub mod media_smc;
pub mod pmc;
pub mod single_scatter;
pub mod surface_smc;
pub mod testbeds;
pub mod tracking;
pub mod words;

pub use builtins::catalog;

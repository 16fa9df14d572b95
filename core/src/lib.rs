//! # mcbench-core
//!
//! The plug-in API of `mcbench`, a convergence-study harness for Monte Carlo estimators: what an
//! estimator or a test bed implements and how it is registered, and the small toolkit they share.
//!
//! - The plug-in traits: [`Estimator`] (with the [`EstimateMoments`] it may report), [`TestBed`]
//!   with its capability views ([`testbed::HemisphereScene`], [`testbed::MediumScene`],
//!   [`testbed::ImagePlaneScene`], [`testbed::EnvSequenceScene`]) and [`Needs`], the counted
//!   [`Task`] an estimate runs in and its [`Costs`].
//! - Registration: the entries [`EstimatorEntry`] and [`TestBedEntry`] (with [`Checks`],
//!   [`BedCase`], [`Exemption`]) and a [`Catalog`] of them, which a crate of plug-ins hands to the
//!   harness (`mcbench`) without depending on it.
//! - Inputs: [`Budget`], typed parameters ([`params`]), reproducible random streams ([`rng`]),
//!   references and where stored ones are found ([`references`]), errors ([`error`]).
//! - The toolkit: [`math`], [`stats`], [`samplers`] (with their registry and chi-square checks),
//!   [`quadrature`], and the scene vocabulary the traits speak: BRDFs ([`brdf`]), lights
//!   ([`lighting`]), phase functions ([`phase`]), environment maps ([`envmap`]), perception
//!   ([`perception`]), compensated accumulation ([`accumulate`]), a process-wide memo ([`memo`])
//!   and the parallel map of reference builders ([`parallel`]).
//! - Exported scenes: a test bed as another renderer's scene files ([`export`]).
//!
//! No estimator of a paper, no I/O, plotting or CLI lives here: the papers' estimators and test
//! beds are the `mcbench-papers` crate, the harness is `mcbench`.
#![warn(missing_docs)]

pub mod accumulate;
pub mod brdf;
pub mod budget;
pub mod catalog;
pub mod entry;
pub mod envmap;
pub mod error;
pub mod estimator;
pub mod export;
pub mod integrand;
pub mod integrand_bed;
pub mod lighting;
pub mod math;
pub mod memo;
pub mod needs;
pub mod parallel;
pub mod params;
pub mod perception;
pub mod phase;
pub mod phong_at;
pub mod quadrature;
pub mod references;
pub mod rng;
pub mod samplers;
pub mod stats;
pub mod task;
pub mod testbed;

pub use budget::{Budget, BudgetKind};
pub use catalog::Catalog;
pub use entry::{
    BedCase, BuildEstimator, BuildTestBed, CaseRole, Checks, ComputeReference, EstimatorEntry, Exemption, TestBedEntry,
};
pub use error::{ConfigError, EstimateError};
pub use estimator::{Bias, EstimateMoments, Estimator};
pub use integrand::{Domain, Integrand};
pub use integrand_bed::IntegrandBed;
pub use math::{Frame, Rgb, Vec3};
pub use params::{NoParams, ParamSet, ParamSpec, ParamWords, Params};
pub use references::{ReferenceKey, ReferenceSource, StoredReference};
pub use rng::StreamRng;
pub use samplers::registry::SamplerEntry;
pub use task::{Costs, Task};
pub use testbed::{Needs, Reference, ReferenceKind, TestBed};

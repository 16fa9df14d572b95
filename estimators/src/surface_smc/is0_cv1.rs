//! `is0_cv1` (paper 001 Fig. 4): uniform hemisphere sampling, piecewise constant (order 0) cache
//! control variate; one adaptive cache per estimate (see [`super`]).

use super::params::CacheSmcParams;
use super::{build_surface_or_medium, Sampling};
use crate::cache::ControlVariate;
use crate::media_smc::Sampling as MediaSampling;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::estimator::Bias;
use mcbench_core::params::ParamSpec;
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "is0_cv1",
    paper: "001",
    label: "is0_cv1",
    bias: Bias::Unbiased,
    needs: Needs::NONE,
    samplers: &["uniform_hemisphere", "phase", "free_flight"],
    summary: "SMC cache: uniform sampling, piecewise-constant control variate (cv1); on a medium, the octree of spherical caches (paper 000)",
    build: |p| build_surface_or_medium("is0_cv1", (Sampling::Uniform, MediaSampling::Uniform), ControlVariate::Constant, p),
    params: ParamSpec::of::<CacheSmcParams>().display("IS0 CV1 (SMC cache)").words(crate::words::param),
    checks: Checks::DEFAULT,
};

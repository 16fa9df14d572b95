//! `is1_cv2` (paper 001 Fig. 4): cache PDF importance sampling with the bilinear control variate
//! (the paper's SMC method); one adaptive cache per estimate (see [`super`]).

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
    id: "is1_cv2",
    paper: "001",
    label: "is1_cv2",
    bias: Bias::Unbiased,
    needs: Needs::NONE,
    samplers: &["uniform_hemisphere", "phase", "free_flight"],
    summary: "SMC cache: cache-PDF importance sampling, bilinear control variate (the paper's SMC); on a medium, the octree of spherical caches (paper 000)",
    build: |p| build_surface_or_medium("is1_cv2", (Sampling::Cache, MediaSampling::Cache), ControlVariate::Bilinear, p),
    params: ParamSpec::of::<CacheSmcParams>().display("IS1 CV2 (SMC cache)").words(crate::words::param),
    checks: Checks::DEFAULT,
};

//! `is0_cv1` (paper 001 Fig. 4): uniform hemisphere sampling, piecewise constant (order 0) cache
//! control variate; one adaptive cache per estimate (see [`super`]).

use super::{Sampling, SmcSurface};
use crate::cache::ControlVariate;
use crate::estimator::Bias;
use crate::media_smc::{MediaSmc, Sampling as MediaSampling};
use crate::registry::{Checks, EstimatorEntry};
use crate::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "is0_cv1",
    paper: "001",
    label: "is0_cv1",
    bias: Bias::Unbiased,
    needs: Needs::NONE,
    samplers: &["uniform_hemisphere", "phase", "free_flight"],
    summary: "SMC cache: uniform sampling, piecewise-constant control variate (cv1); on a medium, the octree of spherical caches (paper 000)",
    build: |p| {
        crate::media_smc::SurfaceOrMedium::build(
            |p| SmcSurface::build("is0_cv1", Sampling::Uniform, ControlVariate::Constant, p),
            |p| Ok(Box::new(MediaSmc::from_params("is0_cv1", MediaSampling::Uniform, ControlVariate::Constant, p)?)),
            p,
        )
    },
    checks: Checks::DEFAULT,
};

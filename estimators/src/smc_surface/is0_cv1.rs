//! `is0_cv1` (paper 001 Fig. 4): uniform hemisphere sampling, piecewise constant (order 0) cache
//! control variate; one adaptive cache per estimate (see [`super`]).

use super::{Sampling, SmcSurface};
use crate::cache::ControlVariate;
use crate::estimator::Bias;
use crate::registry::EstimatorEntry;
use crate::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "is0_cv1",
    paper: "001",
    label: "is0_cv1",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    summary: "SMC surface cache: uniform sampling, piecewise-constant control variate (cv1)",
    build: |p| SmcSurface::build("is0_cv1", Sampling::Uniform, ControlVariate::Constant, p),
};

//! `is1_cv0` (paper 001 Fig. 4): cache PDF importance sampling, no control variate; one adaptive
//! cache per estimate (see [`super`]).

use super::{Sampling, SmcSurface};
use crate::cache::ControlVariate;
use crate::estimator::Bias;
use crate::registry::EstimatorEntry;
use crate::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "is1_cv0",
    paper: "001",
    label: "is1_cv0",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    summary: "SMC surface cache: cache-PDF importance sampling, no control variate",
    build: |p| SmcSurface::build("is1_cv0", Sampling::Cache, ControlVariate::None, p),
};

//! `is1_cv2` (paper 001 Fig. 4): cache PDF importance sampling with the bilinear control variate
//! (the paper's SMC method); one adaptive cache per estimate (see [`super`]).

use super::{Sampling, SmcSurface};
use crate::cache::ControlVariate;
use crate::estimator::Bias;
use crate::registry::EstimatorEntry;
use crate::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "is1_cv2",
    paper: "001",
    label: "is1_cv2",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    summary: "SMC surface cache: cache-PDF importance sampling, bilinear control variate (the paper's SMC)",
    build: |p| SmcSurface::build("is1_cv2", Sampling::Cache, ControlVariate::Bilinear, p),
};

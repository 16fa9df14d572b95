//! `brdf_is1_cv2` (paper 001 §4.5, Fig. 4 right): a per-pixel variance tracker chooses, sample by
//! sample, between BRDF importance sampling (`brdf_is0_cv0`) and the SMC estimator `is1_cv2`,
//! computing both estimates from the one sample drawn; the tracker's weights clamp the count at
//! the refinement criterion (see [`super::variance_tracker`]).

use super::params::SurfaceSmcParams;
use super::{Sampling, SmcSurface};
use crate::cache::ControlVariate;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::estimator::Bias;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "brdf_is1_cv2",
    paper: "001",
    label: "BRDF_is1_cv2",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    samplers: &["brdf"],
    summary: "variance tracker choosing BRDF importance sampling or is1_cv2 per sample",
    build: |p| {
        let p = parse::<SurfaceSmcParams>("brdf_is1_cv2", p)?;
        Ok(Box::new(SmcSurface::from_params(Sampling::BrdfTracked, ControlVariate::Bilinear, &p)))
    },
    params: ParamSpec::of::<SurfaceSmcParams>()
        .display("BRDF or IS1 CV2 by variance (SMC cache)")
        .words(crate::words::param),
    checks: Checks::DEFAULT,
};

//! `rm_is1_cv2`: the ray-marching variant of paper 000 (Eq. 8-9, §4.5) with the octree's
//! `is1_cv2` estimate of the in-scattered radiance at each scattering event; biased by
//! construction (the source term is taken at the far end of each step). Parameter `step`
//! (default 0.5, i.e. one optical depth in `gradient-box`) plus the SMC parameters.
//!
//! Deviation from §4.5, stated: the choice between transmission (`Omega_t`) and scattering
//! (`Omega_s`) is made with probabilities proportional to `kappa_t` and `kappa_s` instead of being
//! merged into the cache's partial-sum tree, and the transmission term carries no control variate;
//! the id exists as the biased control the unbiasedness tests must flag. The id is not
//! `ray_marching`, which feat/media uses for the transmittance tracker.

use super::params::RmIs1Cv2Params;
use super::{MediaSmc, Sampling};
use crate::cache::ControlVariate;
use mcbench_core::entry::{Checks, EstimatorEntry, Exemption};
use mcbench_core::estimator::Bias;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "rm_is1_cv2",
    paper: "000",
    label: "ray marching is1_cv2 (biased)",
    bias: Bias::Biased,
    needs: Needs::MEDIUM,
    samplers: &["uniform_hemisphere", "phase"],
    summary: "ray marching over the 4 pi + 1 domain (paper 000 Eq. 8-9) with the SMC octree; biased control",
    build: |p| {
        let p = parse::<RmIs1Cv2Params>("rm_is1_cv2", p)?;
        let est = MediaSmc::from_params(Sampling::Cache, ControlVariate::Bilinear, &p.octree());
        Ok(Box::new(est.ray_marching(p.step)))
    },
    params: ParamSpec::of::<RmIs1Cv2Params>().display("ray marching + IS1 CV2 (biased control)").words(crate::words::param),
    // A step of 4 (8 optical depths in the box, 4 to 8 steps across the spheres): at the default
    // 0.5 the bias on the spheres' `multiple` images is about 1%, below what their rows resolve.
    checks: Checks {
        params: &[("step", 4.0)],
        exempt: &[
            Exemption {
                testbed: "gradient-box",
                variants: &["albedo-0"],
                reason: "not a control here: homogeneous and non-scattering, the marched optical depth is exact",
            },
            Exemption {
                testbed: "gradient-box",
                variants: &["furnace"],
                reason: "not a control here: in the white furnace the in-scattered radiance is c0 everywhere, so taking it at the step's end is exact",
            },
        ],
    },
};

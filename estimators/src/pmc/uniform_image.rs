//! `uniform_image`: the baseline of paper 003 Table 1, "uniform image-plane sampling": every pixel
//! gets the budget's samples at independent uniform positions in its footprint, and the estimate
//! is their mean (Eq. 3 with `p = h_p`, the same per-sample sampler PMC-IP uses, so the two differ
//! only in where the samples go).

use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, NoParams, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;
use mcbench_core::testbed::Needs;
use rand::Rng;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "uniform_image",
    paper: "003",
    label: "Uniform",
    bias: Bias::Unbiased,
    needs: Needs::IMAGE_PLANE,
    samplers: &[],
    summary: "uniform image-plane sampling: spp samples at uniform positions in every pixel (Table 1 baseline)",
    build: |p| {
        parse::<NoParams>("uniform_image", p)?;
        Ok(Box::new(UniformImage))
    },
    params: ParamSpec::NONE.display("uniform image sampling").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
#[derive(Clone, Copy, Debug, Default)]
pub struct UniformImage;

impl Estimator for UniformImage {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task
            .image_plane()
            .ok_or_else(|| EstimateError::Refused("uniform_image needs an image-plane scene".into()))?;
        let (mut sum, mut n) = (Rgb::ZERO, 0u64);
        while task.more() {
            let (u, v): (f64, f64) = (rng.gen(), rng.gen());
            sum += probe.sample(u, v, rng);
            n += 1;
        }
        Ok(if n > 0 { sum / n as f64 } else { Rgb::ZERO })
    }
    /// Each pixel is estimated on its own by the default `estimate_sequence`.
    fn integrals_independent(&self) -> bool {
        true
    }
}

//! `brdf_is0_cv0`: BRDF importance sampling (paper 001 §4.5): the diffuse cosine lobe and the
//! Phong lobe as a mixture, weighted by the exact mixture pdf ([`mcbench_core::brdf::Phong::pdf`]).

use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, NoParams, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "brdf_is0_cv0",
    paper: "001",
    label: "BRDF_is0_cv0",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    samplers: &["brdf"],
    summary: "BRDF importance sampling (cosine + Phong lobe mixture), no control variate",
    build: |p| {
        parse::<NoParams>("brdf_is0_cv0", p)?;
        Ok(Box::new(BrdfIs0Cv0))
    },
    params: ParamSpec::NONE.display("BRDF sampling (IS0 CV0)").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator (no parameters).
pub struct BrdfIs0Cv0;

impl Estimator for BrdfIs0Cv0 {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        super::average(task, rng, |probe, _frame, rng| {
            // The BRDF's value and density at the drawn direction from one call (one power of
            // the lobe for both, as `Phong::sample` and the integrand would give them).
            let brdf = probe.brdf();
            let w = brdf.sample_direction(rng);
            let (f, pdf) = brdf.eval_pdf(w);
            // The mixture pdf is positive wherever the integrand is non-zero (the cosine lobe
            // covers the hemisphere when kd > 0, the Phong lobe covers its support when kd = 0);
            // a zero pdf can only come with a zero integrand, which contributes nothing.
            if pdf > 0.0 {
                probe.integrand_with_brdf(w, f) / pdf
            } else {
                probe.integrand_with_brdf(w, f) * 0.0
            }
        })
    }
}

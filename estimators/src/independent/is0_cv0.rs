//! `is0_cv0`: uniform hemisphere sampling without control variate, the independent-sample
//! baseline of papers 000/001 (their "MCMC"): `(1/N) sum 2 pi f(w_k)`.

use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, NoParams, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::uniform_hemisphere;
use mcbench_core::task::Task;
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "is0_cv0",
    paper: "001",
    label: "MCMC (independent MC)",
    bias: Bias::Unbiased,
    needs: Needs::NONE,
    samplers: &["uniform_hemisphere", "phase", "free_flight"],
    summary: "independent MC baseline: uniform hemisphere sampling; on a medium, the path tracer (free flights, phase sampling)",
    build: |p| {
        parse::<NoParams>("is0_cv0", p)?;
        Ok(Box::new(crate::media_smc::SurfaceOrMedium {
            surface: Box::new(Is0Cv0),
            medium: Box::new(crate::media_smc::PathTracer),
        }))
    },
    params: ParamSpec::NONE.display("independent MC (papers' MCMC)").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator (no parameters).
pub struct Is0Cv0;

impl Estimator for Is0Cv0 {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        super::average(task, rng, |probe, frame, rng| {
            let local = uniform_hemisphere::sample_local(rng);
            probe.integrand(frame.to_world(local)) / uniform_hemisphere::pdf(local.z)
        })
    }
}

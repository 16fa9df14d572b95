//! `source_driven` (paper 002 §4.3, \[KF12\]): per primary ray, `points` scattering points
//! (default one) from the equiangular (Cauchy) density mimicking `1 / (D^2 + (t - t_l)^2)`
//! ([`mcbench_core::samplers::equiangular`]), drawn before the primary ray is tracked; the integrand at
//! each by the continuous transmittance and a residual-ratio-tracking shadow ray
//! ([`super::points`]); estimate `(1/n) sum f(t_i) / p(t_i)`.

use super::params::SourceDrivenParams;
use super::points::PointEstimator;
use super::{run, supports_single_scatter, Geometry};
use crate::tracking::residual_ratio_tracking::ResidualRatioTracking;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::equiangular::Equiangular;
use mcbench_core::task::Task;
use mcbench_core::testbed::{Needs, TestBed};
use rand::Rng;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "source_driven",
    paper: "002",
    label: "source-driven",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM.and(Needs::POINT_LIGHT),
    samplers: &["equiangular"],
    summary: "equiangular (Cauchy) scattering points, continuous transmittance of the primary ray, residual-ratio-tracking shadow rays",
    build: |p| {
        let p = parse::<SourceDrivenParams>("source_driven", p)?;
        let cfg = ResidualRatioTracking::from_params(&p.residual(), "source_driven")?;
        Ok(Box::new(SourceDriven { cfg, points: p.points }))
    },
    params: ParamSpec::of::<SourceDrivenParams>().display("source-driven").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct SourceDriven {
    /// Residual ratio tracking of the primary and shadow rays.
    pub cfg: ResidualRatioTracking,
    /// Scattering points per primary ray.
    pub points: usize,
}

/// The equiangular density of a pixel's segment (refused when the light lies on the ray).
pub fn equiangular(geo: &Geometry) -> Result<Equiangular, EstimateError> {
    Equiangular::new(geo.t_l, geo.d, geo.seg)
        .ok_or_else(|| EstimateError::Refused(format!("the light is on the pixel ray (D = {:e})", geo.d)))
}

impl Estimator for SourceDriven {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut state: Option<(PointEstimator, Equiangular)> = None;
        run(task, rng, |probe, geo, rng| {
            if state.is_none() {
                state = Some((PointEstimator::new(probe, geo, &self.cfg), equiangular(geo)?));
            }
            let Some((points, source)) = state.as_mut() else { unreachable!("set above") };
            let ts: Vec<f64> = (0..self.points).map(|_| source.sample(rng.gen())).collect();
            let f = points.integrand(probe, geo, &ts, rng)?;
            Ok(ts.iter().zip(&f).map(|(&t, &f)| if f == 0.0 { 0.0 } else { f / source.pdf(t) }).sum::<f64>()
                / self.points as f64)
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_single_scatter(bed)
    }
}

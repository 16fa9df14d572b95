//! `mis` on single scattering (paper 002 §4.3 and Fig. 12's winner): per primary ray `points`
//! source-driven (equiangular) and `points` scattering-driven points (default 1 each), all
//! evaluated with one tracking run of the primary ray ([`super::points`]) and combined with the
//! balance heuristic (Veach): `sum_i f(t_i) / (n (p_src(t_i) + p_scat(t_i)))` over the `2n` points.

use super::params::MisParams;
use super::points::PointEstimator;
use super::scattering_driven::ScatterDensity;
use super::source_driven::equiangular;
use super::{run, supports_single_scatter};
use crate::tracking::residual_ratio_tracking::ResidualRatioTracking;
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::Estimator;
use mcbench_core::math::Rgb;
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::equiangular::Equiangular;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use rand::Rng;

/// The estimator.
pub struct MisScatter {
    /// Residual ratio tracking of the primary and shadow rays.
    pub cfg: ResidualRatioTracking,
    /// Points of each technique per primary ray.
    pub points: usize,
    /// Smallest sampling extinction of the scattering-driven density.
    pub floor: f64,
}

impl MisScatter {
    /// Builds from the single-scattering parameters of `mis`.
    pub fn from_params(p: &MisParams) -> Result<Self, ConfigError> {
        Ok(MisScatter {
            cfg: ResidualRatioTracking::from_params(&p.residual(), "mis")?,
            points: p.points,
            floor: p.scatter_floor,
        })
    }
}

impl Estimator for MisScatter {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut state: Option<(PointEstimator, Equiangular, ScatterDensity)> = None;
        run(task, rng, |probe, geo, rng| {
            if state.is_none() {
                let points = PointEstimator::new(probe, geo, &self.cfg);
                let density = ScatterDensity::new(points.main(), geo, self.floor);
                state = Some((points, equiangular(geo)?, density));
            }
            let Some((points, source, scatter)) = state.as_mut() else { unreachable!("set above") };
            let mut ts: Vec<f64> = (0..self.points).map(|_| source.sample(rng.gen())).collect();
            ts.extend((0..self.points).map(|_| scatter.sample(rng.gen())));
            let f = points.integrand(probe, geo, &ts, rng)?;
            let n = self.points as f64;
            Ok(ts
                .iter()
                .zip(&f)
                .map(|(&t, &f)| if f == 0.0 { 0.0 } else { f / (n * (source.pdf(t) + scatter.pdf(t))) })
                .sum())
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_single_scatter(bed)
    }
}

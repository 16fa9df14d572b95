//! `scattering_driven` (paper 002 §4.3): `points` scattering points per primary ray (default 1)
//! from a density mimicking `T(t) sigma_t(t)` through the primary ray's piecewise-linear main part
//! `sigma_main` (the explorer points of residual ratio tracking), which makes the sampling
//! equation solvable exactly (Eq. 4): a free flight conditioned to end inside the medium,
//! `p(t) = s(t) exp(-int_{t0}^{t} s) / (1 - exp(-int_{t0}^{t1} s))` with `s = max(sigma_main,
//! scatter_floor)` at the knots (default floor 0.01: positive wherever `sigma_t` can be, so the
//! estimator stays unbiased where the approximation is zero). Drawn before the primary ray is
//! tracked; the integrand by [`super::points`]; estimate `(1/n) sum f(t_i) / p(t_i)`.

use super::params::ScatteringDrivenParams;
use super::points::PointEstimator;
use super::{run, supports_single_scatter, Geometry};
use crate::tracking::residual_ratio_tracking::ResidualRatioTracking;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::SamplingDensity;
use mcbench_core::task::Task;
use mcbench_core::testbed::{Needs, TestBed};
use rand::Rng;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "scattering_driven",
    paper: "002",
    label: "scattering-driven",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM.and(Needs::POINT_LIGHT),
    samplers: &["free_flight"],
    summary: "scattering points mimicking T sigma_t through the piecewise-linear main part, continuous transmittance, residual-ratio-tracking shadow rays",
    build: |p| {
        let p = parse::<ScatteringDrivenParams>("scattering_driven", p)?;
        let cfg = ResidualRatioTracking::from_params(&p.residual(), "scattering_driven")?;
        Ok(Box::new(ScatteringDriven { cfg, points: p.points, floor: p.scatter_floor }))
    },
    params: ParamSpec::of::<ScatteringDrivenParams>().display("scattering-driven").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct ScatteringDriven {
    /// Residual ratio tracking of the primary and shadow rays.
    pub cfg: ResidualRatioTracking,
    /// Scattering points per primary ray.
    pub points: usize,
    /// Smallest sampling extinction.
    pub floor: f64,
}

/// The scattering-driven density of a pixel: the truncated free flight of the floored main part.
pub struct ScatterDensity {
    density: SamplingDensity,
    seg: (f64, f64),
}

impl ScatterDensity {
    /// From the primary ray's main part.
    pub fn new(main: &SamplingDensity, geo: &Geometry, floor: f64) -> Self {
        ScatterDensity { density: main.floored(floor), seg: geo.seg }
    }
    /// A scattering point.
    pub fn sample(&self, xi: f64) -> f64 {
        self.density.sample_truncated(self.seg, xi)
    }
    /// Its density.
    pub fn pdf(&self, t: f64) -> f64 {
        self.density.pdf_truncated(self.seg, t)
    }
}

impl Estimator for ScatteringDriven {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut state: Option<(PointEstimator, ScatterDensity)> = None;
        run(task, rng, |probe, geo, rng| {
            let (points, density) = state.get_or_insert_with(|| {
                let points = PointEstimator::new(probe, geo, &self.cfg);
                let density = ScatterDensity::new(points.main(), geo, self.floor);
                (points, density)
            });
            let ts: Vec<f64> = (0..self.points).map(|_| density.sample(rng.gen())).collect();
            let f = points.integrand(probe, geo, &ts, rng)?;
            Ok(ts.iter().zip(&f).map(|(&t, &f)| if f == 0.0 { 0.0 } else { f / density.pdf(t) }).sum::<f64>()
                / self.points as f64)
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_single_scatter(bed)
    }
}

//! The integrand at sampled scattering points (paper 002 §4.3): one residual-ratio-tracking run of
//! the primary ray up to the farthest point gives the continuous transmittance `T^(t)` at every
//! point ([`super::transmittance`]); each point then costs one fetch of `sigma_t` and one shadow
//! ray by residual ratio tracking. Points must be drawn independently of the tracking run (source-
//! and scattering-driven points are drawn before it), so each `T^(t) g(t) T_l^(t)` is unbiased
//! for the integrand. A point where `T^ = 0` or `sigma_t = 0` contributes exactly zero and
//! traces nothing.

use super::transmittance::PrimaryTracker;
use super::{Geometry, ShadowRays};
use crate::tracking::residual_ratio_tracking::ResidualRatioTracking;
use mcbench_core::error::EstimateError;
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::SamplingDensity;
use mcbench_core::task::MediumProbe;

/// Per-pixel state: the primary ray's tracker and the shadow rays.
pub struct PointEstimator {
    tracker: PrimaryTracker,
    shadows: ShadowRays,
}

impl PointEstimator {
    /// The state of one pixel (builds the primary ray's main part: cheap fetches).
    pub fn new(probe: &MediumProbe<'_>, geo: &Geometry, cfg: &ResidualRatioTracking) -> Self {
        PointEstimator {
            tracker: PrimaryTracker::new(probe, geo, cfg),
            shadows: ShadowRays::new(cfg, probe.majorant()),
        }
    }
    /// The primary ray's piecewise-linear main part (what scattering-driven sampling mimics).
    pub fn main(&self) -> &SamplingDensity {
        self.tracker.main()
    }
    /// Unbiased estimates of the integrand `T a sigma_t rho I T_l / r^2` at each of `points`.
    pub fn integrand(
        &mut self,
        probe: &MediumProbe<'_>,
        geo: &Geometry,
        points: &[f64],
        rng: &mut StreamRng,
    ) -> Result<Vec<f64>, EstimateError> {
        let end = points.iter().copied().fold(geo.seg.0, f64::max);
        let run = self.tracker.track(probe, geo, end, rng)?;
        let mut out = Vec::with_capacity(points.len());
        for &t in points {
            let cam = run.at(t);
            if cam == 0.0 {
                out.push(0.0);
                continue;
            }
            let emission = geo.emission(t, probe.sigma_t(geo.point(t)));
            if emission == 0.0 {
                out.push(0.0);
                continue;
            }
            out.push(cam * emission * self.shadows.transmittance(probe, geo.point(t), &geo.light, rng)?);
        }
        Ok(out)
    }
}

//! The continuous transmittance estimate along the primary ray (paper 002 §4.3): residual ratio
//! tracking of `[t0, end]` leaves interaction points `s_1 < s_2 < ...` with transmitted weights
//! `E_k = prod_{j <= k} (1 - r_j)`; for any `s` in `[t0, end]`,
//!
//! `T^(s) = exp(-int_{t0}^{s} sigma_main) E_{k(s)}`, `k(s)` = the last interaction before `s`,
//!
//! is an unbiased estimate of `T(s)` (the interactions on `[t0, s]` are exactly a ratio-tracking
//! run of that sub-segment). Between interaction points it is not constant but falls off
//! exponentially with the control variate \[JNT*11, NNDJ12\], so any scattering point, however it
//! was sampled, reuses the primary ray's interaction data: one tracking run per primary ray serves
//! every scattering point at or before `end`.

use super::Geometry;
use crate::tracking::residual_ratio_tracking::{main_part, RecentMaximum, ResidualRatioTracking};
use crate::tracking::{track, Interaction, Rule};
use mcbench_core::error::EstimateError;
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::SamplingDensity;
use mcbench_core::task::MediumProbe;

/// The primary ray's tracker of one pixel: the main part through explorer points (built once per
/// pixel, cheap fetches) and the recent-maximum `sigma_samp`.
pub struct PrimaryTracker {
    main: SamplingDensity,
    memory: RecentMaximum,
}

impl PrimaryTracker {
    /// The tracker of `geo`'s primary ray with the residual tracking parameters `cfg`.
    pub fn new(probe: &MediumProbe<'_>, geo: &Geometry, cfg: &ResidualRatioTracking) -> Self {
        PrimaryTracker {
            main: main_part(probe, geo.seg, cfg.spacing, cfg.kind).0,
            memory: cfg.memory(probe.majorant()),
        }
    }
    /// The piecewise-linear main part of the extinction along the primary ray.
    pub fn main(&self) -> &SamplingDensity {
        &self.main
    }
    /// Tracks `[t0, end]` once (fetches at the interaction points) and returns its data.
    pub fn track(
        &mut self,
        probe: &MediumProbe<'_>,
        geo: &Geometry,
        end: f64,
        rng: &mut StreamRng,
    ) -> Result<Track<'_>, EstimateError> {
        let sigma_samp = self.memory.sigma();
        let (t0, end) = (geo.seg.0, end.min(geo.seg.1));
        let mut interactions = Vec::new();
        let samp = SamplingDensity::constant(sigma_samp);
        track(probe, (geo.origin, geo.dir), (t0, end), &samp, Some(&self.main), Rule::Double, rng, |i| {
            interactions.push(*i)
        })?;
        self.memory.push(interactions.iter().fold(0.0f64, |m, i| m.max(i.sigma_diff.abs())));
        Ok(Track { main: &self.main, t0, end, sigma_samp, interactions })
    }
}

/// One tracking run of the primary ray: the continuous transmittance estimate on `[t0, end]`.
pub struct Track<'a> {
    main: &'a SamplingDensity,
    t0: f64,
    end: f64,
    sigma_samp: f64,
    interactions: Vec<Interaction>,
}

impl Track<'_> {
    /// The constant sampling extinction of this run (the density of interaction points).
    pub fn sigma_samp(&self) -> f64 {
        self.sigma_samp
    }
    /// The interaction points in order.
    pub fn interactions(&self) -> &[Interaction] {
        &self.interactions
    }
    /// The main part's transmittance `exp(-int_{t0}^{s} sigma_main)`.
    pub fn main_transmittance(&self, s: f64) -> f64 {
        (-self.main.integral(self.t0, s)).exp()
    }
    /// The continuous transmittance estimate `T^(s)` for `s` in `[t0, end]` (module doc).
    pub fn at(&self, s: f64) -> f64 {
        debug_assert!(s <= self.end, "the run tracked [t0, {}] only, asked at {s}", self.end);
        let k = self.interactions.partition_point(|i| i.s < s);
        let e = if k == 0 { 1.0 } else { self.interactions[k - 1].after };
        if e == 0.0 {
            return 0.0;
        }
        self.main_transmittance(s) * e
    }
    /// `T^` just before interaction `i` (its `before` weight), as attenuation-driven sampling
    /// uses it (the interaction itself must not weight its own scattering).
    pub fn before(&self, i: &Interaction) -> f64 {
        if i.before == 0.0 {
            return 0.0;
        }
        self.main_transmittance(i.s) * i.before
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testbeds::medium::{Field, MediumBed};
    use mcbench_core::budget::Budget;
    use mcbench_core::params::Params;
    use mcbench_core::rng::stream;
    use mcbench_core::stats::{holm_bonferroni, one_sample_t, Moments};
    use mcbench_core::task::Task;

    /// The continuous estimate is unbiased at points between interactions (not only at the
    /// tracked segment's end): one run of the central ray's [0, 20] per repetition, T^(s) read at
    /// s = 2.3, 7.7, 12.1, 19.9 against the exact transmittance, Holm over the points. The
    /// constant (step) interpolation between interaction points, which ignores the control
    /// variate's fall-off, is flagged on the same runs.
    #[test]
    fn continuous_transmittance_is_unbiased_between_interactions() {
        let points = [2.3, 7.7, 12.1, 19.9];
        let bed = MediumBed::new(
            Field::Eq21,
            "central-ray",
            &Params::new().with("points", 10.0),
            &crate::built_in_references::BUILT_IN,
        )
        .unwrap();
        let z = mcbench_core::math::Vec3::Z;
        let exact: Vec<f64> = points
            .iter()
            .map(|&s| {
                (-crate::testbeds::medium::reference::optical_depth(&bed, Default::default(), z, 0.0, s).value).exp()
            })
            .collect();
        let task = Task::new(&bed, 9, Budget::samples(1).unwrap());
        let probe = task.medium().unwrap();
        let ray = *probe.ray();
        let geo = Geometry {
            origin: ray.origin,
            dir: ray.dir,
            seg: (0.0, 20.0),
            light: crate::testbeds::medium::LIGHT,
            t_l: 10.0,
            d: 1.0,
            albedo: 0.7,
            phase: mcbench_core::phase::Phase::Rayleigh,
        };
        let cfg = ResidualRatioTracking {
            spacing: 2.0,
            recent: 4,
            floor: 0.05,
            first: None,
            kind: crate::tracking::residual_ratio_tracking::MainPart::Linear,
        };
        let mut tracker = PrimaryTracker::new(&probe, &geo, &cfg);
        let mut rng = stream(31, "continuous");
        let (mut cont, mut step) = (vec![Moments::default(); 4], vec![Moments::default(); 4]);
        for _ in 0..4000 {
            let run = tracker.track(&probe, &geo, 20.0, &mut rng).unwrap();
            for (k, &s) in points.iter().enumerate() {
                cont[k].push(run.at(s));
                // Step interpolation: the estimate at the last interaction before s.
                let last = run.interactions().iter().rev().find(|i| i.s < s);
                step[k].push(last.map_or(1.0, |i| run.main_transmittance(i.s) * i.after));
            }
        }
        let p = |m: &[Moments]| {
            let ps: Vec<f64> =
                m.iter().zip(&exact).map(|(m, e)| one_sample_t(m.mean(), m.std_err(), m.count(), *e).p_value).collect();
            holm_bonferroni(&ps).into_iter().fold(1.0, f64::min)
        };
        assert!(
            p(&cont) > 1e-3,
            "continuous estimate flagged: {:?} vs {exact:?}",
            cont.iter().map(|m| m.mean()).collect::<Vec<_>>()
        );
        assert!(p(&step) < 1e-6, "step interpolation not flagged: {}", p(&step));
    }
}

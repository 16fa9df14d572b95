//! `attenuation_driven_sir` (paper 002 §4.3, sampling importance resampling \[TCE05\]): the
//! candidates are the attenuation-driven scattering points with weights
//! `w_k = T^(s_k-) a sigma_t rho I / (r^2 sigma_samp)` (everything but the shadow transmittance);
//! `shadow_rays` of them (default 1) are resampled with probability `|w_k| / W`, `W = sum |w_k|`,
//! and only those trace a shadow ray: the estimate `(W / M) sum_m sign(w_{k_m}) T_l^(s_{k_m})` has
//! the expectation `sum_k w_k T_l(s_k)` of attenuation-driven sampling (unbiased; weights can be
//! negative with residual tracking, hence the sign). More variance per primary ray, far fewer
//! shadow rays (paper Fig. 12: 30 rays against 10 at equal fetches).

use super::params::AttenuationSirParams;
use super::transmittance::PrimaryTracker;
use super::{run, supports_single_scatter, ShadowRays};
use crate::tracking::residual_ratio_tracking::ResidualRatioTracking;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::mixture::pick;
use mcbench_core::task::Task;
use mcbench_core::testbed::{Needs, TestBed};

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "attenuation_driven_sir",
    paper: "002",
    label: "attenuation-driven SIR",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM.and(Needs::POINT_LIGHT),
    samplers: &["free_flight"],
    summary:
        "attenuation-driven candidates, shadow rays only for `shadow_rays` (1) of them resampled by importance (SIR)",
    build: |p| {
        let p = parse::<AttenuationSirParams>("attenuation_driven_sir", p)?;
        let cfg = ResidualRatioTracking::from_params(&p.residual(), "attenuation_driven_sir")?;
        Ok(Box::new(AttenuationDrivenSir { cfg, shadow_rays: p.shadow_rays }))
    },
    params: ParamSpec::of::<AttenuationSirParams>().display("attenuation-driven SIR").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct AttenuationDrivenSir {
    /// Residual ratio tracking of the primary and shadow rays.
    pub cfg: ResidualRatioTracking,
    /// Resampled candidates per primary ray (shadow rays traced).
    pub shadow_rays: usize,
}

/// The candidates resampled by SIR: `m` indices drawn with probability `|w_k| / W` (with
/// replacement), or none when every weight is zero.
pub fn resample(weights: &[f64], m: usize, rng: &mut StreamRng) -> Vec<usize> {
    let abs: Vec<f64> = weights.iter().map(|w| w.abs()).collect();
    if !abs.iter().any(|&w| w > 0.0) {
        return Vec::new();
    }
    (0..m).map(|_| pick(&abs, rng)).collect()
}

impl Estimator for AttenuationDrivenSir {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let mut state: Option<(PrimaryTracker, ShadowRays)> = None;
        run(task, rng, |probe, geo, rng| {
            let (tracker, shadows) = state.get_or_insert_with(|| {
                (PrimaryTracker::new(probe, geo, &self.cfg), ShadowRays::new(&self.cfg, probe.majorant()))
            });
            let run = tracker.track(probe, geo, geo.seg.1, rng)?;
            let weights: Vec<f64> = run
                .interactions()
                .iter()
                .map(|i| run.before(i) * geo.emission(i.s, i.sigma_t) / run.sigma_samp())
                .collect();
            let total: f64 = weights.iter().map(|w| w.abs()).sum();
            let mut sum = 0.0;
            for k in resample(&weights, self.shadow_rays, rng) {
                let s = run.interactions()[k].s;
                sum += weights[k].signum() * shadows.transmittance(probe, geo.point(s), &geo.light, rng)?;
            }
            Ok(total / self.shadow_rays as f64 * sum)
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_single_scatter(bed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::rng::stream;
    use mcbench_core::samplers::testing::sampler_alpha;
    use mcbench_core::stats::chi_square_gof;

    /// Chi-square of the resampled indices against `|w_k| / W`, with a negative weight and a zero
    /// weight (never drawn) among the candidates.
    #[test]
    fn sir_resampling_fits_the_weights() {
        let weights = [0.3, -1.2, 0.0, 2.5, 0.05, -0.4];
        let mut counts = [0u64; 6];
        let mut rng = stream(41, "sir");
        for _ in 0..50_000 {
            for k in resample(&weights, 2, &mut rng) {
                counts[k] += 1;
            }
        }
        assert_eq!(counts[2], 0);
        let total: f64 = weights.iter().map(|w: &f64| w.abs()).sum();
        let (c, p): (Vec<u64>, Vec<f64>) =
            counts.iter().zip(weights).filter(|(_, w)| *w != 0.0).map(|(c, w)| (*c, w.abs() / total)).unzip();
        let t = chi_square_gof(&c, &p).unwrap();
        assert!(t.p_value > sampler_alpha(), "p = {:e}", t.p_value);
        assert!(resample(&[0.0, 0.0], 3, &mut rng).is_empty());
    }
}

//! Null-collision and particle-model estimators of paper 002 (book: testbeds.md): transmittance trackers
//! (ray marching, delta, ratio, residual ratio, double and single particle models) and particle
//! tracing of multiple scattering (`spm_*`).
//!
//! Every medium access goes through the counted [`MediumProbe`]: one extinction evaluation is one
//! fetch, one ray or path is one sample.

pub mod constant;
pub mod delta_tracking;
pub mod double_particle;
pub mod moments;
pub mod params;
pub mod ratio_tracking;
pub mod ray_marching;
pub mod residual_ratio_tracking;
pub mod single_particle;
pub mod spm;
pub mod variance;

use crate::tracking::moments::tracker_moments;
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::EstimateMoments;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::SamplingDensity;
use mcbench_core::stats::NeumaierSum;
use mcbench_core::task::{MediumProbe, Task};
use mcbench_core::testbed::{MediumQuantity, TestBed};
use rand::Rng;
use residual_ratio_tracking::{main_part, MainPart};

/// How the weight of the transmitted particle changes at an interaction with
/// `r = sigma_diff / sigma_samp` (paper 002 §3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rule {
    /// Double particle model, Eq. 8 (ratio tracking when sigma_samp is a constant majorant):
    /// `E *= 1 - r`, any sign of `r`.
    Double,
    /// Woodcock / delta tracking: terminate with probability `r` (needs `0 <= r <= 1`).
    Delta,
    /// Single particle model, terminating (Eq. 9 with `q_scat = a r`, `q_tran = |1 - r|`); a
    /// scattered or absorbed particle leaves the ray (weight 0). Valid for `0 <= r <= 2/(a+1)`.
    Terminating {
        /// Albedo.
        a: f64,
    },
    /// Single particle model, non-terminating (Eq. 12 probabilities), any `r`.
    NonTerminating {
        /// Albedo.
        a: f64,
    },
}

/// Applies `rule` once: the factor the transmitted weight is multiplied by (0 = the particle left).
/// Inlined into the tracker loop; the refusals are cold paths.
#[inline]
pub fn interact(rule: Rule, r: f64, xi: f64) -> Result<f64, EstimateError> {
    match rule {
        Rule::Double => Ok(1.0 - r),
        Rule::Delta => {
            if !(0.0..=1.0).contains(&r) {
                return Err(refused_delta(r));
            }
            Ok(if xi < r { 0.0 } else { 1.0 })
        }
        Rule::Terminating { a } => {
            if r < 0.0 || r > 2.0 / (a + 1.0) {
                return Err(refused_terminating(r, a));
            }
            let q_tran = (1.0 - r).abs();
            Ok(if xi < q_tran { (1.0 - r) / q_tran } else { 0.0 })
        }
        Rule::NonTerminating { a } => {
            let q_tran = (1.0 - r).abs() / (a * r.abs() + (1.0 - r).abs());
            Ok(if q_tran > 0.0 && xi < q_tran { (1.0 - r) / q_tran } else { 0.0 })
        }
    }
}

#[cold]
fn refused_delta(r: f64) -> EstimateError {
    EstimateError::Refused(format!("delta tracking needs a majorant, but sigma_t / sigma_samp = {r}"))
}

#[cold]
fn refused_terminating(r: f64, a: f64) -> EstimateError {
    EstimateError::Refused(format!(
        "terminating single-particle model invalid at r = {r} (needs 0 <= r <= 2/(a+1) = {})",
        2.0 / (a + 1.0)
    ))
}

/// One interaction of the `Transmittance` algorithm: where it happened, the extinction fetched
/// there, the difference extinction, and the transmitted weight before and after it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interaction {
    /// Ray parameter.
    pub s: f64,
    /// Real extinction `sigma_t` (one fetch).
    pub sigma_t: f64,
    /// `sigma_t - sigma_main`.
    pub sigma_diff: f64,
    /// Weight of the transmitted particle before the interaction.
    pub before: f64,
    /// Weight after it.
    pub after: f64,
}

/// The paper's `Transmittance` algorithm (§4.2) on `[t0, t1]` of the line `origin + s dir` for
/// the difference extinction `sigma_t - main(s)`: free flights from `samp` (Eq. 4), `rule` at each
/// interaction, which is reported to `seen`. Returns the weight of the transmitted particle
/// (multiply by the main part's transmittance); it overflows to infinity where a product of
/// thousands of factors `|1 - r| > 1` exceeds f64 (optical depth 1e4): [`track_scaled`] does not.
#[allow(clippy::too_many_arguments)] // the tracker loop of paper 002 Alg. 1: probe, ray, segment, densities, weights, callbacks
pub fn track(
    probe: &MediumProbe<'_>,
    line: (Vec3, Vec3),
    seg: (f64, f64),
    samp: &SamplingDensity,
    main: Option<&SamplingDensity>,
    rule: Rule,
    rng: &mut StreamRng,
    seen: impl FnMut(&Interaction),
) -> Result<f64, EstimateError> {
    track_scaled(probe, line, seg, samp, main, rule, rng, seen).map(|w| w.value())
}

/// A tracker weight `e 2^k` whose mantissa part `e` is kept within `2^-RESCALE..2^RESCALE` by exact
/// power-of-two rescaling (so it never overflows and is bit-identical to the plain product
/// wherever that product is finite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaledWeight {
    /// The rescaled product.
    pub e: f64,
    /// The power of two it was divided by.
    pub k: i32,
}

impl ScaledWeight {
    /// Exponent step of a rescale.
    pub const RESCALE: i32 = 512;
    /// The bound on `|e|` above which a tracker rescales (`2^RESCALE`).
    pub const BIG: f64 = f64::from_bits((1023 + Self::RESCALE as u64) << 52);
    /// `e 2^k` as an f64 (infinite where it overflows).
    #[inline]
    pub fn value(self) -> f64 {
        if self.k == 0 {
            self.e
        } else {
            self.scaled_value()
        }
    }
    /// [`ScaledWeight::value`] of a rescaled weight (rare: a cold call, not a select).
    #[cold]
    fn scaled_value(self) -> f64 {
        self.e * 2f64.powi(self.k)
    }
    /// `(e 2^-RESCALE, k + RESCALE)`: the weight `(e, k)` rescaled once (exact). A cold call, so
    /// the tracker loops test `|e| > BIG` with a predictable branch.
    #[cold]
    pub fn rescale(e: f64, k: i32) -> (f64, i32) {
        (e * 2f64.powi(-Self::RESCALE), k + Self::RESCALE)
    }
    /// `e 2^k exp(-tau)` without intermediate overflow or underflow: the product with a main
    /// part's transmittance `exp(-tau)` given as its optical depth `tau`; `t_main` (= `exp(-tau)`
    /// as the caller computed it) is used as is when nothing was rescaled, so ordinary results do
    /// not change by a bit.
    pub fn times_transmittance(self, t_main: f64, tau: f64) -> f64 {
        if self.k == 0 && (t_main > 0.0 || self.e == 0.0) {
            return self.e * t_main;
        }
        if self.e == 0.0 {
            return 0.0;
        }
        self.e.signum() * (self.e.abs().ln() + f64::from(self.k) * std::f64::consts::LN_2 - tau).exp()
    }
}

/// [`track`] returning the weight as a [`ScaledWeight`] (log-magnitude safe).
#[allow(clippy::too_many_arguments)] // as track
pub fn track_scaled(
    probe: &MediumProbe<'_>,
    (origin, dir): (Vec3, Vec3),
    (t0, t1): (f64, f64),
    samp: &SamplingDensity,
    main: Option<&SamplingDensity>,
    rule: Rule,
    rng: &mut StreamRng,
    mut seen: impl FnMut(&Interaction),
) -> Result<ScaledWeight, EstimateError> {
    let (mut e, mut k, mut s) = (1.0f64, 0i32, t0);
    loop {
        s = samp.sample(s, rng.gen::<f64>());
        if s >= t1 {
            return Ok(ScaledWeight { e, k });
        }
        let sigma_t = probe.sigma_t(origin + dir * s);
        let sigma_diff = sigma_t - main.map_or(0.0, |m| m.eval(s));
        let before = e;
        e *= interact(rule, sigma_diff / samp.eval(s), rng.gen::<f64>())?;
        // Observers see the unscaled weights (as the plain product, infinite past f64's range).
        let unscale = if k == 0 { 1.0 } else { 2f64.powi(k) };
        seen(&Interaction { s, sigma_t, sigma_diff, before: before * unscale, after: e * unscale });
        if e == 0.0 {
            return Ok(ScaledWeight { e: 0.0, k: 0 });
        }
        if e.abs() > ScaledWeight::BIG {
            (e, k) = ScaledWeight::rescale(e, k);
        }
    }
}

/// The medium segment `[t0, t1]` of a transmittance integral (None: the ray misses it).
pub fn segment(probe: &MediumProbe<'_>) -> Option<(f64, f64)> {
    let ray = probe.ray();
    probe.clip(ray.origin, ray.dir).map(|(a, b)| (a, b.min(ray.length))).filter(|(a, b)| b > a)
}

/// Runs a transmittance estimator: averages `one()` over rays while the budget lasts and
/// multiplies by the integral's weight. A ray that misses the medium is exact (T = 1) and costs
/// one sample, so no estimator can loop on it. Refuses radiance integrals.
pub fn transmittance(
    task: &Task<'_>,
    rng: &mut StreamRng,
    mut one: impl FnMut(&MediumProbe<'_>, (f64, f64), &mut StreamRng) -> Result<f64, EstimateError>,
) -> Result<Rgb, EstimateError> {
    let probe = task.medium().ok_or_else(|| EstimateError::Refused("the test bed has no medium".into()))?;
    let MediumQuantity::Transmittance { weight } = probe.ray().quantity else {
        return Err(EstimateError::Refused("a transmittance estimator cannot estimate scattered radiance".into()));
    };
    let Some(seg) = segment(&probe) else {
        probe.start_sample();
        return Ok(weight);
    };
    // One compensated sum (the channels of a transmittance are equal): the same value as the
    // first channel of an `RgbMean`, without summing three copies per ray.
    let (mut sum, mut n) = (NeumaierSum::new(), 0u64);
    while task.more() {
        probe.start_sample();
        sum.add(one(&probe, seg, rng)?);
        n += 1;
    }
    Ok(weight * if n == 0 { 0.0 } else { sum.value() / n as f64 })
}

/// The exact moments of one tracker ray on `task`'s transmittance integral
/// ([`crate::tracking::moments`]): constant density `sigma_samp`, the rule `rule(albedo)`, and the
/// main part `control` (shape, explorer spacing) computed exactly as the estimator computes it;
/// `None` for radiance integrals or where the rule is invalid on the ray.
pub fn ray_moments(
    task: &Task<'_>,
    sigma_samp: SigmaSamp,
    rule: impl Fn(f64) -> Rule,
    control: Option<(MainPart, f64)>,
) -> Option<EstimateMoments> {
    let probe = task.medium()?;
    let MediumQuantity::Transmittance { weight } = probe.ray().quantity else { return None };
    let Some(seg) = segment(&probe) else {
        return Some(EstimateMoments::constant(weight[0]));
    };
    let main = control.map(|(kind, spacing)| main_part(&probe, seg, spacing, kind));
    let ray = *probe.ray();
    let diff = |t: f64| probe.sigma_t(ray.origin + ray.dir * t) - main.as_ref().map_or(0.0, |m| m.0.eval(t));
    let depth = main.as_ref().map_or(0.0, |m| -m.1.ln());
    let samp = sigma_samp.resolve(probe.majorant());
    let m = tracker_moments(diff, depth, samp, rule(probe.albedo()), seg, &[])?;
    Some(EstimateMoments { mean: m.mean * weight[0], ..m })
}

/// Refuses a sampling extinction under which one ray's variance is not finite in f64 on `bed`
/// (the stability case `sigma_samp = 1e-6 x sigma_t`: the double and non-terminating particle models are
/// unbiased for any `sigma_samp`, but their second moment `exp(int sigma_samp ((1 - r)^2 - 1))`
/// is `exp(7e5)` there, so no run of any length estimates anything). Checks the exact moments
/// ([`mcbench_core::estimator::Estimator::sample_moments`]) of up to 16 transmittance integrals spread over the bed.
/// The integrals are checked in parallel (their moments take seconds of quadrature on the Perlin
/// field); the refusal names the first that fails, whatever the thread count.
pub fn check_finite_variance(
    id: &str,
    est: &dyn mcbench_core::estimator::Estimator,
    sigma_samp: SigmaSamp,
    bed: &dyn TestBed,
) -> Result<(), ConfigError> {
    if bed.medium().is_none() {
        return Ok(());
    }
    first_infinite_variance(est, bed).map_or(Ok(()), |i| Err(infinite_variance(id, sigma_samp, bed, i)))
}

/// The first integral checked whose one-ray variance is not finite, if any (see
/// [`check_finite_variance`]).
fn first_infinite_variance(est: &dyn mcbench_core::estimator::Estimator, bed: &dyn TestBed) -> Option<usize> {
    let budget = mcbench_core::budget::Budget::samples(1).ok()?;
    let n = bed.integrals();
    let step = n.div_ceil(16).max(1);
    let checked: Vec<usize> = (0..n).step_by(step).collect();
    let infinite = mcbench_core::parallel::map_indices(checked.len(), 0, |k| {
        est.sample_moments(&Task::new(bed, checked[k], budget)).is_some_and(|m| !m.rel_variance.is_finite())
    });
    checked.iter().zip(infinite).find_map(|(&i, inf)| inf.then_some(i))
}

/// The refusal of [`check_finite_variance`] at integral `i`.
fn infinite_variance(id: &str, sigma_samp: SigmaSamp, bed: &dyn TestBed, i: usize) -> ConfigError {
    let (field, value) = match sigma_samp {
        SigmaSamp::Ratio(v) => ("sigma_samp_ratio", v),
        SigmaSamp::Absolute(v) => ("sigma_samp", v),
        SigmaSamp::Majorant => ("sigma_samp", bed.medium().map_or(1.0, |m| m.majorant())),
    };
    ConfigError::invalid(
        format!("{id}.{field}"),
        value,
        format!(
            "the variance of one ray overflows f64 on {}/{} integral {i} (paper 002 §3.4 moments): no run can estimate with it; use a sigma_samp nearer the extinction",
            bed.id(),
            bed.variant()
        ),
    )
}

/// A `sigma_samp` parameter, refused unless positive (`None` when absent).
pub fn sigma_samp_param(sigma_samp: Option<f64>, owner: &str) -> Result<Option<f64>, ConfigError> {
    match sigma_samp {
        Some(v) if v <= 0.0 => Err(ConfigError::invalid(format!("{owner}.sigma_samp"), v, "must be > 0")),
        v => Ok(v),
    }
}

/// A tracker's constant sampling density `sigma_samp` (paper 002 Eq. 4 with a constant density):
/// absolute (parameter `sigma_samp`), relative to the scene's declared majorant (parameter
/// `sigma_samp_ratio`, the axis of the canonical sweep: below 1 it is not a majorant), or the
/// declared majorant itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SigmaSamp {
    /// The scene's declared majorant.
    Majorant,
    /// A fixed value (> 0).
    Absolute(f64),
    /// This multiple (> 0) of the scene's declared majorant.
    Ratio(f64),
}

impl SigmaSamp {
    /// From `sigma_samp` or `sigma_samp_ratio` (not both; each > 0), else `default`.
    pub fn from_params(p: &params::SigmaSampParams, owner: &str, default: SigmaSamp) -> Result<SigmaSamp, ConfigError> {
        match (sigma_samp_param(p.sigma_samp, owner)?, p.sigma_samp_ratio) {
            (Some(_), Some(r)) => Err(ConfigError::invalid(
                format!("{owner}.sigma_samp_ratio"),
                r,
                "give sigma_samp or sigma_samp_ratio, not both",
            )),
            (Some(v), None) => Ok(SigmaSamp::Absolute(v)),
            (None, Some(r)) if r > 0.0 => Ok(SigmaSamp::Ratio(r)),
            (None, Some(r)) => Err(ConfigError::invalid(format!("{owner}.sigma_samp_ratio"), r, "must be > 0")),
            (None, None) => Ok(default),
        }
    }
    /// The density on a scene declaring `majorant`.
    pub fn resolve(self, majorant: f64) -> f64 {
        match self {
            SigmaSamp::Majorant => majorant,
            SigmaSamp::Absolute(v) => v,
            SigmaSamp::Ratio(r) => r * majorant,
        }
    }
    /// For trackers that need a majorant (delta and ratio tracking): why this density cannot run
    /// on `bed` (a skipped pair with the reason), or `Ok` when it is at least the declared majorant.
    pub fn require_majorant(self, owner: &str, bed: &dyn TestBed) -> Result<(), String> {
        let Some(m) = bed.medium() else { return Ok(()) };
        let (sigma, majorant) = (self.resolve(m.majorant()), m.majorant());
        if sigma >= majorant {
            return Ok(());
        }
        let field = match self {
            SigmaSamp::Ratio(r) => format!("{owner}.sigma_samp_ratio = {r}"),
            _ => format!("{owner}.sigma_samp = {sigma}"),
        };
        Err(format!(
            "{field}: {owner} needs a majorant, but sigma_samp = {sigma:.6} is below the declared majorant {majorant:.6} of {}/{} (r = sigma_t/sigma_samp would exceed 1; the double and single particle models accept it)",
            bed.id(),
            bed.variant()
        ))
    }
}

/// Refuses (as a skipped pair) test beds whose integrals are not transmittances.
pub fn supports_transmittance(bed: &dyn TestBed) -> Result<(), String> {
    match bed.medium() {
        Some(m) if matches!(m.ray(0).quantity, MediumQuantity::Transmittance { .. }) => Ok(()),
        Some(_) => Err("a transmittance estimator; this variant asks for scattered radiance".into()),
        None => Err("needs a medium".into()),
    }
}

#[cfg(test)]
mod tests;

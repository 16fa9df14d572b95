//! The stored reference of `gradient-box` (book: testbeds.md), made by an integrator that shares no
//! sampling code with the estimators it judges (in particular not with `is0_cv0`'s path tracer,
//! `crate::media_smc::PathTracer`): a reference made by an estimator's own code would hide that
//! estimator's bugs and flag the correct ones.
//!
//! The quantity is paper 000 Eq. 6 along each pixel-centre ray of the orthographic camera:
//! `L(x, w) = T(x, x_b) L_b(w) + int_0^d sigma_t T(s) a int_S2 p(w . w') L(x_s, w') dw' ds` with
//! `T(s) = exp(-sigma_t s)` in the homogeneous cube, `d` the distance to its boundary along `w`,
//! and `L_b` the bed's clamped gradient (the scene definition, [`Gradient::eval`]). The
//! integrator is an expected-value ("escape and forced collision") walk written here:
//! - the unscattered term `T(d) L_b(w)` of every segment is added analytically (no escape event);
//! - the collision distance is drawn from the exponential truncated to `[0, d)` by its own inverse
//!   CDF, `s = -ln(1 - u (1 - T(d))) / sigma_t`, with weight `(1 - T(d)) a`;
//! - the new direction is drawn **uniformly on the sphere** (not from the phase function) with
//!   weight `4 pi p(w . w')`, the phase function evaluated from its formula here;
//! - the distance to the boundary comes from its own slab intersection ([`exit_distance`]);
//! - paths end by Russian roulette once their weight falls below [`ROULETTE_BELOW`].
//!
//! Every term is unbiased for Eq. 6, so a disagreement with the estimators is a bug on one side.
//! Each pixel runs [`BATCHES`] seeded batches; the spread of the batch means gives the per-pixel,
//! per-channel standard error. Made by `mcbench reference gradient-box --variant V [--samples N]`.

use super::gradient_box::GradientBox;
use mcbench_core::error::ConfigError;
use mcbench_core::lighting::Gradient;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::Params;
use mcbench_core::phase::Phase;
use mcbench_core::references::{ReferenceKey, StoredReference};
use mcbench_core::rng::StreamKey;
use mcbench_core::testbed::{Reference, ReferenceKind, TestBed};
use rand::Rng;
use std::f64::consts::PI;

/// Independent batches per pixel (the standard error's degrees of freedom + 1).
pub const BATCHES: u64 = 64;
/// The seed of every stored reference made here (different from the streams of any experiment).
pub const SEED: u64 = 2;
/// The name written into the stored files' `command`.
pub const METHOD: &str = "independent expected-value walk (analytic transmittance, truncated-exponential collisions, uniform-sphere directions weighted by the phase function)";
/// Below this path weight a path survives with probability `weight / ROULETTE_BELOW` and then
/// carries weight `ROULETTE_BELOW` (unbiased).
pub const ROULETTE_BELOW: f64 = 0.05;

/// Default paths per pixel, every variant: 2^20 (the standard errors then stay below those of the
/// previous references, made with 2^20 and, for `thick`, 2^18 phase-sampled paths; see docs/src/testbeds.md).
pub fn default_samples(_variant: &str) -> u64 {
    1 << 20
}

/// What the integrator needs of the scene (book: testbeds.md): the cube `[-0.5, 0.5]^3`.
#[derive(Clone, Copy, Debug)]
pub struct BoxMedium {
    /// Extinction inside the cube.
    pub sigma_t: f64,
    /// Single-scattering albedo.
    pub albedo: f64,
    /// Phase function (read for its parameters only; evaluated by [`phase_value`]).
    pub phase: Phase,
    /// Background seen by directions leaving the cube.
    pub background: Gradient,
}

/// The phase function's density at scattering cosine `cos` from its textbook formula: isotropic
/// `1 / 4 pi`; Henyey-Greenstein `(1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2))` (g > 0 forward);
/// Rayleigh `3 (1 + cos^2) / (16 pi)`.
pub fn phase_value(phase: Phase, cos: f64) -> f64 {
    match phase {
        Phase::Isotropic => 0.25 / PI,
        Phase::HenyeyGreenstein(g) => (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5)),
        Phase::Rayleigh => 3.0 * (1.0 + cos * cos) / (16.0 * PI),
    }
}

/// A direction uniform on the unit sphere (density `1 / 4 pi`): `z = 1 - 2 u1`, `phi = 2 pi u2`.
pub fn uniform_sphere<R: Rng + ?Sized>(rng: &mut R) -> Vec3 {
    let z = 1.0 - 2.0 * rng.gen::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * rng.gen::<f64>();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Entry and exit distances `(t_in, t_out)`, `0 <= t_in <= t_out`, of the ray `o + t w` through the
/// cube `[-0.5, 0.5]^3`, or `None` when it misses (per axis: the interval where the coordinate
/// lies in `[-0.5, 0.5]`, intersected).
pub fn exit_distance(o: Vec3, w: Vec3) -> Option<(f64, f64)> {
    let mut lo = 0.0f64;
    let mut hi = f64::INFINITY;
    for axis in 0..3 {
        let (p, v) = match axis {
            0 => (o.x, w.x),
            1 => (o.y, w.y),
            _ => (o.z, w.z),
        };
        if v.abs() < 1e-300 {
            if p.abs() > 0.5 {
                return None;
            }
            continue;
        }
        let near = if v > 0.0 { (-0.5 - p) / v } else { (0.5 - p) / v };
        let far = if v > 0.0 { (0.5 - p) / v } else { (-0.5 - p) / v };
        lo = lo.max(near);
        hi = hi.min(far);
        if lo > hi {
            return None;
        }
    }
    Some((lo, hi))
}

/// The pixel-centre ray of pixel `i` of a `size x size` image, from the test bed's definition: orthographic along
/// +y, the image covering `x, z in [-0.5, 0.5]`, row 0 at the top (`z = +0.5`); origin at y = -1.
pub fn camera_ray(size: usize, i: usize) -> (Vec3, Vec3) {
    let h = 1.0 / size as f64;
    let (col, row) = ((i % size) as f64, (i / size) as f64);
    (Vec3::new(-0.5 + h * (col + 0.5), -1.0, 0.5 - h * (row + 0.5)), Vec3::new(0.0, 1.0, 0.0))
}

/// One path's estimate of the radiance arriving at `o` against direction `w` (paper 000 Eq. 6).
pub fn radiance<R: Rng + ?Sized>(m: &BoxMedium, o: Vec3, w: Vec3, rng: &mut R) -> Rgb {
    let (mut o, mut w) = (o, w);
    let mut weight = 1.0f64;
    let mut sum = Rgb::ZERO;
    loop {
        let Some((t_in, t_out)) = exit_distance(o, w) else {
            return sum + m.background.eval(w) * weight;
        };
        let d = t_out - t_in;
        // 1 - T(d), accurate for small optical depths.
        let hit = -(-m.sigma_t * d).exp_m1();
        sum += m.background.eval(w) * (weight * (1.0 - hit));
        if m.albedo <= 0.0 || hit <= 0.0 {
            return sum;
        }
        // Truncated exponential on [0, d): F(s) = (1 - exp(-sigma s)) / hit.
        let u: f64 = rng.gen();
        let s = (-(-u * hit).ln_1p() / m.sigma_t).min(d);
        o = o + w * (t_in + s);
        weight *= hit * m.albedo;
        if weight < ROULETTE_BELOW {
            if rng.gen::<f64>() * ROULETTE_BELOW >= weight {
                return sum;
            }
            weight = ROULETTE_BELOW;
        }
        let next = uniform_sphere(rng);
        weight *= 4.0 * PI * phase_value(m.phase, w.dot(next));
        w = next;
    }
}

/// The mean and the standard error (from the spread of [`BATCHES`] batch means) of `per_batch`
/// paths per batch at pixel `i`.
pub fn pixel(m: &BoxMedium, size: usize, i: usize, per_batch: u64, label: &str) -> (Rgb, Rgb) {
    let (o, w) = camera_ray(size, i);
    let (mut s1, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for batch in 0..BATCHES {
        let key = StreamKey {
            seed: SEED,
            testbed: label,
            estimator: "independent-reference",
            budget: per_batch,
            rep: batch,
            integral: i as u64,
        };
        let mut rng = key.rng();
        let mut acc = [0.0f64; 3];
        for _ in 0..per_batch {
            let v = radiance(m, o, w, &mut rng);
            (0..3).for_each(|c| acc[c] += v[c]);
        }
        for c in 0..3 {
            let mean = acc[c] / per_batch as f64;
            s1[c] += mean;
            s2[c] += mean * mean;
        }
    }
    let n = BATCHES as f64;
    let mean = s1.map(|s| s / n);
    let se = std::array::from_fn(|c| ((s2[c] - n * mean[c] * mean[c]).max(0.0) / (n - 1.0) / n).sqrt());
    (Rgb(mean), Rgb(se))
}

/// Computes the reference of `variant` with the test bed's `params` and `samples` paths per pixel
/// (default [`default_samples`]) on `threads` threads; the result does not depend on the thread
/// count.
pub fn compute_reference(
    variant: &str,
    params: &Params,
    samples: Option<u64>,
    threads: usize,
) -> Result<(ReferenceKey, StoredReference), ConfigError> {
    let samples = samples.unwrap_or_else(|| default_samples(variant));
    if samples == 0 || samples > 1 << 40 {
        return Err(ConfigError::invalid("samples", samples, "must be a whole number in [1, 2^40]"));
    }
    let per_batch = samples.div_ceil(BATCHES).max(1);
    let bed = GradientBox::without_reference(variant, params)?;
    let key = bed.reference_key();
    let (size, _) = bed.resolution();
    let s = bed.setup();
    let medium = BoxMedium { sigma_t: s.sigma_t, albedo: s.albedo, phase: s.phase, background: s.background };
    let label = format!("gradient-box/{variant}/independent-reference");
    let results =
        mcbench_core::parallel::map_indices(size * size, threads, |i| pixel(&medium, size, i, per_batch, &label));
    if results.iter().any(|(m, e)| !m.is_finite() || !e.is_finite()) {
        return Err(ConfigError::invalid("reference", variant, "a pixel's estimate was not finite"));
    }
    let command = format!(
        "{} --samples {} (resolution {size}, sigma_t {}, seed {SEED}, {BATCHES} batches of {per_batch} paths per pixel; {METHOD})",
        key.command(),
        per_batch * BATCHES,
        s.sigma_t,
    );
    let reference = Reference {
        kind: ReferenceKind::Stored { command: command.clone(), samples: BATCHES },
        value: results.iter().map(|r| r.0).collect(),
        std_err: results.iter().map(|r| r.1).collect(),
    };
    Ok((
        key.clone(),
        StoredReference {
            testbed: key.testbed,
            variant: key.variant,
            params: key.params,
            command,
            resolution: (size, size),
            reference,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::testbed::MediumScene;

    fn medium(variant: &str) -> BoxMedium {
        let s = super::super::gradient_box::variant_setup(variant).unwrap();
        BoxMedium { sigma_t: s.sigma_t, albedo: s.albedo, phase: s.phase, background: s.background }
    }

    /// The camera written here from the test bed's definition is the bed's, and the slab code agrees with the bed's
    /// clip on rays from outside and inside the cube.
    #[test]
    fn camera_and_intersection_match_the_scene() {
        let bed = GradientBox::without_reference("albedo-0.8", &Params::new()).unwrap();
        for i in 0..256 {
            let (o, w) = camera_ray(16, i);
            let r = bed.ray(i);
            assert_eq!((o, w), (r.origin, r.dir), "pixel {i}");
        }
        let mut rng = StreamKey { seed: 9, testbed: "t", estimator: "e", budget: 0, rep: 0, integral: 0 }.rng();
        for _ in 0..10_000 {
            let o = Vec3::new(rng.gen::<f64>() * 3.0 - 1.5, rng.gen::<f64>() * 3.0 - 1.5, rng.gen::<f64>() * 3.0 - 1.5);
            let w = uniform_sphere(&mut rng);
            match (exit_distance(o, w), super::super::gradient_box::clip_box(o, w)) {
                (Some(a), Some(b)) => assert!((a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12),
                (None, None) => {}
                (a, b) => panic!("{o:?} {w:?}: {a:?} vs {b:?}"),
            }
        }
    }

    /// The phase formulas here agree with the scene's, and the uniform-sphere weight integrates to 1.
    #[test]
    fn phase_values_match_and_are_normalised() {
        for phase in [Phase::Isotropic, Phase::HenyeyGreenstein(0.1), Phase::HenyeyGreenstein(-0.6), Phase::Rayleigh] {
            let mut sum = 0.0;
            let n = 20_000;
            for k in 0..n {
                let c = -1.0 + 2.0 * (k as f64 + 0.5) / n as f64;
                assert!((phase_value(phase, c) - phase.eval(c)).abs() <= 1e-14 * phase.eval(c));
                sum += phase_value(phase, c) * 2.0 * PI * 2.0 / n as f64;
            }
            assert!((sum - 1.0).abs() < 1e-6, "{phase:?}: {sum}");
        }
    }

    /// Albedo 0: every path returns exactly the transmittance of the cube times the background
    /// seen along +y, `exp(-sigma_t) c0`, in closed form.
    #[test]
    fn albedo_zero_is_pure_transmittance() {
        let m = BoxMedium { sigma_t: 1.7, ..medium("albedo-0") };
        let mut rng = StreamKey { seed: 1, testbed: "t", estimator: "e", budget: 0, rep: 0, integral: 0 }.rng();
        for i in [0, 37, 255] {
            let (o, w) = camera_ray(16, i);
            let v = radiance(&m, o, w, &mut rng);
            let want = m.background.c0 * (-1.7f64).exp();
            for c in 0..3 {
                assert!((v[c] - want[c]).abs() <= 1e-14, "pixel {i}: {v:?} vs {want:?}");
            }
        }
    }

    /// White furnace (albedo 1, constant background): the mean is `c0` within its error.
    #[test]
    fn furnace_mean_is_c0() {
        let m = medium("furnace");
        let (mean, se) = pixel(&m, 4, 5, 2000, "furnace");
        for c in 0..3 {
            let z = (mean[c] - m.background.c0[c]) / se[c];
            assert!(z.abs() < 5.0, "channel {c}: {} +- {} vs {}", mean[c], se[c], m.background.c0[c]);
        }
    }

    /// Thin medium (sigma_t = 0.05, isotropic, albedo 1): the radiance through the centre is
    /// `T L_b(+y) + (1 - T) <L_b>` up to the attenuation of the once-scattered light, which is at
    /// most `(1 - T) (1 - exp(-sigma_t sqrt 3)) max L_b` (albedo 1: no radiance exceeds `max L_b`).
    #[test]
    fn thin_medium_single_scattering() {
        let m = BoxMedium {
            sigma_t: 0.05,
            albedo: 1.0,
            phase: Phase::Isotropic,
            background: medium("albedo-1").background,
        };
        let (mean, se) = pixel(&m, 1, 0, 4000, "thin");
        // Green: c0 0.8, c1 1.2, c2 0: clamped where w_z < -2/3; <max(0, 0.8 + 1.2 z)> over the
        // sphere = int_{-2/3}^1 (0.8 + 1.2 z) dz / 2 = (0.8 * 5/3 + 0.6 (1 - 4/9)) / 2.
        let avg = (0.8 * 5.0 / 3.0 + 0.6 * (1.0 - 4.0 / 9.0)) / 2.0;
        let t = (-0.05f64).exp();
        let first = t * 0.8 + (1.0 - t) * avg;
        let bound = (1.0 - t) * (1.0 - (-0.05 * 3f64.sqrt()).exp()) * 2.0;
        assert!((mean[1] - first).abs() < bound + 5.0 * se[1], "{} +- {} vs {first} (bound {bound})", mean[1], se[1]);
    }

    /// The stored reference does not depend on the thread count and is reproducible.
    #[test]
    fn reference_is_deterministic_and_thread_independent() {
        let p = Params::new().with("resolution", 2.0);
        let a = compute_reference("hg-0.1", &p, Some(640), 1).unwrap().1;
        let b = compute_reference("hg-0.1", &p, Some(640), 3).unwrap().1;
        assert_eq!(a.reference.value, b.reference.value);
        assert_eq!(a.reference.std_err, b.reference.std_err);
        assert!(a.command.contains("independent expected-value walk"));
    }
}

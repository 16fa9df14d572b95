//! The tracker loop for a constant sampling extinction and no main part: paper 002's
//! `Transmittance` algorithm (§4.2) with free flights from a constant `sigma_samp` (Eq. 4 with a
//! constant density: `s += -ln(1 - xi) / sigma_samp`) and a rule of [`interact`] at each
//! interaction, `r = sigma_t / sigma_samp`. This is what delta, ratio and single-particle tracking
//! and the double particle model without a control variate run. It is [`track`] with the general
//! density's per-step `eval` and `solve`, the main part and the observer taken out, and each
//! step's next free flight computed before the step's fetch so the two overlap: the same random
//! numbers drawn in the same order and the same arithmetic, so every estimate is bit-identical to
//! [`track`]'s (the tests below compare them ray by ray, with the generators' states).

use super::{interact, track, Rule, ScaledWeight};
use crate::error::EstimateError;
use crate::rng::StreamRng;
use crate::samplers::free_flight::SamplingDensity;
use crate::task::MediumProbe;
use rand::Rng;

/// [`track`] with `SamplingDensity::constant(sigma)`, no main part and no observer: the weight of
/// the transmitted particle on `[t0, t1]` of the probe's ray `origin + s dir`. Falls back to
/// [`track`] when the segment starts before 0 (where the constant density's first knot splits a
/// flight) or the density is not positive (no interaction). Always inlined, so a caller's
/// constant `rule` is folded into its own copy of the loop.
#[inline(always)]
pub fn track_constant(
    probe: &MediumProbe<'_>,
    seg: (f64, f64),
    sigma: f64,
    rule: Rule,
    rng: &mut StreamRng,
) -> Result<f64, EstimateError> {
    let v = sigma.max(0.0);
    if !(seg.0 >= 0.0 && v > 0.0) {
        return general(probe, seg, sigma, rule, rng);
    }
    // A local copy of the generator stays in registers across the fetch (an opaque call), instead
    // of being stored back to the caller's memory at every draw.
    let mut local = rng.clone();
    let weight = steps(probe, seg, v, rule, &mut local);
    *rng = local;
    weight.map(ScaledWeight::value)
}

/// [`track`] with the constant density: the fallback of [`track_constant`], kept out of line.
#[cold]
#[inline(never)]
fn general(
    probe: &MediumProbe<'_>,
    seg: (f64, f64),
    sigma: f64,
    rule: Rule,
    rng: &mut StreamRng,
) -> Result<f64, EstimateError> {
    let line = (probe.ray().origin, probe.ray().dir);
    track(probe, line, seg, &SamplingDensity::constant(sigma), None, rule, rng, |_| ())
}

/// The loop of [`track_constant`] from `t0 >= 0` to `t1` with the density `v > 0`
/// (`SamplingDensity::constant(sigma)` holds `sigma.max(0)`).
///
/// The generator is drawn in [`track`]'s order (each step's flight, then its interaction's
/// number), but each step's next flight is computed before the step's fetch, from a copy of the
/// generator that is kept only when the particle goes on: the two long calls (`ln_1p` and the
/// fetch) do not depend on each other, so the processor overlaps them.
#[inline(always)]
fn steps(
    probe: &MediumProbe<'_>,
    (t0, t1): (f64, f64),
    v: f64,
    rule: Rule,
    rng: &mut StreamRng,
) -> Result<ScaledWeight, EstimateError> {
    // Read through the probe at each step rather than copied per ray.
    let ray = probe.ray();
    let (mut e, mut k) = (1.0f64, 0i32);
    // `solve` ends a flight at `s + x` if `x` is finite, else at +inf: for `v > 0`, `x` is in
    // `[0, +inf]`, so that is `s + x` itself (never NaN), one addition and no finiteness test.
    let mut s = t0 + flight(rng, v);
    if s >= t1 {
        return Ok(ScaledWeight { e, k });
    }
    loop {
        let xi = rng.gen::<f64>();
        let mut ahead = rng.clone();
        let next = s + flight(&mut ahead, v);
        // `sigma_diff = sigma_t - 0` is `sigma_t` bit for bit, and the density's `eval` is `v`.
        let sigma_t = probe.sigma_t(ray.origin + ray.dir * s);
        e *= interact(rule, sigma_t / v, xi)?;
        if e == 0.0 {
            return Ok(ScaledWeight { e: 0.0, k: 0 });
        }
        if e.abs() > ScaledWeight::BIG {
            (e, k) = ScaledWeight::rescale(e, k);
        }
        *rng = ahead;
        if next >= t1 {
            return Ok(ScaledWeight { e, k });
        }
        s = next;
    }
}

/// One free-flight length `x = tau / v`, `tau = -ln(1 - xi)` (Eq. 4 on the constant density's last,
/// infinite piece, which holds every `s >= 0`: `SamplingDensity::solve`'s arithmetic).
#[inline(always)]
fn flight(rng: &mut StreamRng, v: f64) -> f64 {
    let tau = -(-rng.gen::<f64>()).ln_1p();
    tau / v
}

#[cfg(test)]
mod tests {
    use super::super::track;
    use super::*;
    use crate::budget::Budget;
    use crate::media::{Field, MediumBed};
    use crate::params::Params;
    use crate::rng::stream;
    use crate::task::Task;
    use crate::testbed::TestBed;

    fn bed(field: Field, variant: &str, params: Params) -> MediumBed {
        MediumBed::without_reference(field, variant, &params).expect("bed")
    }

    /// Both loops on every integral of `bed` for each rule and density: equal weights bit for bit,
    /// equal fetch counts, and the generators left in the same state; also from segment starts
    /// below 0 (the fallback) and on sub-segments.
    fn same_as_general(bed: &MediumBed, rays: usize) -> usize {
        let a = bed.medium().expect("medium").albedo();
        let rules = [Rule::Double, Rule::Delta, Rule::Terminating { a }, Rule::NonTerminating { a }];
        let mut compared = 0;
        for i in 0..bed.integrals() {
            let budget = Budget::samples(1).unwrap();
            let (fast_task, general_task) = (Task::new(bed, i, budget), Task::new(bed, i, budget));
            let (fast, general) = (fast_task.medium().unwrap(), general_task.medium().unwrap());
            let Some((t0, t1)) = super::super::segment(&fast) else { continue };
            let line = (fast.ray().origin, fast.ray().dir);
            let majorant = fast.majorant();
            for (j, rule) in rules.into_iter().enumerate() {
                for sigma in [majorant, 1.7 * majorant, 0.4 * majorant, 0.05 * majorant, 0.0] {
                    for seg in [(t0, t1), (t0 - 0.5, t1), (0.5 * (t0 + t1), t1)] {
                        let label = format!("ray {i} rule {rule:?} sigma {sigma} seg {seg:?}");
                        let mut rng_fast = stream(i as u64 * 8 + j as u64, "constant path");
                        let mut rng_general = rng_fast.clone();
                        let density = SamplingDensity::constant(sigma);
                        for _ in 0..rays {
                            let w_fast = track_constant(&fast, seg, sigma, rule, &mut rng_fast);
                            let w_general = track(&general, line, seg, &density, None, rule, &mut rng_general, |_| ());
                            match (w_fast, w_general) {
                                (Ok(x), Ok(y)) => assert_eq!(x.to_bits(), y.to_bits(), "{label}: {x} vs {y}"),
                                (Err(x), Err(y)) => assert_eq!(x.to_string(), y.to_string(), "{label}"),
                                (x, y) => panic!("{label}: {x:?} vs {y:?}"),
                            }
                            assert_eq!(rng_fast.gen::<u64>(), rng_general.gen::<u64>(), "{label}: generator state");
                            compared += 1;
                        }
                        assert_eq!(fast_task.costs(), general_task.costs(), "{label}: fetch counts");
                    }
                }
            }
        }
        compared
    }

    /// The constant-density loop is the general one bit for bit: eq21-medium's central ray and
    /// image rays (some miss the sphere) and perlin-medium, every rule (refusals included), majorant
    /// and non-majorant densities, zero density, and a thick medium whose double-particle weights
    /// overflow f64 and are rescaled.
    #[test]
    fn constant_path_is_the_general_path_bit_for_bit() {
        let points = Params::new().with("points", 6.0);
        let mut n = same_as_general(&bed(Field::Eq21, "central-ray", points.clone()), 40);
        n += same_as_general(&bed(Field::Eq21, "transmittance", Params::new().with("resolution", 4.0)), 10);
        n += same_as_general(&bed(Field::Perlin, "central-ray", Params::new().with("points", 2.0)), 10);
        let thick = bed(Field::Eq21, "central-ray", Params::new().with("points", 2.0).with("scale", 1500.0));
        n += same_as_general(&thick, 3);
        assert!(n > 10_000, "{n} rays compared");
    }

    /// The rescaling bound is `2^512`, as the general loop computed it.
    #[test]
    fn rescale_bound_is_two_to_the_512() {
        assert_eq!(ScaledWeight::BIG, 2f64.powi(ScaledWeight::RESCALE));
        assert_eq!(ScaledWeight::rescale(ScaledWeight::BIG * 3.0, 0), (3.0, ScaledWeight::RESCALE));
    }

    /// The thick case does reach the rescaled range (a weight beyond 2^512) on the constant path.
    #[test]
    fn thick_medium_rescales_on_the_constant_path() {
        let thick = bed(Field::Eq21, "central-ray", Params::new().with("points", 2.0).with("scale", 1500.0));
        let task = Task::new(&thick, 1, Budget::samples(1).unwrap());
        let probe = task.medium().unwrap();
        let seg = super::super::segment(&probe).unwrap();
        let mut rng = stream(9, "thick");
        let mut local = rng.clone();
        let w = steps(&probe, seg, 0.05 * probe.majorant(), Rule::Double, &mut local).unwrap();
        assert!(w.k > 0, "weight {w:?} never rescaled");
        assert!(track_constant(&probe, seg, 0.05 * probe.majorant(), Rule::Double, &mut rng).is_ok());
    }
}

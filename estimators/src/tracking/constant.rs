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
use mcbench_core::error::EstimateError;
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::SamplingDensity;
use mcbench_core::task::MediumProbe;
use rand::Rng;

/// [`track`] with `SamplingDensity::constant(sigma)`, no main part and no observer, ray after ray
/// of an estimate: [`ConstantTracker::track`] is the weight of the transmitted particle on
/// `[t0, t1]` of the probe's ray `origin + s dir`.
///
/// The generator is drawn in [`track`]'s order (each step's flight, then its interaction's
/// number), but each step's next flight is computed before the step's fetch, from a copy of the
/// generator that is kept only when it is used: the two long calls (`ln_1p` and the fetch) do not
/// depend on each other, so the processor overlaps them. When the particle is absorbed, the flight
/// drawn ahead is the next draw [`track`] would make, the first flight of the next ray: the
/// tracker keeps it, with the generator's state before and after it, and the next ray starts with
/// it if it has the same density and is given the generator in that state (a flight's length
/// `-ln(1 - xi) / sigma` does not depend on where it starts).
#[derive(Default)]
pub struct ConstantTracker {
    drawn: Option<Drawn>,
}

/// A free flight drawn ahead: the generator before and after its draw, the density and the
/// flight's length.
struct Drawn {
    from: StreamRng,
    to: StreamRng,
    v: f64,
    x: f64,
}

impl ConstantTracker {
    /// One ray's weight with the constant density `sigma` and `rule` at every interaction. Falls
    /// back to [`track`] when the segment starts before 0 (where the constant density's first knot
    /// splits a flight) or the density is not positive (no interaction). Always inlined, so a
    /// caller's constant `rule` is folded into its own copy of the loop.
    #[inline(always)]
    pub fn track(
        &mut self,
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
        // A local copy of the generator stays in registers across the fetch (an opaque call),
        // instead of being stored back to the caller's memory at every draw.
        let mut local = rng.clone();
        let first = match self.drawn.take() {
            Some(d) if d.v == v && d.from == local => {
                local = d.to;
                d.x
            }
            _ => flight(&mut local, v),
        };
        let weight = self.steps(probe, seg, (v, rule), first, &mut local);
        *rng = local;
        weight.map(ScaledWeight::value)
    }

    /// The loop of [`ConstantTracker::track`] from `t0 >= 0` to `t1` with the density `v > 0`
    /// (`SamplingDensity::constant(sigma)` holds `sigma.max(0)`), the first flight `first` drawn.
    #[inline(always)]
    fn steps(
        &mut self,
        probe: &MediumProbe<'_>,
        (t0, t1): (f64, f64),
        (v, rule): (f64, Rule),
        first: f64,
        rng: &mut StreamRng,
    ) -> Result<ScaledWeight, EstimateError> {
        // Read through the probe at each step rather than copied per ray.
        let ray = probe.ray();
        let (mut e, mut k) = (1.0f64, 0i32);
        // `solve` ends a flight at `s + x` if `x` is finite, else at +inf: for `v > 0`, `x` is in
        // `[0, +inf]`, so that is `s + x` itself (never NaN), one addition and no finiteness test.
        let mut s = t0 + first;
        if s >= t1 {
            return Ok(ScaledWeight { e, k });
        }
        loop {
            let xi = rng.gen::<f64>();
            let mut ahead = rng.clone();
            let x = flight(&mut ahead, v);
            // `sigma_diff = sigma_t - 0` is `sigma_t` bit for bit, and the density's `eval` is `v`.
            let sigma_t = probe.sigma_t(ray.origin + ray.dir * s);
            e *= interact(rule, sigma_t / v, xi)?;
            if e == 0.0 {
                self.drawn = Some(Drawn { from: rng.clone(), to: ahead, v, x });
                return Ok(ScaledWeight { e: 0.0, k: 0 });
            }
            if e.abs() > ScaledWeight::BIG {
                (e, k) = ScaledWeight::rescale(e, k);
            }
            *rng = ahead;
            s += x;
            if s >= t1 {
                return Ok(ScaledWeight { e, k });
            }
        }
    }
}

/// [`track`] with the constant density: the fallback of [`ConstantTracker::track`], out of line.
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

/// One free-flight length `x = tau / v`, `tau = -ln(1 - xi)` (Eq. 4 on the constant density's last,
/// infinite piece, which holds every `s >= 0`: `SamplingDensity::solve`'s arithmetic).
#[inline(always)]
fn flight(rng: &mut StreamRng, v: f64) -> f64 {
    let tau = -(-rng.gen::<f64>()).ln_1p();
    tau / v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testbeds::medium::{Field, MediumBed};
    use mcbench_core::budget::Budget;
    use mcbench_core::params::Params;
    use mcbench_core::rng::stream;
    use mcbench_core::task::Task;
    use mcbench_core::testbed::TestBed;

    fn bed(field: Field, variant: &str, params: Params) -> MediumBed {
        MediumBed::without_reference(field, variant, &params).expect("bed")
    }

    /// One sequence of rays on both paths, the ray `n` with the density `sigmas[n % len]` on the
    /// segment `segs[n % len]`, and every `draw_every`-th ray followed by a draw from both
    /// generators (the flight a tracker drew ahead is then not the next draw): equal weights bit
    /// for bit and the generators in the same state after every ray. Returns the rays compared.
    fn sequence(
        (fast, general): (&MediumProbe<'_>, &MediumProbe<'_>),
        (sigmas, segs): (&[f64], &[(f64, f64)]),
        rule: Rule,
        (rays, draw_every): (usize, usize),
        seed: u64,
    ) -> usize {
        let line = (fast.ray().origin, fast.ray().dir);
        let mut tracker = ConstantTracker::default();
        let mut rng_fast = stream(seed, "constant path");
        let mut rng_general = rng_fast.clone();
        for n in 0..rays {
            let (sigma, seg) = (sigmas[n % sigmas.len()], segs[n % segs.len()]);
            let label = format!("ray {n} rule {rule:?} sigma {sigma} seg {seg:?}");
            let w_fast = tracker.track(fast, seg, sigma, rule, &mut rng_fast);
            let density = SamplingDensity::constant(sigma);
            let w_general = track(general, line, seg, &density, None, rule, &mut rng_general, |_| ());
            match (w_fast, w_general) {
                (Ok(x), Ok(y)) => assert_eq!(x.to_bits(), y.to_bits(), "{label}: {x} vs {y}"),
                (Err(x), Err(y)) => assert_eq!(x.to_string(), y.to_string(), "{label}"),
                (x, y) => panic!("{label}: {x:?} vs {y:?}"),
            }
            assert!(rng_fast == rng_general, "{label}: generator states differ");
            if n % draw_every == draw_every - 1 {
                assert_eq!(rng_fast.gen::<u64>(), rng_general.gen::<u64>());
            }
        }
        rays
    }

    /// Both paths on every integral of `bed` for each rule and density (one density per sequence,
    /// and two alternating), on the segment, from a start below 0 (the fallback) and from its
    /// middle, in turn: equal weights, generator states and fetch counts.
    fn same_as_general(bed: &MediumBed, rays: usize) -> usize {
        let a = bed.medium().expect("medium").albedo();
        let rules = [Rule::Double, Rule::Delta, Rule::Terminating { a }, Rule::NonTerminating { a }];
        let mut compared = 0;
        for i in 0..bed.integrals() {
            let budget = Budget::samples(1).unwrap();
            let (fast_task, general_task) = (Task::new(bed, i, budget), Task::new(bed, i, budget));
            let (fast, general) = (fast_task.medium().unwrap(), general_task.medium().unwrap());
            let Some((t0, t1)) = super::super::segment(&fast) else { continue };
            let m = fast.majorant();
            let segs = [(t0, t1), (t0 - 0.5, t1), (0.5 * (t0 + t1), t1)];
            for (j, rule) in rules.into_iter().enumerate() {
                let seed = 64 * i as u64 + 8 * j as u64;
                for (l, sigma) in [m, 1.7 * m, 0.4 * m, 0.05 * m, 0.0].into_iter().enumerate() {
                    compared += sequence((&fast, &general), (&[sigma], &segs[..1]), rule, (rays, 5), seed + l as u64);
                    compared += sequence((&fast, &general), (&[sigma], &segs), rule, (rays, 7), seed + l as u64);
                }
                compared += sequence((&fast, &general), (&[m, 0.4 * m], &segs[..1]), rule, (rays, rays), seed + 7);
                assert_eq!(fast_task.costs(), general_task.costs(), "integral {i} rule {rule:?}: fetch counts");
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
        let (mut rng, v) = (stream(9, "thick"), 0.05 * probe.majorant());
        let first = flight(&mut rng, v);
        let w = ConstantTracker::default().steps(&probe, seg, (v, Rule::Double), first, &mut rng).unwrap();
        assert!(w.k > 0, "weight {w:?} never rescaled");
    }
}

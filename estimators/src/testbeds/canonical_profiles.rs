//! The extinction profiles of `canonical-1d`: unit-mean shapes `f` on the segment `[0, 1]`
//! (`int_0^1 f = 1`), so that `sigma_t(t) = tau f(t)` has optical depth `tau` over the segment and
//! the transmittance `T(s) = exp(-tau F(s))` with the closed-form cumulative shape
//! `F(s) = int_0^s f` (paper 002 Eq. 1; the profiles follow the canonical cases of the
//! transmittance harness of Georgiev et al. 2019, extended with a hole and a step).
//!
//! | profile | shape before normalisation | closed form of `F` |
//! |---|---|---|
//! | `constant` | 1 | `s` |
//! | `cosine` | `1 + cos(5 pi t)` (two and a half periods, zero at t = 1/5, 3/5, 1) | `s + sin(5 pi s) / (5 pi)` |
//! | `gaussian` | `0.1 + exp(-(t - 0.5)^2 / (2 0.1^2))` (a bump on a thin floor) | erf |
//! | `hole` | 1, and 0.01 on the gap `[0.35, 0.65]` (a near-empty gap) | piecewise linear |
//! | `linear-up` | `t` | `s^2` |
//! | `linear-down` | `1 - t` | `2 s - s^2` |
//! | `step` | 1 on `[0, 0.4)`, 4 on `[0.4, 1]` | piecewise linear |
//!
//! The step's edge at 0.4 and the hole's gap edges are off the explorer grid `{0, 0.5, 1}` of the
//! control variates and off the grid of a ray marcher with an even number of steps: with an edge
//! on its grid, the number of marching points on each side of the edge does not depend on the
//! random offset and ray marching is exact, a special case rather than the rule. Likewise the
//! cosine has a fractional number of periods: over a whole number `m` of periods the random-offset
//! marcher with `n` steps is exact unless `n` divides `m` (the periodic rectangle rule integrates
//! `cos(2 pi m t)` exactly), which a first version with three periods showed (exact with 2 steps).

use mcbench_core::math::erf;
use std::f64::consts::PI;

/// One canonical extinction profile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Profile {
    /// Homogeneous.
    Constant,
    /// Two and a half periods of a raised cosine touching zero.
    Cosine,
    /// A Gaussian bump (width 0.1) on a floor of a tenth of its height.
    Gaussian,
    /// Homogeneous with a near-empty gap (1% density) over `[0.35, 0.65]`.
    Hole,
    /// Linearly increasing from 0.
    LinearUp,
    /// Linearly decreasing to 0.
    LinearDown,
    /// A step up by a factor 4 at `t = 0.4`.
    Step,
}

const BUMP_CENTRE: f64 = 0.5;
const BUMP_WIDTH: f64 = 0.1;
const BUMP_FLOOR: f64 = 0.1;
const HOLE: (f64, f64) = (0.35, 0.65);
const HOLE_DENSITY: f64 = 0.01;
const STEP_EDGE: f64 = 0.4;
const STEP_HIGH: f64 = 4.0;
const COSINE_FREQ: f64 = 5.0 * PI;

impl Profile {
    /// Every profile, in the order of the test bed's variants.
    pub const ALL: [Profile; 7] = [
        Profile::Constant,
        Profile::Cosine,
        Profile::Gaussian,
        Profile::Hole,
        Profile::LinearUp,
        Profile::LinearDown,
        Profile::Step,
    ];

    /// The name used in variant names.
    pub fn name(self) -> &'static str {
        match self {
            Profile::Constant => "constant",
            Profile::Cosine => "cosine",
            Profile::Gaussian => "gaussian",
            Profile::Hole => "hole",
            Profile::LinearUp => "linear-up",
            Profile::LinearDown => "linear-down",
            Profile::Step => "step",
        }
    }

    /// The profile called `name`.
    pub fn parse(name: &str) -> Option<Profile> {
        Profile::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The shape before normalisation at `s` and its integral from 0 to `s`.
    fn raw(self, s: f64) -> (f64, f64) {
        match self {
            Profile::Constant => (1.0, s),
            Profile::Cosine => (1.0 + (COSINE_FREQ * s).cos(), s + (COSINE_FREQ * s).sin() / COSINE_FREQ),
            Profile::Gaussian => {
                let z = |x: f64| (x - BUMP_CENTRE) / (BUMP_WIDTH * std::f64::consts::SQRT_2);
                let scale = BUMP_WIDTH * (PI / 2.0).sqrt();
                (BUMP_FLOOR + (-z(s) * z(s)).exp(), BUMP_FLOOR * s + scale * (erf(z(s)) - erf(z(0.0))))
            }
            Profile::Hole => {
                let (a, b) = HOLE;
                let f = if (a..=b).contains(&s) { HOLE_DENSITY } else { 1.0 };
                let cum = s.min(a) + HOLE_DENSITY * (s.clamp(a, b) - a) + (s.max(b) - b);
                (f, cum)
            }
            Profile::LinearUp => (s, 0.5 * s * s),
            Profile::LinearDown => (1.0 - s, s - 0.5 * s * s),
            Profile::Step => {
                let f = if s < STEP_EDGE { 1.0 } else { STEP_HIGH };
                (f, s.min(STEP_EDGE) + STEP_HIGH * (s.max(STEP_EDGE) - STEP_EDGE))
            }
        }
    }

    /// The integral of the raw shape over `[0, 1]` (the normaliser).
    fn mass(self) -> f64 {
        self.raw(1.0).1
    }

    /// The unit-mean shape `f(t)` for `t` in `[0, 1]`.
    pub fn shape(self, t: f64) -> f64 {
        self.raw(t).0 / self.mass()
    }

    /// The closed-form `F(s) = int_0^s f` for `s` in `[0, 1]` (`F(1) = 1`).
    pub fn cumulative(self, s: f64) -> f64 {
        self.raw(s).1 / self.mass()
    }

    /// The maximum of `f` over `[0, 1]` (so `tau x peak` is the tight majorant).
    pub fn peak(self) -> f64 {
        let raw_max = match self {
            Profile::Constant | Profile::Hole | Profile::LinearUp | Profile::LinearDown => 1.0,
            Profile::Cosine => 2.0,
            Profile::Gaussian => BUMP_FLOOR + 1.0,
            Profile::Step => STEP_HIGH,
        };
        raw_max / self.mass()
    }

    /// Where `f` jumps or has a kink inside `(0, 1)` (breakpoints for quadrature).
    pub fn breaks(self) -> Vec<f64> {
        match self {
            Profile::Hole => vec![HOLE.0, HOLE.1],
            Profile::Step => vec![STEP_EDGE],
            Profile::Cosine => (1..5).map(|k| k as f64 / 5.0).collect(),
            Profile::Gaussian => vec![BUMP_CENTRE - 2.0 * BUMP_WIDTH, BUMP_CENTRE, BUMP_CENTRE + 2.0 * BUMP_WIDTH],
            Profile::Constant | Profile::LinearUp | Profile::LinearDown => Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::quadrature::gauss_kronrod_multi;

    fn quad(p: Profile, s: f64) -> f64 {
        let mut breaks = vec![0.0];
        breaks.extend(p.breaks().into_iter().filter(|&b| b < s));
        breaks.push(s);
        gauss_kronrod_multi(|t| [p.shape(t)], &breaks, 1e-15, 1e-15, 50).value[0]
    }

    /// The closed forms agree with adaptive quadrature of the shape to 1e-13, every shape has unit
    /// mean, and the peak is the maximum of the shape (checked on a fine grid, never exceeded).
    #[test]
    fn closed_forms_match_quadrature_and_peaks_bound_the_shapes() {
        for p in Profile::ALL {
            assert!((p.cumulative(1.0) - 1.0).abs() < 1e-14, "{p:?}");
            for s in [0.1, 0.25, 0.37, 0.5, 0.61, 0.9, 1.0] {
                let (c, q) = (p.cumulative(s), quad(p, s));
                assert!((c - q).abs() < 1e-13, "{p:?} F({s}) = {c} vs quadrature {q}");
            }
            let grid_max = (0..=100_000).map(|k| p.shape(k as f64 / 1e5)).fold(0.0, f64::max);
            assert!(grid_max <= p.peak() * (1.0 + 1e-15), "{p:?}: {grid_max} > {}", p.peak());
            assert!(grid_max >= p.peak() * (1.0 - 1e-6), "{p:?}: peak {} not reached ({grid_max})", p.peak());
            assert!((0..=1000).all(|k| p.shape(k as f64 / 1e3) >= 0.0));
            assert_eq!(Profile::parse(p.name()), Some(p));
        }
        assert_eq!(Profile::parse("flat"), None);
    }
}

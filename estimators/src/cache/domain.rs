//! The directional domains of the radiance caches and their equal-solid-angle parameterisation.
//!
//! Paper 001 §4.1 (hemisphere, surfaces): `s = phi / 2 pi`, `t = 1 - cos(theta)`; paper 000 §4.1
//! (sphere, media): `s = phi / 2 pi`, `t = (1 - cos(theta)) / 2`. In both, `d omega` is a constant
//! times `ds dt`, so a regular partition of the unit square gives cells of equal solid angle.

use mcbench_core::math::Vec3;
use mcbench_core::samplers::spherical_direction;
use std::f64::consts::{PI, TAU};

/// A point of the unit parameter square: `s` is the azimuth, `t` the polar coordinate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct St {
    /// `phi / 2 pi` in `[0, 1)`.
    pub s: f64,
    /// `1 - cos(theta)` (hemisphere) or `(1 - cos(theta)) / 2` (sphere), in `[0, 1]`.
    pub t: f64,
}

/// The domain of a cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    /// The upper hemisphere about local +z (paper 001, surfaces). Polar value at the pole `t = 0`;
    /// the horizon `t = 1` is implied zero because the integrand carries `cos(theta)` (§4.1).
    Hemisphere,
    /// The whole sphere (paper 000, media). Polar values at both poles `t = 0` and `t = 1`.
    Sphere,
}

impl Domain {
    /// Total solid angle: `2 pi` or `4 pi`.
    pub fn measure(self) -> f64 {
        match self {
            Domain::Hemisphere => TAU,
            Domain::Sphere => 2.0 * TAU,
        }
    }
    /// The resolution `(ns, nt)` a cache starts with: one cell on the hemisphere (paper 001 §4.3),
    /// two cells in `s` on the sphere (paper 000 §4.3).
    pub fn initial_resolution(self) -> (usize, usize) {
        match self {
            Domain::Hemisphere => (1, 1),
            Domain::Sphere => (2, 1),
        }
    }
    /// True when `t = 1` is a pole with its own polar value; false when it is the horizon where the
    /// reconstruction falls linearly to zero (paper 001 §4.1).
    pub fn has_bottom_pole(self) -> bool {
        matches!(self, Domain::Sphere)
    }
    /// Solid angle of one cell at resolution `ns x nt`.
    pub fn cell_solid_angle(self, ns: usize, nt: usize) -> f64 {
        self.measure() / (ns * nt) as f64
    }
    /// The parameters of a unit direction in the local frame (+z the normal or the pole). On the
    /// hemisphere, directions below the horizon give `None`.
    pub fn st_of(self, local: Vec3) -> Option<St> {
        let t = match self {
            Domain::Hemisphere if local.z <= 0.0 => return None,
            Domain::Hemisphere => 1.0 - local.z,
            Domain::Sphere => 0.5 * (1.0 - local.z.clamp(-1.0, 1.0)),
        };
        let s = (local.y.atan2(local.x) / TAU).rem_euclid(1.0);
        // rem_euclid may return exactly 1.0 for tiny negative inputs.
        Some(St { s: if s >= 1.0 { 0.0 } else { s }, t: t.clamp(0.0, 1.0) })
    }
    /// The unit local direction of parameters `st`.
    pub fn direction(self, st: St) -> Vec3 {
        let cos_theta = match self {
            Domain::Hemisphere => 1.0 - st.t,
            Domain::Sphere => 1.0 - 2.0 * st.t,
        };
        spherical_direction(cos_theta, 2.0 * PI * st.s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_round_trip_and_cells_have_equal_solid_angle() {
        for domain in [Domain::Hemisphere, Domain::Sphere] {
            for &(s, t) in &[(0.1, 0.2), (0.9, 0.7), (0.5, 0.999), (0.0, 0.0)] {
                let st = St { s, t };
                let back = domain.st_of(domain.direction(st)).unwrap();
                assert!((back.t - t).abs() < 1e-12, "{domain:?} {st:?} {back:?}");
                if t > 0.0 {
                    assert!((back.s - s).abs() < 1e-12, "{domain:?} {st:?} {back:?}");
                }
            }
            // Solid angle of a band t in [a, b]: 2 pi (cos a' - cos b') is linear in t.
            let band = |t0: f64, t1: f64| {
                let c = |t: f64| domain.direction(St { s: 0.0, t }).z;
                TAU * (c(t0) - c(t1))
            };
            let (a, b) = (band(0.0, 0.25), band(0.5, 0.75));
            assert!((a - b).abs() < 1e-12 && (a - domain.measure() / 4.0).abs() < 1e-12);
        }
        assert_eq!(Domain::Hemisphere.st_of(Vec3::new(0.0, 0.6, -0.8)), None);
        assert_eq!(Domain::Sphere.st_of(Vec3::new(0.0, 0.0, -1.0)).map(|st| st.t), Some(1.0));
    }
}

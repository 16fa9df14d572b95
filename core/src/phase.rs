//! Phase functions of participating media (paper 000 Eq. 5, book: testbeds.md): isotropic,
//! Henyey-Greenstein and Rayleigh, each with an exact sampler.
//!
//! Convention: `cos` is the cosine between the propagation direction *before* and *after* the
//! scattering event. A path traced from the camera along `d` that continues along `d'` sees light
//! travelling `-d'` then `-d`, whose scattering cosine is again `d . d'`, so estimators may use
//! path directions directly. Every phase function here is normalised over the sphere.

use crate::math::{Frame, Vec3};
use crate::samplers::spherical_direction;
use rand::Rng;
use std::f64::consts::PI;

/// A phase function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// `1 / 4 pi`.
    Isotropic,
    /// Henyey-Greenstein with asymmetry `g` in `(-1, 1)`.
    HenyeyGreenstein(f64),
    /// Rayleigh `3 / (16 pi) (1 + cos^2)`.
    Rayleigh,
}

/// The isotropic density `1 / 4 pi`.
pub const ISOTROPIC: f64 = 1.0 / (4.0 * PI);

impl Phase {
    /// The density per unit solid angle at scattering cosine `cos`.
    pub fn eval(self, cos: f64) -> f64 {
        match self {
            Phase::Isotropic => ISOTROPIC,
            Phase::HenyeyGreenstein(g) => {
                let d = 1.0 + g * g - 2.0 * g * cos;
                ISOTROPIC * (1.0 - g * g) / (d * d.sqrt())
            }
            Phase::Rayleigh => 3.0 / (16.0 * PI) * (1.0 + cos * cos),
        }
    }

    /// A scattering cosine drawn from the phase function.
    pub fn sample_cos<R: Rng + ?Sized>(self, rng: &mut R) -> f64 {
        let u: f64 = rng.gen();
        match self {
            Phase::Isotropic => 1.0 - 2.0 * u,
            Phase::HenyeyGreenstein(g) if g.abs() < 1e-6 => 1.0 - 2.0 * u,
            Phase::HenyeyGreenstein(g) => {
                // Inverse CDF of HG in cos (Pharr et al.), with the sign convention that g > 0 is
                // forward scattering (cos near +1).
                let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
                ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
            }
            Phase::Rayleigh => {
                // CDF (cos^3 + 3 cos + 4) / 8 = u: Cardano's solution of the depressed cubic.
                let q = 4.0 * (2.0 * u - 1.0);
                let r = (q * q / 4.0 + 1.0).sqrt();
                ((q / 2.0 + r).cbrt() - (r - q / 2.0).cbrt()).clamp(-1.0, 1.0)
            }
        }
    }

    /// A new unit direction drawn from the phase function around the unit propagation direction
    /// `dir`, with the phase function's value at the drawn scattering cosine. Two random numbers:
    /// the cosine ([`Phase::sample_cos`]), then the azimuth `phi = 2 pi u`.
    ///
    /// A uniform cosine (isotropic, and Henyey-Greenstein with `|g| < 1e-6`, which
    /// [`Phase::sample_cos`] draws as isotropic) gives a direction uniform on the sphere whatever
    /// the axis, so it is built directly in world coordinates (`z = cos`, azimuth `phi` about
    /// `+z`) with no frame around `dir`; other phase functions rotate the local direction into
    /// the frame around `dir` (Duff et al. 2017).
    pub fn sample<R: Rng + ?Sized>(self, dir: Vec3, rng: &mut R) -> (Vec3, f64) {
        let cos = self.sample_cos(rng);
        let phi = 2.0 * PI * rng.gen::<f64>();
        let local = spherical_direction(cos, phi);
        match self {
            Phase::Isotropic => (local, ISOTROPIC),
            Phase::HenyeyGreenstein(g) if g.abs() < 1e-6 => (local, self.eval(dir.dot(local))),
            _ => (Frame::around(dir).to_world(local), self.eval(cos)),
        }
    }

    /// A short name for tables (`isotropic`, `hg(0.1)`, `rayleigh`).
    pub fn name(self) -> String {
        match self {
            Phase::Isotropic => "isotropic".into(),
            Phase::HenyeyGreenstein(g) => format!("hg({g})"),
            Phase::Rayleigh => "rayleigh".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samplers::testing::{sampler_chi_square, SphereGrid};

    /// Every phase function integrates to one (Gauss-Legendre in cos, exact in phi).
    #[test]
    fn phase_functions_are_normalised() {
        for phase in [Phase::Isotropic, Phase::HenyeyGreenstein(0.1), Phase::HenyeyGreenstein(-0.7), Phase::Rayleigh] {
            let (x, w) = crate::quadrature::gauss_legendre(64);
            let total: f64 = x.iter().zip(&w).map(|(&c, &wi)| wi * 2.0 * PI * phase.eval(c)).sum();
            assert!((total - 1.0).abs() < 1e-9, "{phase:?}: {total}");
        }
    }

    /// A uniform cosine draws in world coordinates: the same numbers give the same direction
    /// whatever the propagation direction (isotropic and near-zero `g`), with `z` the drawn cosine;
    /// HG(0.1) still turns with `dir`.
    #[test]
    fn uniform_cosines_draw_without_a_frame() {
        use crate::rng::StreamKey;
        let key = StreamKey { seed: 5, testbed: "t", estimator: "e", budget: 0, rep: 0, integral: 0 };
        let dirs = [Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.3, -0.5, 0.8).normalize()];
        for phase in [Phase::Isotropic, Phase::HenyeyGreenstein(1e-7)] {
            let draws: Vec<Vec3> = dirs.iter().map(|&d| phase.sample(d, &mut key.rng()).0).collect();
            assert!(draws.iter().all(|&w| w == draws[0]), "{phase:?}: {draws:?}");
            let u: f64 = key.rng().gen();
            assert_eq!(draws[0].z, 1.0 - 2.0 * u, "{phase:?}");
        }
        let hg = Phase::HenyeyGreenstein(0.1);
        assert_ne!(hg.sample(dirs[0], &mut key.rng()).0, hg.sample(dirs[1], &mut key.rng()).0);
    }

    /// Teeth: HG(0.1) samples checked against the isotropic density are rejected.
    #[test]
    fn chi_square_rejects_the_wrong_phase() {
        let dir = Vec3::new(0.0, 0.0, 1.0);
        let phase = Phase::HenyeyGreenstein(0.1);
        let c = sampler_chi_square(&SphereGrid::full(16, 8), 200_000, 9, |r| phase.sample(dir, r).0, |_| ISOTROPIC);
        assert!(c.p_value < 1e-6, "p = {}", c.p_value);
    }
}

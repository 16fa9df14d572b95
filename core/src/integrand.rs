//! Generic integrands (book: extending.md): one function on a named [`Domain`], with its exact
//! value when it has one. [`crate::integrand_bed`] turns an integrand into a test bed that
//! provides [`crate::Needs::INTEGRAND`]; estimators reach it through the counted
//! [`crate::task::IntegrandProbe`] of [`crate::Task::integrand`] (one sample per evaluation).
//!
//! ```
//! use mcbench_core::integrand::{Domain, Integrand};
//!
//! /// `x y` on the unit square: 1/4.
//! struct Product;
//! impl Integrand for Product {
//!     fn domain(&self) -> Domain {
//!         Domain::UnitCube(2)
//!     }
//!     fn eval(&self, x: &[f64]) -> f64 {
//!         x[0] * x[1]
//!     }
//!     fn exact(&self) -> Option<f64> {
//!         Some(0.25)
//!     }
//! }
//! assert_eq!(Product.eval(&[0.5, 0.5]), 0.25);
//! assert_eq!(Product.domain().measure(), 1.0);
//! ```

use crate::error::ConfigError;
use crate::samplers::{cosine_hemisphere, uniform_hemisphere};
use rand::Rng;
use std::f64::consts::PI;

/// Where an integrand lives and the measure it is integrated against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    /// The unit hypercube `[0, 1]^d` with the Lebesgue measure (volume 1); points have `d`
    /// coordinates.
    UnitCube(usize),
    /// The unit sphere with the solid-angle measure (area `4 pi`); points are unit vectors
    /// `(x, y, z)`.
    Sphere,
    /// The upper hemisphere (`z >= 0`) with the projected solid-angle measure `cos(theta) dw`
    /// (mass `pi`): `int f(w) cos(theta) dw`; points are unit vectors `(x, y, z)`.
    CosineHemisphere,
}

impl Domain {
    /// The largest dimension of a [`Domain::UnitCube`].
    pub const MAX_DIM: usize = 64;

    /// Coordinates of a point: `d` on the cube, 3 on the sphere and hemisphere.
    pub fn dim(&self) -> usize {
        match self {
            Domain::UnitCube(d) => *d,
            Domain::Sphere | Domain::CosineHemisphere => 3,
        }
    }

    /// The total mass of the measure: 1, `4 pi`, `pi`.
    pub fn measure(&self) -> f64 {
        match self {
            Domain::UnitCube(_) => 1.0,
            Domain::Sphere => 4.0 * PI,
            Domain::CosineHemisphere => PI,
        }
    }

    /// Checks the domain (a cube of 1 to [`Domain::MAX_DIM`] dimensions); `owner` names the bed.
    pub fn check(&self, owner: &str) -> Result<(), ConfigError> {
        match self {
            Domain::UnitCube(d) if !(1..=Self::MAX_DIM).contains(d) => Err(ConfigError::invalid(
                format!("{owner} domain"),
                format!("UnitCube({d})"),
                format!("a cube has 1 to {} dimensions", Self::MAX_DIM),
            )),
            _ => Ok(()),
        }
    }

    /// A point drawn with density `1 / measure` with respect to the domain's measure, written
    /// into `x` (of length [`Domain::dim`]): uniform on the cube and the sphere (the
    /// `uniform_hemisphere` sampler mirrored with probability 1/2), cosine-distributed on the
    /// hemisphere (the `cosine_hemisphere` sampler).
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R, x: &mut [f64]) {
        match self {
            Domain::UnitCube(_) => x.iter_mut().for_each(|c| *c = rng.gen()),
            Domain::Sphere => {
                let w = uniform_hemisphere::sample_local(rng);
                let z = if rng.gen::<bool>() { w.z } else { -w.z };
                x.copy_from_slice(&[w.x, w.y, z]);
            }
            Domain::CosineHemisphere => {
                let w = cosine_hemisphere::sample_local(rng);
                x.copy_from_slice(&[w.x, w.y, w.z]);
            }
        }
    }

    /// The antithetic image of a point: a map of the domain onto itself that keeps its measure
    /// (`1 - x` on the cube, `-w` on the sphere, the azimuth turned by half a turn on the
    /// hemisphere), so the image of a sample has the same distribution.
    pub fn reflect(&self, x: &mut [f64]) {
        match self {
            Domain::UnitCube(_) => x.iter_mut().for_each(|c| *c = 1.0 - *c),
            Domain::Sphere => x.iter_mut().for_each(|c| *c = -*c),
            Domain::CosineHemisphere => {
                x[0] = -x[0];
                x[1] = -x[1];
            }
        }
    }
}

impl std::fmt::Display for Domain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Domain::UnitCube(d) => write!(f, "[0,1]^{d}"),
            Domain::Sphere => write!(f, "sphere"),
            Domain::CosineHemisphere => write!(f, "cosine-weighted hemisphere"),
        }
    }
}

/// One integral `int f dmu` over a [`Domain`]: what a researcher writes to get a test bed
/// ([`crate::integrand_bed::IntegrandBed`]).
pub trait Integrand: Send + Sync {
    /// The domain and its measure.
    fn domain(&self) -> Domain;
    /// `f(x)` at a point of the domain (`x.len()` is [`Domain::dim`]).
    fn eval(&self, x: &[f64]) -> f64;
    /// The exact value of the integral, when it has a closed form; `None` when the harness
    /// computes and stores it (`mcbench reference <bed>`).
    fn exact(&self) -> Option<f64> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    /// The mean of `f` over samples times the measure converges to the integral on every domain:
    /// `z^2` on the sphere (4 pi / 3), `z` against `cos dw` (2 pi / 3), `x0 + x1` on the square (1);
    /// reflected points have the same means.
    #[test]
    fn samples_have_density_one_over_the_measure() {
        type Case = (Domain, fn(&[f64]) -> f64, f64);
        let cases: [Case; 3] = [
            (Domain::Sphere, |x| x[2] * x[2], 4.0 * PI / 3.0),
            (Domain::CosineHemisphere, |x| x[2], 2.0 * PI / 3.0),
            (Domain::UnitCube(2), |x| x[0] + x[1], 1.0),
        ];
        for (domain, f, exact) in cases {
            let mut rng = stream(3, "domain");
            let n = 400_000;
            let mut x = vec![0.0; domain.dim()];
            let (mut sum, mut reflected) = (0.0, 0.0);
            for _ in 0..n {
                domain.sample(&mut rng, &mut x);
                sum += f(&x);
                domain.reflect(&mut x);
                reflected += f(&x);
            }
            for s in [sum, reflected] {
                let est = domain.measure() * s / n as f64;
                assert!((est / exact - 1.0).abs() < 5e-3, "{domain}: {est} vs {exact}");
            }
        }
        assert!(Domain::UnitCube(0).check("bed").is_err() && Domain::UnitCube(65).check("bed").is_err());
        assert!(Domain::UnitCube(3).check("bed").is_ok() && Domain::Sphere.check("bed").is_ok());
    }
}

//! `cosine-power`: a cosine-power lobe `f(w) = cos(theta)^n` on the cosine-weighted hemisphere,
//! `int f(w) cos(theta) dw = 2 pi / (n + 2)`. The `smooth` variant (`n = 3`) is broad; the `stiff`
//! one (`n = 60`) is a narrow lobe that cosine-distributed points rarely hit (relative variance
//! about 15 per sample).

use mcbench_core::entry::{BedCase, TestBedEntry};
use mcbench_core::integrand::{Domain, Integrand};
use mcbench_core::integrand_bed::{self, IntegrandBed};
use mcbench_core::params::ParamSpec;

/// The integrand: exponent `n`.
pub struct CosinePower {
    /// Exponent.
    pub n: i32,
}

impl Integrand for CosinePower {
    fn domain(&self) -> Domain {
        Domain::CosineHemisphere
    }
    fn eval(&self, w: &[f64]) -> f64 {
        w[2].max(0.0).powi(self.n)
    }
    fn exact(&self) -> Option<f64> {
        Some(2.0 * std::f64::consts::PI / f64::from(self.n + 2))
    }
}

impl IntegrandBed for CosinePower {
    const ID: &'static str = "cosine-power";
    const VARIANTS: &'static [&'static str] = &["smooth", "stiff"];
    const SUMMARY: &'static str =
        "cosine-power lobe cos^n on the cosine-weighted hemisphere (n = 3 smooth, 60 stiff), exact";
    fn variant(name: &str) -> Option<Self> {
        match name {
            "smooth" => Some(CosinePower { n: 3 }),
            "stiff" => Some(CosinePower { n: 60 }),
            _ => None,
        }
    }
}

const SMOOTH: [BedCase; 2] = integrand_bed::cases("smooth", 32);
const STIFF: [BedCase; 2] = integrand_bed::cases("stiff", 512);

/// Registry entry.
pub static ENTRY: TestBedEntry = TestBedEntry {
    params: ParamSpec::NONE.display("cosine-power lobe on the hemisphere").words(crate::words::variant),
    ..integrand_bed::entry::<CosinePower>(&[SMOOTH[0], SMOOTH[1], STIFF[0], STIFF[1]])
};

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::quadrature::gauss_legendre;

    /// The closed form against Gauss-Legendre quadrature in `mu = cos(theta)` of
    /// `2 pi int_0^1 mu^n mu dmu` (exact for these polynomial degrees).
    #[test]
    fn closed_form_matches_quadrature() {
        let (nodes, weights) = gauss_legendre(48);
        for variant in CosinePower::VARIANTS {
            let f = CosinePower::variant(variant).unwrap();
            let q: f64 = nodes
                .iter()
                .zip(&weights)
                .map(|(x, w)| {
                    let mu = 0.5 * (x + 1.0);
                    0.5 * w * 2.0 * std::f64::consts::PI * f.eval(&[0.0, (1.0 - mu * mu).sqrt(), mu]) * mu
                })
                .sum();
            let exact = f.exact().unwrap();
            assert!((q / exact - 1.0).abs() < 1e-13, "{variant}: {q} vs {exact}");
        }
    }
}

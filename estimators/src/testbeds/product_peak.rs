//! `product-peak`: Genz's product-peak integrand on the unit cube `[0, 1]^3`,
//! `f(x) = prod_i 1 / (a^-2 + (x_i - u_i)^2)`, whose integral is the closed form
//! `prod_i a (atan(a (1 - u_i)) + atan(a u_i))`. The `smooth` variant (`a = 1.5`) is nearly flat;
//! the `stiff` one (`a = 12`) is a sharp peak whose plain Monte Carlo estimates have a relative
//! variance of about 6 per sample and a long right tail.

use mcbench_core::entry::{BedCase, TestBedEntry};
use mcbench_core::integrand::{Domain, Integrand};
use mcbench_core::integrand_bed::{self, IntegrandBed};
use mcbench_core::params::ParamSpec;

/// The peak's centre `u`.
pub const CENTRE: [f64; 3] = [0.3, 0.62, 0.45];

/// The integrand: sharpness `a` in every dimension.
pub struct ProductPeak {
    /// Sharpness.
    pub a: f64,
}

impl Integrand for ProductPeak {
    fn domain(&self) -> Domain {
        Domain::UnitCube(CENTRE.len())
    }
    fn eval(&self, x: &[f64]) -> f64 {
        x.iter().zip(CENTRE).map(|(x, u)| 1.0 / (self.a.powi(-2) + (x - u) * (x - u))).product()
    }
    fn exact(&self) -> Option<f64> {
        Some(CENTRE.iter().map(|u| self.a * ((self.a * (1.0 - u)).atan() + (self.a * u).atan())).product())
    }
}

impl IntegrandBed for ProductPeak {
    const ID: &'static str = "product-peak";
    const VARIANTS: &'static [&'static str] = &["smooth", "stiff"];
    const SUMMARY: &'static str = "Genz product peak on [0,1]^3 (a = 1.5 smooth, 12 stiff), exact";
    fn variant(name: &str) -> Option<Self> {
        match name {
            "smooth" => Some(ProductPeak { a: 1.5 }),
            "stiff" => Some(ProductPeak { a: 12.0 }),
            _ => None,
        }
    }
}

const SMOOTH: [BedCase; 2] = integrand_bed::cases("smooth", 32);
const STIFF: [BedCase; 2] = integrand_bed::cases("stiff", 512);

/// Registry entry.
pub static ENTRY: TestBedEntry = TestBedEntry {
    params: ParamSpec::NONE.display("Genz product peak on [0,1]^3").words(crate::words::variant),
    ..integrand_bed::entry::<ProductPeak>(&[SMOOTH[0], SMOOTH[1], STIFF[0], STIFF[1]])
};

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::quadrature::gauss_legendre;

    /// The closed form against a composite Gauss-Legendre rule of each one-dimensional factor
    /// (64 panels of 16 nodes), for both variants.
    #[test]
    fn closed_form_matches_quadrature() {
        let (nodes, weights) = gauss_legendre(16);
        for variant in ProductPeak::VARIANTS {
            let f = ProductPeak::variant(variant).unwrap();
            let factor = |u: f64| {
                let panels = 64;
                let h = 1.0 / panels as f64;
                let mut s = 0.0;
                for p in 0..panels {
                    for (x, w) in nodes.iter().zip(&weights) {
                        let t = (p as f64 + 0.5 * (x + 1.0)) * h;
                        s += 0.5 * h * w / (f.a.powi(-2) + (t - u) * (t - u));
                    }
                }
                s
            };
            let quadrature: f64 = CENTRE.iter().map(|&u| factor(u)).product();
            let exact = f.exact().unwrap();
            assert!((quadrature / exact - 1.0).abs() < 1e-12, "{variant}: {quadrature} vs {exact}");
        }
    }
}

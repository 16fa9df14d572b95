//! Equiangular (Cauchy) sampling of a ray parameter (paper 002 §4.3 "source-driven sampling",
//! \[KF12\]): the density `D / ((theta1 - theta0) (D^2 + (t - t_l)^2))` on `[t0, t1]`, which
//! mimics the `1 / r^2` fall-off of a point light at distance `D` from the ray, closest at `t_l`.
//! Sampled exactly by `t = t_l + D tan(theta)`, `theta` uniform in `[theta0, theta1]`.

/// An equiangular density on a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Equiangular {
    t_l: f64,
    d: f64,
    t0: f64,
    t1: f64,
    theta0: f64,
    theta1: f64,
}

impl Equiangular {
    /// The density on `[t0, t1]` for a light at distance `d` from the ray, closest at `t_l`;
    /// `None` when `d` is not positive or the segment is empty (no proper density).
    pub fn new(t_l: f64, d: f64, (t0, t1): (f64, f64)) -> Option<Self> {
        if !(d > 0.0 && t1 > t0) {
            return None;
        }
        let (theta0, theta1) = (((t0 - t_l) / d).atan(), ((t1 - t_l) / d).atan());
        (theta1 > theta0).then_some(Equiangular { t_l, d, t0, t1, theta0, theta1 })
    }
    /// The `t` with CDF value `xi` in `[0, 1)`.
    pub fn sample(&self, xi: f64) -> f64 {
        let theta = self.theta0 + xi * (self.theta1 - self.theta0);
        (self.t_l + self.d * theta.tan()).clamp(self.t0, self.t1)
    }
    /// The density at `t` (zero outside the segment).
    pub fn pdf(&self, t: f64) -> f64 {
        if !(self.t0..=self.t1).contains(&t) {
            return 0.0;
        }
        let u = t - self.t_l;
        self.d / ((self.theta1 - self.theta0) * (self.d * self.d + u * u))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samplers::testing::interval_chi_square;
    use rand::Rng;

    /// Teeth: the same samples against a peak at the wrong place are rejected.
    #[test]
    fn chi_square_rejects_a_shifted_peak() {
        let (e, wrong) = (Equiangular::new(6.0, 0.3, (1.0, 17.0)).unwrap(), Equiangular::new(6.2, 0.3, (1.0, 17.0)));
        let wrong = wrong.unwrap();
        let edges: Vec<f64> = (0..=64).map(|k| 1.0 + 16.0 * k as f64 / 64.0).collect();
        let c = interval_chi_square(&edges, 100_000, 22, |r| e.sample(r.gen()), |t| wrong.pdf(t));
        assert!(c.p_value < 1e-6, "p = {}", c.p_value);
    }

    #[test]
    fn degenerate_geometry_has_no_density() {
        assert!(Equiangular::new(0.0, 0.0, (0.0, 1.0)).is_none());
        assert!(Equiangular::new(0.0, 1.0, (1.0, 1.0)).is_none());
        // A light 1e-4 from the ray: the density integrates to one (tangent substitution).
        let e = Equiangular::new(5.0, 1e-4, (0.0, 20.0)).unwrap();
        let q = crate::quadrature::gauss_kronrod(
            |th: f64| e.pdf(5.0 + 1e-4 * th.tan()) * 1e-4 / th.cos().powi(2),
            e.theta0,
            e.theta1,
            1e-12,
            1e-12,
            30,
        );
        assert!((q.value - 1.0).abs() < 1e-9, "{}", q.value);
    }
}

//! Free-flight distance sampling (paper 002 Eq. 3-4): solve `-ln(1 - xi) = int_0^s sigma_samp`
//! exactly for a piecewise-constant or piecewise-linear, non-negative `sigma_samp(t)` along a ray.
//!
//! Both densities are given by knots `t_0 < t_1 < ... < t_n` with values; beyond the last knot
//! the last value continues (a constant tail), before the first the first value holds.

/// How `sigma_samp` varies between knots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interp {
    /// Value `v_j` on `[t_j, t_{j+1})`.
    Constant,
    /// Linear from `v_j` to `v_{j+1}` on `[t_j, t_{j+1}]`.
    Linear,
}

/// The knots of a density: one knot held inline (a constant density, built once per ray by the
/// trackers, so it must not allocate), or any number on the heap.
#[derive(Clone, Debug, PartialEq)]
enum Knots {
    One([f64; 1], [f64; 1]),
    Many(Vec<f64>, Vec<f64>),
}

/// A non-negative sampling extinction along a ray (paper 002 Eq. 4).
#[derive(Clone, Debug, PartialEq)]
pub struct SamplingDensity {
    knots: Knots,
    interp: Interp,
}

impl SamplingDensity {
    /// A constant density `sigma` (> 0 for a proper free flight; 0 never interacts).
    pub fn constant(sigma: f64) -> Self {
        SamplingDensity { knots: Knots::One([0.0], [sigma.max(0.0)]), interp: Interp::Constant }
    }
    /// A density through knots (`t` increasing, same length as `v`, at least one knot); negative
    /// values are clamped to zero (a sampling density is a density).
    pub fn new(t: Vec<f64>, v: Vec<f64>, interp: Interp) -> Self {
        assert!(!t.is_empty() && t.len() == v.len(), "knots and values must match");
        debug_assert!(t.windows(2).all(|w| w[0] < w[1]), "knots must increase");
        SamplingDensity { knots: Knots::Many(t, v.into_iter().map(|x| x.max(0.0)).collect()), interp }
    }
    /// The knot positions.
    fn t(&self) -> &[f64] {
        match &self.knots {
            Knots::One(t, _) => t,
            Knots::Many(t, _) => t,
        }
    }
    /// The values at the knots.
    fn v(&self) -> &[f64] {
        match &self.knots {
            Knots::One(_, v) => v,
            Knots::Many(_, v) => v,
        }
    }
    /// The same knots with every value raised to at least `floor` (a density that is positive
    /// wherever `floor > 0`).
    pub fn floored(&self, floor: f64) -> SamplingDensity {
        let knots = match &self.knots {
            Knots::One(t, v) => Knots::One(*t, [v[0].max(floor)]),
            Knots::Many(t, v) => Knots::Many(t.clone(), v.iter().map(|v| v.max(floor)).collect()),
        };
        SamplingDensity { knots, interp: self.interp }
    }
    /// The density at `s`.
    #[inline]
    pub fn eval(&self, s: f64) -> f64 {
        let (t, v) = (self.t(), self.v());
        let n = t.len();
        if s <= t[0] {
            return v[0];
        }
        if s >= t[n - 1] {
            return v[n - 1];
        }
        let j = t.partition_point(|&x| x <= s) - 1;
        match self.interp {
            Interp::Constant => v[j],
            Interp::Linear => {
                let h = t[j + 1] - t[j];
                v[j] + (v[j + 1] - v[j]) * (s - t[j]) / h
            }
        }
    }
    /// Pieces as `(start, end, value at start, slope)`, the first from -inf and the last to +inf.
    fn piece(&self, j: usize) -> (f64, f64, f64, f64) {
        let (t, v) = (self.t(), self.v());
        let n = t.len();
        let start = if j == 0 { f64::NEG_INFINITY } else { t[j - 1] };
        let end = if j == n { f64::INFINITY } else { t[j] };
        if j == 0 || j == n || self.interp == Interp::Constant {
            let v0 = if j == 0 { v[0] } else { v[j - 1] };
            return (start, end, v0, 0.0);
        }
        let k = (v[j] - v[j - 1]) / (end - start);
        (start, end, v[j - 1], k)
    }
    /// `int_a^b sigma_samp` for `a <= b`.
    pub fn integral(&self, a: f64, b: f64) -> f64 {
        let mut total = 0.0;
        for j in 0..=self.t().len() {
            let (s0, s1, v0, k) = self.piece(j);
            let (lo, hi) = (a.max(s0), b.min(s1));
            if hi > lo {
                let at = |x: f64| if k == 0.0 { v0 } else { v0 + k * (x - s0) };
                total += 0.5 * (at(lo) + at(hi)) * (hi - lo);
            }
        }
        total
    }
    /// The free-flight end point: the `s > start` with `int_start^s sigma_samp = tau`
    /// (`tau = -ln(1 - xi)`), or `+inf` when the density never accumulates `tau`.
    #[inline]
    pub fn solve(&self, start: f64, tau: f64) -> f64 {
        if let Knots::One([t0], [v0]) = self.knots {
            if start >= t0 {
                // The last (infinite) piece of `solve_pieces`, taken directly: the same arithmetic.
                let x = tau / v0;
                return if x.is_finite() { start + x } else { f64::INFINITY };
            }
        }
        self.solve_pieces(start, tau)
    }
    /// [`SamplingDensity::solve`] piece by piece.
    fn solve_pieces(&self, start: f64, mut tau: f64) -> f64 {
        for j in 0..=self.t().len() {
            let (s0, s1, v0, k) = self.piece(j);
            if s1 <= start {
                continue;
            }
            let lo = start.max(s0);
            let a = if k == 0.0 { v0 } else { v0 + k * (lo - s0) };
            let len = s1 - lo;
            let piece = if len.is_infinite() { f64::INFINITY } else { (a + 0.5 * k * len) * len };
            if piece >= tau {
                // a x + k x^2 / 2 = tau, in the cancellation-free form.
                let x = if k == 0.0 { tau / a } else { 2.0 * tau / (a + (a * a + 2.0 * k * tau).max(0.0).sqrt()) };
                return if x.is_finite() { lo + x } else { f64::INFINITY };
            }
            tau -= piece;
        }
        f64::INFINITY
    }
    /// Samples a free flight from `start` with one uniform number `xi` in `[0, 1)`.
    #[inline]
    pub fn sample(&self, start: f64, xi: f64) -> f64 {
        self.solve(start, -(-xi).ln_1p())
    }
    /// A free flight from `t0` conditioned to end before `t1` (paper 002 §4.3 scattering-driven
    /// sampling mimics `T sigma_t` this way), by inverting its CDF
    /// `(1 - exp(-Lambda(t))) / (1 - exp(-Lambda(t1)))` with `xi` in `[0, 1)`. Needs
    /// `int_{t0}^{t1} sigma > 0` (see [`SamplingDensity::pdf_truncated`]).
    pub fn sample_truncated(&self, (t0, t1): (f64, f64), xi: f64) -> f64 {
        let total = self.integral(t0, t1);
        self.solve(t0, -(xi * (-total).exp_m1()).ln_1p()).clamp(t0, t1)
    }
    /// The density of [`SamplingDensity::sample_truncated`] at `t`: zero outside `[t0, t1]` or
    /// when the density accumulates nothing there.
    pub fn pdf_truncated(&self, (t0, t1): (f64, f64), t: f64) -> f64 {
        let norm = -(-self.integral(t0, t1)).exp_m1();
        if !(t0..=t1).contains(&t) || norm <= 0.0 {
            return 0.0;
        }
        self.eval(t) * (-self.integral(t0, t)).exp() / norm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_linear_free_flight_solves_eq4_exactly() {
        // Its chi-square fit is in the sampler registry (`samplers::registry`, "ff-pwl").
        let d = SamplingDensity::new(vec![0.0, 1.0, 2.5, 4.0, 6.0], vec![0.1, 1.2, 0.0, 0.9, 0.3], Interp::Linear);
        // Exactness: the solved distance accumulates exactly tau.
        for tau in [0.01, 0.5, 1.3, 2.7, 5.0] {
            let s = d.solve(0.5, tau);
            assert!((d.integral(0.5, s) - tau).abs() < 1e-12, "tau {tau}");
        }
    }

    #[test]
    fn zero_density_never_interacts() {
        assert!(SamplingDensity::constant(0.0).sample(0.0, 0.5).is_infinite());
        assert_eq!(SamplingDensity::constant(2.0).integral(1.0, 3.0), 4.0);
    }
}

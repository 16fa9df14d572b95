//! Exact moments of one-ray transmittance estimates (paper 002 §3.4, generalised to every order),
//! for predicting the variance of a measured estimate *and* the error bar of its sample variance.
//!
//! A tracker with a constant sampling density `sigma_samp` on `[t0, t1]` meets interactions at the
//! points of a Poisson process of rate `sigma_samp`; its estimate is `X = T_main prod_i g(t_i)`
//! with independent factors `g` drawn by the interaction rule at `r = sigma_diff / sigma_samp`
//! (`sigma_diff = sigma_t - sigma_main`, paper 002 Eq. 5). Campbell's theorem (the probability
//! generating functional of a Poisson process) gives every raw moment in closed form:
//!
//! `E[X^k] = T_main^k exp(int sigma_samp (E[g(t)^k] - 1) dt)`.
//!
//! `k = 1` is `T` (unbiasedness); `k = 2` is Eq. 16, `V = T^2 (exp(int w) - 1)` with
//! `w = sigma_samp (E[g^2] - 1) + 2 sigma_diff`, which reproduces Eq. 17 (double particle),
//! Eq. 19 (terminating) and Eq. 20 (non-terminating) — the tests check this against
//! [`super::variance`]. `k = 3, 4` give the skewness and the fourth moment, from which the standard
//! error of a sample variance follows. The per-interaction moments `E[g^k]`:
//! - double particle / ratio tracking (`g = 1 - r`): `(1 - r)^k`;
//! - delta tracking (`g` is 0 with probability `r`, else 1; `0 <= r <= 1`): `1 - r`;
//! - terminating single particle (`g = sign(1 - r)` with probability `|1 - r|`, else 0;
//!   `0 <= r <= 2/(a+1)`): `sign(1 - r)^k |1 - r|`;
//! - non-terminating (`g = (1 - r)/q` with probability `q = |1 - r| / (a|r| + |1 - r|)`, else 0):
//!   `sign(1 - r)^k |1 - r| (a|r| + |1 - r|)^(k - 1)`.
//!
//! Ray marching (the biased control) has no Poisson structure: its moments are integrals over the
//! one random offset of the marching grid ([`ray_marching_moments`]).

use crate::quadrature::gauss_kronrod_multi;
use crate::tracking::Rule;

/// Moments of one estimate: its mean and, relative to powers of the mean, its central second,
/// third, fourth and sixth moments (the fourth gives the error bar of a sample variance, the third
/// and sixth that sample variance's own skewness).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateMoments {
    /// `E[X]`.
    pub mean: f64,
    /// `Var[X] / E[X]^2`.
    pub rel_variance: f64,
    /// `E[(X - E X)^4] / E[X]^4`.
    pub rel_central4: f64,
    /// `E[(X - E X)^3] / E[X]^3`.
    pub rel_central3: f64,
    /// `E[(X - E X)^6] / E[X]^6`.
    pub rel_central6: f64,
}

impl EstimateMoments {
    /// `Var[X]`.
    pub fn variance(&self) -> f64 {
        self.rel_variance * self.mean * self.mean
    }
    /// A constant estimate (zero variance).
    pub fn constant(mean: f64) -> EstimateMoments {
        EstimateMoments { mean, rel_variance: 0.0, rel_central4: 0.0, rel_central3: 0.0, rel_central6: 0.0 }
    }
    /// The moments of the mean of `n` independent copies (the cumulant of order k scales as
    /// `n^(1 - k)`).
    pub fn mean_of(&self, n: f64) -> EstimateMoments {
        let (c2, c3, c4, c6) = (self.rel_variance, self.rel_central3, self.rel_central4, self.rel_central6);
        let k4 = c4 - 3.0 * c2 * c2;
        let k6 = c6 - 15.0 * c4 * c2 - 10.0 * c3 * c3 + 30.0 * c2 * c2 * c2;
        let (k2, k3, k4, k6) = (c2 / n, c3 / (n * n), k4 / n.powi(3), k6 / n.powi(5));
        EstimateMoments {
            mean: self.mean,
            rel_variance: k2,
            rel_central3: k3,
            rel_central4: (self.rel_central4 + 3.0 * (n - 1.0) * c2 * c2) / (n * n * n),
            rel_central6: k6 + 15.0 * k4 * k2 + 10.0 * k3 * k3 + 15.0 * k2 * k2 * k2,
        }
    }
    /// The skewness of the sample variance of `reps` independent copies, to leading order in
    /// `1/reps`: third cumulant `(mu6 - 3 mu4 mu2 - 6 mu3^2 + 2 mu2^3) / reps^2` over the variance
    /// `(mu4 - mu2^2) / reps` to the power 3/2 (`sqrt(8 / reps)` for normal estimates: the
    /// chi-square's skewness). 0 without spread.
    pub fn sample_variance_skewness(&self, reps: f64) -> f64 {
        let (m2, m3, m4, m6) = (self.rel_variance, self.rel_central3, self.rel_central4, self.rel_central6);
        let k3 = (m6 - 3.0 * m4 * m2 - 6.0 * m3 * m3 + 2.0 * m2 * m2 * m2) / (reps * reps);
        let var = ((m4 - m2 * m2) / reps).max(0.0);
        if var > 0.0 && k3.is_finite() {
            k3 / var.powf(1.5)
        } else {
            0.0
        }
    }
    /// The standard deviation of the (unbiased) sample variance of `reps` independent copies:
    /// `sqrt(mu4 / R - sigma^4 (R - 3) / (R (R - 1)))` (absolute units).
    pub fn sample_variance_sd(&self, reps: f64) -> f64 {
        let v = self.rel_variance;
        let rel = (self.rel_central4 / reps - v * v * (reps - 3.0) / (reps * (reps - 1.0))).max(0.0);
        rel.sqrt() * self.mean * self.mean
    }
}

/// `E[g^k]` of one interaction's factor under `rule` at `r` (NaN where the rule is invalid).
pub fn factor_moment(rule: Rule, r: f64, k: i32) -> f64 {
    let d = (1.0 - r).abs();
    let sign = if (k % 2 == 1) && r > 1.0 { -1.0 } else { 1.0 };
    match rule {
        Rule::Double => (1.0 - r).powi(k),
        Rule::Delta if (0.0..=1.0).contains(&r) => 1.0 - r,
        Rule::Terminating { a } if r >= 0.0 && r <= 2.0 / (a + 1.0) => sign * d,
        Rule::NonTerminating { a } => sign * d * (a * r.abs() + d).powi(k - 1),
        Rule::Delta | Rule::Terminating { .. } => f64::NAN,
    }
}

/// The moments of one tracker ray on `[t0, t1]` (`breaks`: known jumps or kinks inside), for the
/// difference extinction `sigma_diff(t)`, a main part of total optical depth `main_depth` (0
/// without a control variate), a constant `sigma_samp` and `rule`; `None` where the rule is
/// invalid somewhere on the ray. Quadrature: adaptive Gauss-Kronrod, relative tolerance 1e-13.
pub fn tracker_moments(
    sigma_diff: impl Fn(f64) -> f64,
    main_depth: f64,
    sigma_samp: f64,
    rule: Rule,
    (t0, t1): (f64, f64),
    breaks: &[f64],
) -> Option<EstimateMoments> {
    let mut knots = vec![t0];
    knots.extend(breaks.iter().copied().filter(|&b| b > t0 && b < t1));
    knots.push(t1);
    // log E[X^k] - k log T_main = int sigma_samp (E[g^k] - 1), for k = 1..6.
    let q = gauss_kronrod_multi(
        |t| {
            let r = sigma_diff(t) / sigma_samp;
            [1, 2, 3, 4, 5, 6].map(|k| sigma_samp * (factor_moment(rule, r, k) - 1.0))
        },
        &knots,
        1e-15,
        1e-13,
        50,
    );
    if q.value.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let l = q.value;
    // Relative raw moments m_k = E[(X / E X)^k] = exp(l_k - k l_1); e_k = m_k - 1.
    let e = |k: usize| (l[k - 1] - k as f64 * l[0]).exp_m1();
    Some(EstimateMoments {
        mean: (l[0] - main_depth).exp(),
        rel_variance: e(2),
        rel_central3: e(3) - 3.0 * e(2),
        rel_central4: e(4) - 4.0 * e(3) + 6.0 * e(2),
        rel_central6: e(6) - 6.0 * e(5) + 15.0 * e(4) - 20.0 * e(3) + 15.0 * e(2),
    })
}

/// The exact mean and central moments of one ray-marching estimate `exp(-h sum_j sigma(t0 + (j + u) h))`
/// with `steps` equal steps `h` and one uniform offset `u` (paper 002 §2's biased control), by
/// adaptive quadrature over `u` (`breaks`: jumps of `sigma` in `t`, mapped to the offsets where a
/// marching point crosses them).
pub fn ray_marching_moments(
    sigma: impl Fn(f64) -> f64,
    (t0, t1): (f64, f64),
    steps: usize,
    breaks: &[f64],
) -> EstimateMoments {
    let h = (t1 - t0) / steps as f64;
    let x = |u: f64| (-(0..steps).map(|j| sigma(t0 + (j as f64 + u) * h)).sum::<f64>() * h).exp();
    let mut knots: Vec<f64> = vec![0.0, 1.0];
    for &b in breaks.iter().filter(|&&b| b > t0 && b < t1) {
        let u = ((b - t0) / h).fract();
        if u > 0.0 && u < 1.0 {
            knots.push(u);
        }
    }
    knots.sort_by(f64::total_cmp);
    knots.dedup();
    let mean = gauss_kronrod_multi(|u| [x(u)], &knots, 1e-300, 1e-14, 50).value[0];
    let c = gauss_kronrod_multi(
        |u| {
            let d = x(u) / mean - 1.0;
            [d * d, d * d * d * d, d * d * d, d.powi(6)]
        },
        &knots,
        1e-300,
        1e-12,
        50,
    )
    .value;
    EstimateMoments { mean, rel_variance: c[0], rel_central4: c[1], rel_central3: c[2], rel_central6: c[3] }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::media::variance::{predicted, Model};
    use crate::rng::stream;
    use rand::Rng;

    /// k = 1 is the transmittance and k = 2 reproduces Eq. 16 with Eq. 17, 19 and 20 for every
    /// model, on a profile with a sign-changing difference extinction.
    #[test]
    fn second_moment_is_eq16_and_first_is_unbiased() {
        let sigma = |t: f64| 0.3 + 0.7 * (2.0 * t).sin().powi(2);
        let tau = crate::quadrature::gauss_kronrod(sigma, 0.0, 3.0, 1e-15, 1e-14, 50).value;
        for (rule, model, samp) in [
            (Rule::Double, Model::Double, 0.4),
            (Rule::Double, Model::Double, 2.5),
            (Rule::Terminating { a: 0.7 }, Model::Terminating, 0.9),
            (Rule::Delta, Model::Terminating, 1.2),
            (Rule::NonTerminating { a: 0.7 }, Model::NonTerminating { a: 0.7 }, 0.35),
            (Rule::NonTerminating { a: 0.7 }, Model::NonTerminating { a: 0.7 }, 3.0),
        ] {
            let m = tracker_moments(sigma, 0.0, samp, rule, (0.0, 3.0), &[]).unwrap();
            let (t, v) = predicted(sigma, model, samp, &[3.0])[0];
            assert!((m.mean / (-tau).exp() - 1.0).abs() < 1e-11 && (m.mean / t - 1.0).abs() < 1e-11, "{rule:?}");
            assert!((m.variance() / v - 1.0).abs() < 1e-9, "{rule:?} {samp}: {} vs Eq. 16 {v}", m.variance());
        }
        assert!(tracker_moments(sigma, 0.0, 0.5, Rule::Delta, (0.0, 3.0), &[]).is_none());
        assert!(tracker_moments(sigma, 0.0, 0.5, Rule::Terminating { a: 0.9 }, (0.0, 3.0), &[]).is_none());
    }

    /// The fourth central moment against a direct simulation of the non-terminating model
    /// (Poisson interactions, one factor each), and ray marching's moments against sampling of
    /// the offset: within 5 standard errors.
    #[test]
    fn fourth_moment_and_ray_marching_match_simulation() {
        let sigma = |t: f64| if t < 0.4 { 0.5 } else { 2.0 };
        let (a, samp) = (0.7, 1.5);
        let m = tracker_moments(sigma, 0.0, samp, Rule::NonTerminating { a }, (0.0, 1.0), &[0.4]).unwrap();
        let mut rng = stream(5, "moments");
        let n = 400_000;
        let (mut s2, mut s4, mut s8) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            let (mut x, mut t) = (1.0f64, 0.0);
            loop {
                t += -(-rng.gen::<f64>()).ln_1p() / samp;
                if t >= 1.0 {
                    break;
                }
                let r = sigma(t) / samp;
                let q = (1.0 - r).abs() / (a * r + (1.0 - r).abs());
                x *= if rng.gen::<f64>() < q { (1.0 - r) / q } else { 0.0 };
            }
            let d = x / m.mean - 1.0;
            (s2, s4, s8) = (s2 + d * d, s4 + d.powi(4), s8 + d.powi(8));
        }
        let nf = n as f64;
        let (v, c4) = (s2 / nf, s4 / nf);
        assert!((v - m.rel_variance).abs() < 5.0 * ((s4 / nf - v * v) / nf).sqrt(), "{v} vs {}", m.rel_variance);
        assert!((c4 - m.rel_central4).abs() < 5.0 * ((s8 / nf - c4 * c4) / nf).sqrt(), "{c4} vs {}", m.rel_central4);
        let rm = ray_marching_moments(sigma, (0.0, 1.0), 2, &[0.4]);
        let xs: Vec<f64> = (0..200_000)
            .map(|_| {
                let u: f64 = rng.gen();
                (-0.5 * (sigma(0.5 * u) + sigma(0.5 + 0.5 * u))).exp()
            })
            .collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64;
        assert!((mean - rm.mean).abs() < 5.0 * (var / xs.len() as f64).sqrt(), "{mean} vs {}", rm.mean);
        assert!((var / (rm.variance()) - 1.0).abs() < 0.02, "{var} vs {}", rm.variance());
        // Jensen: ray marching overestimates T = exp(-1.4).
        assert!(rm.mean > (-1.4f64).exp());
    }

    /// The sample variance's standard deviation against the normal case (mu4 = 3 sigma^4):
    /// `sigma^2 sqrt(2 / (R - 1))`; and averaging n copies divides the variance by n.
    #[test]
    fn sample_variance_error_bar_reduces_to_the_normal_case() {
        let normal = EstimateMoments {
            mean: 2.0,
            rel_variance: 0.01,
            rel_central4: 3e-4,
            rel_central3: 0.0,
            rel_central6: 15e-6,
        };
        let sd = normal.sample_variance_sd(101.0);
        assert!((sd / (0.04 * (2.0f64 / 100.0).sqrt()) - 1.0).abs() < 1e-12, "{sd}");
        let m = normal.mean_of(4.0);
        assert!((m.variance() - 0.01).abs() < 1e-15 && (m.rel_central4 - 3.0 * 0.0025f64.powi(2)).abs() < 1e-15);
    }

    /// The mean of n exponential estimates is Gamma(n)/n: its relative central moments are
    /// 1/n, 2/n^2, (3n + 6)/n^3 and (15 n^3 + 130 n^2 + 120 n)/n^6 (cumulants (j-1)! n / n^j);
    /// the sample variance of normal estimates has the chi-square's skewness sqrt(8 / R).
    #[test]
    fn higher_moments_of_a_mean_and_of_a_sample_variance() {
        let exp =
            EstimateMoments { mean: 1.0, rel_variance: 1.0, rel_central3: 2.0, rel_central4: 9.0, rel_central6: 265.0 };
        let n = 4.0;
        let g = exp.mean_of(n);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        assert!(close(g.rel_variance, 1.0 / n));
        assert!(close(g.rel_central3, 2.0 / (n * n)));
        assert!(close(g.rel_central4, (3.0 * n + 6.0) / n.powi(3)));
        assert!(
            close(g.rel_central6, (15.0 * n.powi(3) + 130.0 * n * n + 120.0 * n) / n.powi(6)),
            "{}",
            g.rel_central6
        );
        let v: f64 = 0.01;
        let normal = EstimateMoments {
            mean: 3.0,
            rel_variance: v,
            rel_central3: 0.0,
            rel_central4: 3.0 * v * v,
            rel_central6: 15.0 * v.powi(3),
        };
        for reps in [16.0, 400.0] {
            assert!(close(normal.sample_variance_skewness(reps), (8.0 / reps).sqrt()));
        }
        // Heavy tails skew the sample variance far more: exponential estimates at 400 repetitions.
        assert!(exp.sample_variance_skewness(400.0) > 3.0 * normal.sample_variance_skewness(400.0));
        assert_eq!(EstimateMoments::constant(2.0).sample_variance_skewness(10.0), 0.0);
    }
}

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

use crate::tracking::Rule;
use mcbench_core::estimator::EstimateMoments;
use mcbench_core::quadrature::gauss_kronrod_multi;

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
    use crate::tracking::variance::{predicted, Model};
    use mcbench_core::rng::stream;
    use rand::Rng;

    /// k = 1 is the transmittance and k = 2 reproduces Eq. 16 with Eq. 17, 19 and 20 for every
    /// model, on a profile with a sign-changing difference extinction.
    #[test]
    fn second_moment_is_eq16_and_first_is_unbiased() {
        let sigma = |t: f64| 0.3 + 0.7 * (2.0 * t).sin().powi(2);
        let tau = mcbench_core::quadrature::gauss_kronrod(sigma, 0.0, 3.0, 1e-15, 1e-14, 50).value;
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
}

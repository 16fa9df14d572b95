//! Paper 002 Eq. 16-20 against measured variance on the eq21 central ray (Fig. 8): one-ray
//! estimates of T(s) at s = 5 and 10, 20000 rays per point; held when the measured variance is
//! within 4 standard errors (from the sample fourth moment) of the prediction.

use mcbench::output::Claim;
use mcbench_core::budget::Budget;
use mcbench_core::estimator::Estimator;
use mcbench_core::math::Vec3;
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::stats::Moments;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use mcbench_papers::builtins;
use mcbench_papers::testbeds::medium::{Field, MediumBed};
use mcbench_papers::tracking::variance::{predicted, Model};

/// Albedo of the eq21 medium (the non-terminating model's `w` depends on it).
const ALBEDO: f64 = 0.7;

/// The estimator / model / sigma_samp cases of paper 002 Fig. 8 that Eq. 16 predicts.
pub const CASES: [(&str, Model, f64); 5] = [
    ("double_particle", Model::Double, 0.4),
    ("double_particle", Model::Double, 1.0),
    ("single_particle_nonterminating", Model::NonTerminating { a: ALBEDO }, 0.4),
    ("single_particle_nonterminating", Model::NonTerminating { a: ALBEDO }, 1.0),
    ("single_particle_terminating", Model::Terminating, 1.0),
];

/// The sample mean and variance of `n` one-ray estimates of integral `k`, and the standard error
/// of that variance (from the sample fourth moment).
pub struct Measured {
    /// Mean of the one-ray estimates.
    pub mean: f64,
    /// Their sample variance.
    pub variance: f64,
    /// Standard error of `variance`.
    pub variance_se: f64,
}

/// `n` one-ray estimates of integral `k` of `bed` on the stream `(seed, "eq16 claim")`.
pub fn measure(est: &dyn Estimator, bed: &dyn TestBed, k: usize, n: usize, seed: u64) -> Measured {
    let mut rng = stream(seed, "eq16 claim");
    let mut xs = Vec::with_capacity(n);
    let mut m = Moments::default();
    for _ in 0..n {
        let task = Task::new(bed, k, Budget { kind: mcbench_core::budget::BudgetKind::Samples, amount: 1 });
        let x = est.estimate(&task, &mut rng).map(|v| v[0]).unwrap_or(f64::NAN);
        m.push(x);
        xs.push(x);
    }
    let v = m.variance();
    let m4 = xs.iter().map(|x| (x - m.mean()).powi(4)).sum::<f64>() / n as f64;
    Measured { mean: m.mean(), variance: v, variance_se: sample_variance_se(m4, v * (n as f64 - 1.0) / n as f64, n) }
}

/// Standard error of the sample variance of `n` values with central moments `m2`, `m4` (both
/// averaged over `n`): `Var(s^2) = m4 / n - m2^2 (n - 3) / (n (n - 1))`, the exact finite-`n`
/// form with the moments plugged in. The first-order `(m4 - m2^2) / n` vanishes for a two-point
/// distribution with equal weights (a binary estimate with T = 1/2: `m4 = m2^2`), where the
/// sample variance still fluctuates at order `m2 / n`; a zero standard error would turn any
/// difference into an infinite z.
fn sample_variance_se(m4: f64, m2: f64, n: usize) -> f64 {
    let n = n as f64;
    (m4 / n - m2 * m2 * (n - 3.0) / (n * (n - 1.0))).max(0.0).sqrt()
}

/// The central-ray bed with `points` integrals, its extinction along the ray and the grid of s.
pub fn central_ray(points: usize) -> Option<(MediumBed, Vec<f64>)> {
    let bed = MediumBed::new(
        Field::Eq21,
        "central-ray",
        &Params::new().with("points", points as f64),
        &mcbench_core::references::NoReferences,
    )
    .ok()?;
    let grid: Vec<f64> = (0..points).filter_map(|k| bed.medium().map(|m| m.ray(k).length)).collect();
    Some((bed, grid))
}

/// Builds the estimator of a case (None when the id is not registered).
pub fn build(id: &str, samp: f64) -> Option<Box<dyn Estimator>> {
    builtins::estimator(id).and_then(|e| (e.build)(&Params::new().with("sigma_samp", samp))).ok()
}

/// The Eq. 16 claims.
pub fn eq16_claims() -> Vec<Claim> {
    let Some((bed, grid)) = central_ray(4) else {
        return Vec::new();
    };
    let sigma = |t: f64| bed.extinction(Vec3::new(0.0, 0.0, t));
    let mut out = Vec::new();
    for (ci, (id, model, samp)) in CASES.into_iter().enumerate() {
        let Some(est) = build(id, samp) else { continue };
        let pred = predicted(sigma, model, samp, &grid);
        for k in 0..2 {
            let n = 20_000;
            let Measured { variance: v, variance_se: se, .. } =
                measure(est.as_ref(), &bed, k, n, ci as u64 * 7 + k as u64);
            out.push(Claim {
                testbed: "eq21-medium/central-ray".into(),
                claim: format!("paper 002 Eq. 16 ({id}, sigma_samp {samp}): predicted variance of T(s = {}) equals the measured one", grid[k]),
                paper_value: Some(pred[k].1),
                our_value: Some(v),
                held: Some((v - pred[k].1).abs() <= 4.0 * se),
                note: format!("T = {:.5}, measured variance {v:.5e} +- {se:.2e} (1 SE, {n} one-ray estimates); std band T +- {:.4}", pred[k].0, pred[k].1.sqrt()),
                ..Default::default()
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::sample_variance_se;

    #[test]
    fn variance_se_of_a_balanced_binary_sample_is_not_zero() {
        // n values, half 0 and half 1: mean 1/2, m2 = 1/4, m4 = 1/16.
        let n = 4000;
        let se = sample_variance_se(1.0 / 16.0, 0.25, n);
        // Exact for a Bernoulli(1/2) population: Var(s^2) = 1 / (8 n (n - 1)).
        let exact = (1.0 / (8.0 * n as f64 * (n as f64 - 1.0))).sqrt();
        assert!(se > 0.5 * exact && se < 2.0 * exact, "se {se:e}, exact {exact:e}");
        // A normal sample: m4 = 3 v^2, so Var(s^2) is about 2 v^2 / n.
        let se = sample_variance_se(3.0, 1.0, n);
        assert!((se / (2.0 / n as f64).sqrt() - 1.0).abs() < 1e-3, "{se}");
    }
}

//! Paper 002 Eq. 16-20 against measured variance on the eq21 central ray (Fig. 8): one-ray
//! estimates of T(s) at s = 5 and 10, 20000 rays per point; held when the measured variance is
//! within 4 standard errors (from the sample fourth moment) of the prediction.

use crate::output::Claim;
use estimators::budget::Budget;
use estimators::math::Vec3;
use estimators::media::variance::{predicted, Model};
use estimators::media::{Field, MediumBed};
use estimators::params::Params;
use estimators::registry;
use estimators::rng::stream;
use estimators::stats::Moments;
use estimators::task::Task;
use estimators::testbed::TestBed;

/// The Eq. 16 claims.
pub fn eq16_claims() -> Vec<Claim> {
    let Ok(bed) = MediumBed::new(Field::Eq21, "central-ray", &Params::new().with("points", 4.0)) else {
        return Vec::new();
    };
    let sigma = |t: f64| bed.extinction(Vec3::new(0.0, 0.0, t));
    let grid: Vec<f64> = (0..4).filter_map(|k| bed.medium().map(|m| m.ray(k).length)).collect();
    let a = 0.7;
    let cases = [
        ("double_particle", Model::Double, 0.4),
        ("double_particle", Model::Double, 1.0),
        ("single_particle_nonterminating", Model::NonTerminating { a }, 0.4),
        ("single_particle_nonterminating", Model::NonTerminating { a }, 1.0),
        ("single_particle_terminating", Model::Terminating, 1.0),
    ];
    let mut out = Vec::new();
    for (ci, (id, model, samp)) in cases.into_iter().enumerate() {
        let Ok(est) = registry::estimator(id).and_then(|e| (e.build)(&Params::new().with("sigma_samp", samp))) else {
            continue;
        };
        let pred = predicted(sigma, model, samp, &grid);
        for k in 0..2 {
            let n = 20_000;
            let mut rng = stream(ci as u64 * 7 + k as u64, "eq16 claim");
            let mut xs = Vec::with_capacity(n);
            let mut m = Moments::default();
            for _ in 0..n {
                let task = Task::new(&bed, k, Budget { kind: estimators::budget::BudgetKind::Samples, amount: 1 });
                let x = est.estimate(&task, &mut rng).map(|v| v[0]).unwrap_or(f64::NAN);
                m.push(x);
                xs.push(x);
            }
            let v = m.variance();
            let m4 = xs.iter().map(|x| (x - m.mean()).powi(4)).sum::<f64>() / n as f64;
            let se = ((m4 - v * v) / n as f64).max(0.0).sqrt();
            out.push(Claim {
                testbed: "eq21-medium/central-ray".into(),
                claim: format!("paper 002 Eq. 16 ({id}, sigma_samp {samp}): predicted variance of T(s = {}) equals the measured one", grid[k]),
                paper_value: Some(pred[k].1),
                our_value: Some(v),
                held: Some((v - pred[k].1).abs() <= 4.0 * se),
                note: format!("T = {:.5}, measured variance {v:.5e} +- {se:.2e} (1 SE, {n} one-ray estimates); std band T +- {:.4}", pred[k].0, pred[k].1.sqrt()),
            });
        }
    }
    out
}

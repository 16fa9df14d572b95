//! Unbiasedness (book: statistics.md), refusal and stability (book: stability.md) tests of the trackers.

use crate::builtins;
use crate::testbeds::medium::{Field, MediumBed};
use mcbench_core::budget::{Budget, BudgetKind};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::Estimator;
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::stats::{holm_bonferroni, one_sample_t, welch, Moments};
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;

fn build(id: &str, p: Params) -> Box<dyn Estimator> {
    (builtins::estimator(id).unwrap().build)(&p).unwrap()
}

/// Smallest Holm-adjusted p-value of per-integral t-tests (reps estimates of `spp` rays each).
fn holm_p(bed: &MediumBed, est: &dyn Estimator, reps: usize, spp: u64, seed: u64) -> f64 {
    let mut ps = Vec::new();
    for i in 0..bed.integrals() {
        let mut m = Moments::default();
        let mut rng = stream(seed + i as u64, "unbiased");
        for _ in 0..reps {
            let task = Task::new(bed, i, Budget::samples(spp).unwrap());
            m.push(est.estimate(&task, &mut rng).unwrap()[0]);
        }
        let r = bed.reference().value[i][0];
        if m.std_err() > 0.0 {
            ps.push(one_sample_t(m.mean(), m.std_err(), m.count(), r).p_value);
        } else {
            assert!((m.mean() - r).abs() < 1e-12 * r.abs().max(1.0));
        }
    }
    holm_bonferroni(&ps).into_iter().fold(1.0, f64::min)
}

/// Every unbiased transmittance estimator passes (Holm over the central ray's points, family-wise
/// alpha 1e-3), including sigma_samp below the maximum extinction (not a majorant) and control
/// variates (piecewise-linear and constant main parts) with negative difference extinction; the
/// coarse ray-marching control is flagged.
#[test]
fn transmittance_estimators_are_unbiased_and_ray_marching_is_flagged() {
    let eq21 = MediumBed::new(
        Field::Eq21,
        "central-ray",
        &Params::new().with("points", 8.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    let perlin = MediumBed::new(
        Field::Perlin,
        "central-ray",
        &Params::new().with("points", 4.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    let s = |v: f64| Params::new().with("sigma_samp", v);
    let cases: Vec<(&MediumBed, &str, Params)> = vec![
        (&eq21, "delta_tracking", Params::new()),
        (&eq21, "ratio_tracking", Params::new()),
        (&eq21, "residual_ratio_tracking", Params::new()),
        (&eq21, "double_particle", s(0.4)),
        (&eq21, "double_particle", s(0.4).with("control", 1.0)),
        (&eq21, "double_particle", s(3.0)),
        (&eq21, "single_particle_nonterminating", s(0.5)),
        (&eq21, "single_particle_terminating", s(0.9)),
        (&perlin, "residual_ratio_tracking", Params::new()),
        (&perlin, "double_particle", s(0.3).with("control", 1.0)),
        (&eq21, "double_particle", s(0.4).with("control", 2.0)),
        (&perlin, "residual_ratio_tracking", Params::new().with("control", 2.0)),
        (&eq21, "single_particle_nonterminating", Params::new().with("sigma_samp_ratio", 0.25)),
    ];
    for (k, (bed, id, p)) in cases.into_iter().enumerate() {
        let est = build(id, p.clone());
        est.validate(bed).unwrap();
        let p_value = holm_p(bed, est.as_ref(), 300, 8, 100 * k as u64);
        assert!(p_value > 1e-3, "{id} {p:?} on {}: Holm p = {p_value:e}", bed.id());
    }
    let marching = build("ray_marching", Params::new().with("step", 2.5));
    let p_value = holm_p(&eq21, marching.as_ref(), 300, 8, 7);
    assert!(p_value < 1e-3, "ray marching not flagged: p = {p_value}");
}

/// The terminating model refuses r > 2/(a+1) (and delta tracking a non-majorant) before any
/// run, naming the field; at run time an out-of-range r is refused, never silently used.
#[test]
fn invalid_terminating_configurations_are_refused() {
    let bed = MediumBed::new(
        Field::Eq21,
        "central-ray",
        &Params::new().with("points", 4.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    let err = build("single_particle_terminating", Params::new().with("sigma_samp", 0.4))
        .validate(&bed)
        .unwrap_err()
        .to_string();
    assert!(err.contains("single_particle_terminating.sigma_samp"), "{err}");
    // Delta and ratio tracking need a majorant: a smaller density is a skipped pair with the
    // reason naming the field (absolute or relative to the declared majorant 1); at the majorant
    // (ratio 1) and above they run.
    for id in ["delta_tracking", "ratio_tracking"] {
        for (name, v) in [("sigma_samp", 0.4), ("sigma_samp_ratio", 0.75)] {
            let err = build(id, Params::new().with(name, v)).supports(&bed).unwrap_err();
            assert!(err.contains(&format!("{id}.{name} = {v}")) && err.contains("majorant"), "{err}");
        }
        for v in [1.0, 8.0] {
            assert!(build(id, Params::new().with("sigma_samp_ratio", v)).supports(&bed).is_ok());
        }
        let both = Params::new().with("sigma_samp", 1.0).with("sigma_samp_ratio", 1.0);
        assert!((builtins::estimator(id).unwrap().build)(&both).err().unwrap().to_string().contains("not both"));
    }
    for bad in [("control", 3.0), ("control", 0.5), ("sigma_samp_ratio", -1.0)] {
        let err = (builtins::estimator("double_particle").unwrap().build)(&Params::new().with(bad.0, bad.1));
        assert!(err.err().unwrap().to_string().contains(&format!("double_particle.{}", bad.0)));
    }
    let err = (builtins::estimator("residual_ratio_tracking").unwrap().build)(&Params::new().with("control", 0.0));
    assert!(err.err().unwrap().to_string().contains("residual_ratio_tracking.control"));
    let multiple =
        MediumBed::without_reference(Field::Eq21, "multiple", &Params::new().with("resolution", 4.0)).unwrap();
    let err =
        build("spm_terminating", Params::new().with("sigma_samp", 0.8)).validate(&multiple).unwrap_err().to_string();
    assert!(err.contains("2/(a+1)"), "{err}");
    assert!(build("spm_terminating", Params::new().with("sigma_samp", 1.0)).validate(&multiple).is_ok());
    // In a sweep the same configuration is a skipped pair with the reason (valid at 0.9 on Eq. 21,
    // albedo 0.7: r <= 1/0.9 < 2/1.7; not at 0.8).
    let skip = build("spm_terminating", Params::new().with("sigma_samp", 0.8)).supports(&multiple).unwrap_err();
    assert!(skip.contains("spm_terminating.sigma_samp") && skip.contains("2/(a+1)"), "{skip}");
    assert!(build("spm_terminating", Params::new().with("sigma_samp", 0.9)).supports(&multiple).is_ok());
    assert!(matches!(super::interact(super::Rule::Terminating { a: 0.7 }, -0.1, 0.5), Err(EstimateError::Refused(_))));
    assert!(builtins::estimator("double_particle")
        .map(|e| (e.build)(&Params::new().with("sigma_samp", 0.0)).is_err())
        .unwrap());
}

/// The particle models agree with delta tracking on a multiple-scattering pixel (Welch).
#[test]
fn particle_models_agree_with_delta_tracking() {
    let bed = MediumBed::without_reference(Field::Eq21, "multiple", &Params::new().with("resolution", 4.0)).unwrap();
    let run = |id: &str, sigma: f64| {
        let est = build(id, Params::new().with("sigma_samp", sigma));
        let mut m = Moments::default();
        let mut rng = stream(3, id);
        for _ in 0..400 {
            let task = Task::new(&bed, 5, Budget::samples(10).unwrap());
            m.push(est.estimate(&task, &mut rng).unwrap()[1]);
        }
        m
    };
    let base = run("delta_tracking", 1.0);
    for (id, sigma) in
        [("spm_terminating", 1.5), ("spm_nonterminating", 0.5), ("spm_adaptive", 0.6), ("spm_adaptive", 2.0)]
    {
        let m = run(id, sigma);
        let p = welch(m.mean(), m.std_err(), m.count(), base.mean(), base.std_err(), base.count()).p_value;
        assert!(p > 1e-3, "{id} {sigma}: {} vs {} (p {p:e})", m.mean(), base.mean());
    }
}

/// Stability: extreme sampling densities, optical depth 1e4, rays that miss the medium, albedo 1
/// with non-terminating weights: finite results (or a refusal), and no endless loop.
#[test]
fn stability_cases_are_finite() {
    let short = MediumBed::new(
        Field::Eq21,
        "central-ray",
        &Params::new().with("points", 200.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    for sigma in [1e-6, 1e6] {
        let est = build("double_particle", Params::new().with("sigma_samp", sigma));
        let task = Task::new(&short, 0, Budget::samples(4).unwrap());
        assert!(est.estimate(&task, &mut stream(1, "stab")).unwrap().is_finite());
    }
    let thick = MediumBed::new(
        Field::Eq21,
        "central-ray",
        &Params::new().with("points", 2.0).with("scale", 1500.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    assert!(thick.reference().value[1][0] == 0.0 || thick.reference().value[1][0] < 1e-300);
    for id in ["ratio_tracking", "delta_tracking", "residual_ratio_tracking", "ray_marching"] {
        let task = Task::new(&thick, 1, Budget::samples(2).unwrap());
        assert!(build(id, Params::new()).estimate(&task, &mut stream(2, id)).unwrap().is_finite(), "{id}");
    }
    // The corner pixel's ray misses the sphere: exact, one sample, even under a fetch budget.
    let image = MediumBed::new(
        Field::Eq21,
        "transmittance",
        &Params::new().with("resolution", 4.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    for id in ["ratio_tracking", "residual_ratio_tracking", "ray_marching", "delta_tracking"] {
        let task = Task::new(&image, 0, Budget::new(BudgetKind::Fetches, 10).unwrap());
        let v = build(id, Params::new()).estimate(&task, &mut stream(4, id)).unwrap();
        assert_eq!(v, image.reference().value[0], "{id}");
        assert_eq!(task.costs().samples, 1);
    }
    // A fetch budget the harness converted into a fixed ray count stops after exactly that many
    // rays, however many fetches they spent (an inner pixel, 7 rays, a budget of only 10 fetches).
    for id in ["ratio_tracking", "delta_tracking"] {
        let task = Task::with_samples(&image, 5, Budget::new(BudgetKind::Fetches, 10).unwrap(), 7);
        build(id, Params::new()).estimate(&task, &mut stream(5, id)).unwrap();
        assert_eq!(task.costs().samples, 7, "{id}");
    }
    let white = MediumBed::without_reference(
        Field::Eq21,
        "multiple",
        &Params::new().with("resolution", 4.0).with("albedo", 1.0),
    )
    .unwrap();
    let task = Task::new(&white, 5, Budget::samples(50).unwrap());
    assert!(build("spm_nonterminating", Params::new().with("sigma_samp", 0.5))
        .estimate(&task, &mut stream(5, "w"))
        .unwrap()
        .is_finite());
}

/// Each tracker's `sample_moments` (paper 002 Eq. 16-20 and higher moments, exact) against the
/// sample mean and variance of 20000 one-ray estimates on `canonical-1d` (a hole: negative
/// difference extinction under both control variates, minorant densities): within 5 standard
/// errors, the variance's error bar from the predicted fourth moment. Ray marching's exact moments
/// show its bias.
#[test]
fn sample_moments_match_one_ray_estimates() {
    use crate::testbeds::canonical_1d::Canonical1d;
    let bed = Canonical1d::new("hole-T0.1", &Params::new()).unwrap();
    let r = |v: f64| Params::new().with("sigma_samp_ratio", v);
    let cases = [
        ("delta_tracking", r(1.5)),
        ("ratio_tracking", r(1.0)),
        ("double_particle", r(0.5).with("control", 2.0)),
        ("double_particle", r(2.0).with("control", 1.0)),
        ("single_particle_nonterminating", r(0.75)),
        ("single_particle_terminating", r(1.0)),
        ("ray_marching", Params::new()),
    ];
    let n = 20_000;
    for (k, (id, p)) in cases.into_iter().enumerate() {
        let est = build(id, p.clone());
        let budget = Budget::samples(1).unwrap();
        let m = est.sample_moments(&Task::new(&bed, 0, budget)).unwrap_or_else(|| panic!("{id}: no moments"));
        let mut rng = stream(k as u64, "sample moments");
        let mut s = Moments::default();
        for _ in 0..n {
            s.push(est.estimate(&Task::new(&bed, 0, budget), &mut rng).unwrap()[0]);
        }
        let (mean_se, var_sd) = ((m.variance() / n as f64).sqrt(), m.sample_variance_sd(n as f64));
        assert!((s.mean() - m.mean).abs() < 5.0 * mean_se, "{id} {p:?}: mean {} vs {}", s.mean(), m.mean);
        assert!((s.variance() - m.variance()).abs() < 5.0 * var_sd, "{id} {p:?}: {} vs {}", s.variance(), m.variance());
    }
    let marching =
        build("ray_marching", Params::new()).sample_moments(&Task::new(&bed, 0, Budget::samples(1).unwrap()));
    assert!(marching.unwrap().mean > 0.1 * (1.0 + 1e-3), "ray marching's exact mean shows its bias");
    let radiance =
        MediumBed::without_reference(Field::Eq21, "multiple", &Params::new().with("resolution", 4.0)).unwrap();
    assert!(build("delta_tracking", Params::new())
        .sample_moments(&Task::new(&radiance, 0, Budget::samples(1).unwrap()))
        .is_none());
}

/// The finite-variance check (its integrals checked in parallel) refuses a sampling extinction far
/// below the extinction (the second moment `exp(7e5)`) by its parameter and the first integral
/// that fails, the same on every call, and accepts one near the extinction.
#[test]
fn the_finite_variance_check_refuses_by_parameter_and_first_integral() {
    let bed = MediumBed::new(
        Field::Eq21,
        "central-ray",
        &Params::new().with("points", 8.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    for id in ["double_particle", "single_particle_nonterminating"] {
        let tiny = build(id, Params::new().with("sigma_samp", 1e-6));
        for _ in 0..2 {
            let err = tiny.validate(&bed).unwrap_err().to_string();
            assert!(
                err.contains(&format!("{id}.sigma_samp"))
                    && err.contains("overflows f64 on eq21-medium/central-ray integral 0"),
                "{err}"
            );
        }
        let near = build(id, Params::new().with("sigma_samp", 1.0));
        for _ in 0..2 {
            near.validate(&bed).unwrap();
        }
    }
}

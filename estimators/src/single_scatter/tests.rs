//! Unbiasedness (book: statistics.md), stability (book: stability.md), refusals and costs of the single-scatter
//! estimators, on `eq21-medium/single-scatter` (exact references by nested quadrature).

use crate::builtins::{self, ESTIMATORS};
use crate::testbeds::medium::{Field, MediumBed};
use mcbench_core::budget::{Budget, BudgetKind};
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::stats::{holm_bonferroni, one_sample_t, Moments};
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;

/// The ids of paper 002 Fig. 12.
const IDS: [&str; 7] = [
    "ray_marching",
    "delta_tracking",
    "attenuation_driven",
    "attenuation_driven_sir",
    "source_driven",
    "scattering_driven",
    "mis",
];

fn build(id: &str, p: Params) -> Box<dyn Estimator> {
    (builtins::estimator(id).unwrap().build)(&p).unwrap()
}

fn bed(params: Params) -> MediumBed {
    MediumBed::new(Field::Eq21, "single-scatter", &params, &crate::built_in_references::BUILT_IN).unwrap()
}

/// Per-pixel moments of `reps` estimates of `spp` primary rays each (pixels `pixels`).
fn moments(bed: &MediumBed, est: &dyn Estimator, pixels: &[usize], reps: usize, spp: u64, seed: u64) -> Vec<Moments> {
    pixels
        .iter()
        .map(|&i| {
            let mut m = Moments::default();
            let mut rng = stream(seed + i as u64, "single-scatter");
            for _ in 0..reps {
                let task = Task::new(bed, i, Budget::samples(spp).unwrap());
                let v = est.estimate(&task, &mut rng).unwrap();
                assert!(v.is_finite() && v[0] == v[1] && v[1] == v[2], "{v:?}");
                m.push(v[0]);
            }
            m
        })
        .collect()
}

/// Smallest Holm-adjusted p-value of per-pixel t-tests against the reference.
fn holm_p(bed: &MediumBed, m: &[Moments], pixels: &[usize]) -> f64 {
    let ps: Vec<f64> = m
        .iter()
        .zip(pixels)
        .filter(|(m, _)| m.std_err() > 0.0)
        .map(|(m, &i)| one_sample_t(m.mean(), m.std_err(), m.count(), bed.reference().value[i][0]).p_value)
        .collect();
    holm_bonferroni(&ps).into_iter().fold(1.0, f64::min)
}

/// Every unbiased id passes per-pixel t-tests (Holm, family-wise alpha 1e-3) on the 12 pixels of
/// a 4x4 image that see the medium, with the light at its default place (the centre) and, for a
/// sharper peak, 0.3 from the ray of pixel 5; the biased control (coarse ray marching) is flagged
/// on the same pixels.
#[test]
fn unbiased_ids_pass_and_ray_marching_is_flagged() {
    let beds = [
        bed(Params::new().with("resolution", 4.0)),
        bed(Params::new().with("resolution", 4.0).with("light_x", -2.2).with("light_z", 12.5).with("light_y", 1.0)),
    ];
    let pixels: Vec<usize> = (0..16).filter(|i| ![0, 3, 12, 15].contains(i)).collect();
    for (b, bed) in beds.iter().enumerate() {
        for (k, id) in IDS.iter().enumerate().skip(1) {
            assert_eq!(builtins::estimator(id).unwrap().bias, Bias::Unbiased);
            let m = moments(bed, build(id, Params::new()).as_ref(), &pixels, 400, 4, 1000 * b as u64 + 50 * k as u64);
            let p = holm_p(bed, &m, &pixels);
            assert!(p > 1e-3, "{id} on bed {b}: Holm p = {p:e}");
        }
        let marching = build("ray_marching", Params::new().with("step", 3.0));
        let p = holm_p(bed, &moments(bed, marching.as_ref(), &pixels, 400, 1, 7 + b as u64), &pixels);
        assert!(p < 1e-3, "ray marching not flagged on bed {b}: p = {p}");
    }
}

/// The same on the Perlin medium's stored 4x4 reference (default light): every unbiased id passes
/// under sample budgets, and the pooled relative bias of all pixels is tested too (the harness's
/// fetch budgets make the ray count a stopping time; these budgets do not).
#[test]
fn unbiased_ids_pass_on_the_perlin_medium() {
    let bed =
        MediumBed::new(Field::Perlin, "single-scatter", &Params::new(), &crate::built_in_references::BUILT_IN).unwrap();
    let pixels: Vec<usize> = (0..16).filter(|i| ![0, 3, 12, 15].contains(i)).collect();
    for (k, id) in IDS.iter().enumerate().skip(1) {
        let m = moments(&bed, build(id, Params::new()).as_ref(), &pixels, 300, 4, 500 + 50 * k as u64);
        let p = holm_p(&bed, &m, &pixels);
        assert!(p > 1e-3, "{id}: Holm p = {p:e}");
        let (mut rel, mut var) = (0.0, 0.0);
        for (m, &i) in m.iter().zip(&pixels) {
            let r = bed.reference().value[i][0];
            rel += (m.mean() - r) / r;
            var += (m.std_err() / r).powi(2);
        }
        let z = rel / var.sqrt();
        assert!(z.abs() < 3.29, "{id}: pooled relative bias z = {z:.2}");
    }
}

/// Stability: the light on the sphere's boundary, inside the densest region (sigma_t = 1
/// at z = pi, x + y + z = 4 pi / 3) and 1e-4 from a pixel ray: every id returns finite values,
/// and the source-driven and MIS estimators (whose density follows the 1 / r^2 peak) still agree
/// with the reference at the pixel nearest the light. 1e-4 from a pixel ray the light is placed
/// twice: at y = 0, where Eq. 21 with its exponent 5 is nearly empty (sigma_t 2e-5: the
/// contribution comes from the far part of the chord, which equiangular sampling reaches with
/// probability about 1e-4 per point, so 1200 source-driven points see almost none of it and only
/// MIS, whose scattering-driven half samples that part, is checked there), and at y = 4 pi - 10
/// on the same pixel ray, where x + y + z = 4 pi puts it on a crest (sigma_t 0.66).
#[test]
fn stable_with_the_light_on_the_boundary_in_a_dense_region_and_near_a_ray() {
    let pi = std::f64::consts::PI;
    let both: &[&str] = &["source_driven", "mis"];
    let near_ray = Params::new().with("resolution", 4.0).with("light_x", -2.5 + 1e-4).with("light_z", 12.5);
    let cases = [
        (Params::new().with("resolution", 4.0).with("light_z", 20.0), 1usize, both),
        (Params::new().with("resolution", 4.0).with("light_x", 4.0 * pi / 3.0 - pi).with("light_z", pi), 14, both),
        (near_ray.clone(), 5, &["mis"][..]),
        (near_ray.with("light_y", 4.0 * pi - 10.0), 5, both),
    ];
    for (c, (params, near, agree)) in cases.into_iter().enumerate() {
        let bed = bed(params);
        assert!(bed.reference().value[near][0] > 0.0);
        for id in IDS {
            let est = build(id, Params::new());
            for budget in [Budget::samples(8).unwrap(), Budget::new(BudgetKind::Fetches, 50).unwrap()] {
                let task = Task::new(&bed, near, budget);
                let v = est.estimate(&task, &mut stream(c as u64, id)).unwrap();
                assert!(v.is_finite(), "{id} case {c} {budget:?}: {v:?}");
            }
        }
        for &id in agree {
            let m = moments(&bed, build(id, Params::new()).as_ref(), &[near], 300, 4, 90 + c as u64);
            let p = holm_p(&bed, &m, &[near]);
            assert!(p > 1e-3, "{id} case {c}: {} vs {} (p {p:e})", m[0].mean(), bed.reference().value[near][0]);
        }
    }
}

/// A light on a pixel ray is refused naming the field; so are bad parameters of the ids.
#[test]
fn bad_input_is_refused_naming_the_field() {
    let err = MediumBed::new(
        Field::Eq21,
        "single-scatter",
        &Params::new().with("resolution", 4.0).with("light_x", -2.5).with("light_z", 12.5),
        &crate::built_in_references::BUILT_IN,
    )
    .err()
    .map(|e| e.to_string())
    .unwrap_or_default();
    assert!(err.contains("eq21-medium.light_x"), "{err}");
    let err = MediumBed::new(
        Field::Eq21,
        "transmittance",
        &Params::new().with("light_x", 1.0),
        &crate::built_in_references::BUILT_IN,
    )
    .err()
    .map(|e| e.to_string());
    assert!(err.unwrap_or_default().contains("eq21-medium.light_x"));
    for (id, p, field) in [
        ("mis", Params::new().with("scatter_floor", 0.0), "mis.scatter_floor"),
        ("mis", Params::new().with("foo", 1.0), "mis.foo"),
        ("scattering_driven", Params::new().with("scatter_floor", -1.0), "scattering_driven.scatter_floor"),
        ("attenuation_driven_sir", Params::new().with("shadow_rays", 0.0), "shadow_rays"),
        ("source_driven", Params::new().with("explorer_spacing", 0.0), "source_driven.explorer_spacing"),
        ("ray_marching", Params::new().with("step", 0.0), "ray_marching.step"),
        ("ray_marching", Params::new().with("jitter", 0.5), "ray_marching.jitter"),
    ] {
        let err = (builtins::estimator(id).unwrap().build)(&p).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(err.contains(field), "{id}: {err}");
    }
    // The shared ids still take their other halves' parameters.
    assert!((builtins::estimator("mis").unwrap().build)(&Params::new().with("power", 2.0)).is_ok());
    let bed = bed(Params::new().with("resolution", 4.0));
    let err = build("delta_tracking", Params::new().with("sigma_samp", 0.5)).validate(&bed).unwrap_err().to_string();
    assert!(err.contains("delta_tracking.sigma_samp"), "{err}");
}

/// `supports()` accepts exactly the seven ids on a single-scatter bed and refuses the new ids
/// elsewhere; the shared ids keep serving their other test beds.
#[test]
fn supports_accepts_the_single_scatter_ids_only() {
    let single = bed(Params::new().with("resolution", 2.0));
    let transmittance = MediumBed::new(
        Field::Eq21,
        "transmittance",
        &Params::new().with("resolution", 2.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    let checker = (builtins::testbed("checker-direct").unwrap().build)(
        "default",
        &Params::new().with("resolution", 2.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    for entry in ESTIMATORS {
        let Ok(est) = (entry.build)(&Params::new()) else { continue };
        let runs = entry.skip_reason(single.provides()).is_none() && est.supports(&single).is_ok();
        assert_eq!(runs, IDS.contains(&entry.id), "{} on single-scatter", entry.id);
    }
    for id in ["attenuation_driven", "attenuation_driven_sir", "source_driven", "scattering_driven"] {
        let entry = builtins::estimator(id).unwrap();
        let est = (entry.build)(&Params::new()).unwrap();
        assert!(entry.skip_reason(transmittance.provides()).is_some() || est.supports(&transmittance).is_err(), "{id}");
    }
    assert!(build("ray_marching", Params::new()).supports(&transmittance).is_ok());
    assert!(build("delta_tracking", Params::new()).supports(&transmittance).is_ok());
    assert!(build("mis", Params::new()).supports(&transmittance).is_err());
    assert!(build("mis", Params::new()).supports(checker.as_ref()).is_ok());
}

/// Costs: one sample per primary ray, shadow rays counted as rays, a ray missing the medium is
/// exact and costs one sample, and ray marching under a fetch budget marches exactly one primary
/// ray spending about the budget (or, with an explicit step, as many rays as the budget buys).
#[test]
fn costs_are_counted() {
    let bed = bed(Params::new().with("resolution", 4.0));
    let task = Task::new(&bed, 0, Budget::new(BudgetKind::Fetches, 50).unwrap());
    assert_eq!(build("mis", Params::new()).estimate(&task, &mut stream(1, "miss")).unwrap()[0], 0.0);
    assert_eq!((task.costs().samples, task.costs().fetches), (1, 0));
    let task = Task::new(&bed, 5, Budget::samples(20).unwrap());
    build("mis", Params::new()).estimate(&task, &mut stream(2, "mis")).unwrap();
    let c = task.costs();
    assert_eq!(c.samples, 20);
    assert!(c.rays > c.samples && c.rays <= 3 * c.samples, "{c:?}");
    for budget in [50u64, 300] {
        let task = Task::new(&bed, 5, Budget::new(BudgetKind::Fetches, budget).unwrap());
        build("ray_marching", Params::new()).estimate(&task, &mut stream(3, "rm")).unwrap();
        let f = task.costs().fetches as f64;
        assert_eq!(task.costs().samples, 1);
        assert!((0.6 * budget as f64..1.5 * budget as f64).contains(&f), "{budget}: {f}");
    }
    // Without jitter the marcher is deterministic (the paper's noise-free marcher).
    let fixed = build("ray_marching", Params::new().with("jitter", 0.0));
    let runs: Vec<f64> = (0..2)
        .map(|k| {
            let task = Task::new(&bed, 5, Budget::new(BudgetKind::Fetches, 100).unwrap());
            fixed.estimate(&task, &mut stream(k, "rm0")).unwrap()[0]
        })
        .collect();
    assert_eq!(runs[0], runs[1]);
    // An explicit step keeps the step under a fetch budget: the budget buys more rays.
    let task = Task::new(&bed, 5, Budget::new(BudgetKind::Fetches, 300).unwrap());
    build("ray_marching", Params::new().with("step", 5.0)).estimate(&task, &mut stream(4, "rm5")).unwrap();
    assert!(task.costs().samples > 5 && task.costs().fetches >= 300, "{:?}", task.costs());
}

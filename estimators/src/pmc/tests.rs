//! Small-size unbiasedness of the paper 003 estimators on `checker-direct` (fixed seeds, a
//! one-sample t-test per pixel with Holm-Bonferroni at family-wise alpha 1e-3), beside controls
//! that must be flagged: the clamped independent-MC control and a threshold-stopping adaptive
//! sampler of the kind paper 003 §2 criticises (Kirk and Arvo 1991).

use crate::builtins;
use mcbench_core::budget::Budget;
use mcbench_core::estimator::Estimator;
use mcbench_core::math::{Frame, Rgb};
use mcbench_core::params::Params;
use mcbench_core::rng::{StreamKey, StreamRng};
use mcbench_core::samplers::uniform_hemisphere;
use mcbench_core::stats::{holm_bonferroni, one_sample_t, Moments};
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;

const REPS: usize = 400;

/// Smallest Holm-adjusted p-value over the pixels (channel 0: the scene is grey).
fn min_holm_p(bed: &dyn TestBed, est: &dyn Estimator, name: &str, spp: u64) -> f64 {
    let mut ps = Vec::new();
    for i in 0..bed.integrals() {
        let mut m = Moments::default();
        for rep in 0..REPS {
            let key = StreamKey {
                seed: 9,
                testbed: "checker",
                estimator: name,
                budget: spp,
                rep: rep as u64,
                integral: i as u64,
            };
            let task = Task::new(bed, i, Budget::samples(spp).unwrap());
            let v = est.estimate(&task, &mut key.rng()).unwrap();
            assert!(v.is_finite());
            assert!(task.costs().samples <= spp);
            m.push(v[0]);
        }
        let r = bed.reference().value[i][0];
        ps.push(if m.std_err() == 0.0 {
            if m.mean() == r {
                1.0
            } else {
                0.0
            }
        } else {
            one_sample_t(m.mean(), m.std_err(), REPS as u64, r).p_value
        });
    }
    holm_bonferroni(&ps).into_iter().fold(1.0, f64::min)
}

fn bed(variant: &str) -> Box<dyn TestBed> {
    (builtins::testbed("checker-direct").unwrap().build)(
        variant,
        &Params::new().with("resolution", 5.0),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap()
}

fn check(id: &str, params: Params, spp: u64) -> (f64, f64) {
    let est = (builtins::estimator(id).unwrap().build)(&params).unwrap();
    let a = min_holm_p(bed("default").as_ref(), est.as_ref(), id, spp);
    let b = min_holm_p(bed("occluded").as_ref(), est.as_ref(), id, spp);
    eprintln!("{id}: smallest Holm-adjusted p default {a:.3e}, occluded {b:.3e}");
    (a, b)
}

#[test]
fn mis_and_pmc_hi_pass_and_the_controls_are_flagged() {
    for (id, params, spp) in [
        ("mis", Params::new(), 16),
        ("mis", Params::new().with("power", 2.0), 16),
        ("pmc_hi", Params::new(), 24),
        ("pmc_hi_feedback", Params::new(), 32),
    ] {
        let (a, b) = check(id, params, spp);
        assert!(a > 1e-3 && b > 1e-3, "{id} flagged as biased: {a:e} {b:e}");
    }
    let (a, _) = check("clamped_is0_cv0", Params::new(), 16);
    assert!(a < 1e-6, "the clamped control is not flagged: {a:e}");
}

/// A threshold-stopping adaptive sampler (paper 003 §2): uniform hemisphere samples, stopping as
/// soon as (after 4 samples) the relative standard error falls below 10% or the samples are all
/// zero. Whether to stop depends on the samples themselves, so the estimate is biased low where a
/// small bright light is rarely hit.
struct ThresholdStop;

impl Estimator for ThresholdStop {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, mcbench_core::error::EstimateError> {
        let probe = task.hemisphere().unwrap();
        let frame = Frame::around(probe.point().normal);
        let mut m = Moments::default();
        while task.more() {
            let l = uniform_hemisphere::sample_local(rng);
            m.push(probe.integrand(frame.to_world(l))[0] / uniform_hemisphere::pdf(l.z));
            if m.count() >= 4 && (m.mean() == 0.0 || m.std_err() < 0.1 * m.mean()) {
                break;
            }
        }
        Ok(Rgb::splat(m.mean()))
    }
}

#[test]
fn a_threshold_stopping_sampler_is_detected_as_biased() {
    let p = min_holm_p(bed("default").as_ref(), &ThresholdStop, "threshold", 256);
    eprintln!("threshold-stopping sampler: smallest Holm-adjusted p {p:.3e}");
    assert!(p < 1e-6, "not flagged: {p:e}");
}

/// PMC evaluates its target once per population member: PMC-HI the integrand of each weight
/// `f / K` (Eq. 8), PMC-IP each pixel sample; the independent and threshold samplers weight
/// nothing by a target, and no paper 003 estimator keeps a radiance cache.
#[test]
fn pmc_evaluates_its_target_once_per_sample() {
    let b = bed("default");
    for (id, per_sample) in [("pmc_hi", 1), ("pmc_hi_feedback", 1), ("mis", 0)] {
        let est = (builtins::estimator(id).unwrap().build)(&Params::new()).unwrap();
        for spp in [1u64, 7, 64] {
            let task = Task::new(b.as_ref(), 12, Budget::samples(spp).unwrap());
            est.estimate(&task, &mut mcbench_core::rng::stream(spp, id)).unwrap();
            let c = task.costs();
            assert_eq!((c.target_evals, c.cache_ops), (per_sample * c.samples, 0), "{id} at {spp} spp");
        }
    }
    let image = (builtins::testbed("checker-image").unwrap().build)(
        "default",
        &Params::new(),
        &crate::built_in_references::BUILT_IN,
    )
    .unwrap();
    for (id, per_sample) in [("pmc_ip", 1), ("uniform_image", 0), ("threshold_image", 0)] {
        let est = (builtins::estimator(id).unwrap().build)(&Params::new()).unwrap();
        let tasks: Vec<Task<'_>> =
            (0..image.integrals()).map(|i| Task::new(image.as_ref(), i, Budget::samples(10).unwrap())).collect();
        est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(3, id)).unwrap();
        let (evals, samples) =
            tasks.iter().fold((0, 0), |(e, s), t| (e + t.costs().target_evals, s + t.costs().samples));
        assert!(samples > 0, "{id}");
        assert_eq!(evals, per_sample * samples, "{id}");
    }
}

//! Unbiasedness tests of the surface SMC ids (book: statistics.md) with teeth, and parameter handling.

use super::*;
use crate::builtins;
use crate::testbeds::gradient_plane::GradientPlane;
use mcbench_core::budget::Budget;
use mcbench_core::rng::StreamKey;
use mcbench_core::stats::{holm_bonferroni, one_sample_t, Moments};
use mcbench_core::testbed::TestBed;

/// Family-wise level of the unbiasedness tests (book: statistics.md).
const ALPHA: f64 = 1e-3;

/// The outcome of one unbiasedness run: Holm-adjusted smallest p-value over pixels and channels,
/// and the largest relative bias the run could have missed (power 0.5 at ALPHA, per test).
struct Verdict {
    min_adjusted_p: f64,
    detectable_rel_bias: f64,
}

impl Verdict {
    fn rejects(&self) -> bool {
        self.min_adjusted_p <= ALPHA
    }
}

/// `reps` independent estimates at `spp` of each pixel in `pixels` of a 4x4 gradient-plane
/// variant, a one-sample t-test per pixel and channel against the exact reference, Holm over all.
fn unbiasedness(est: &dyn Estimator, id: &str, variant: &str, pixels: &[usize], reps: u64, spp: u64) -> Verdict {
    let bed = GradientPlane::new(variant, &Params::new().with("resolution", 4.0)).unwrap();
    let budget = Budget::samples(spp).unwrap();
    let (mut p_values, mut detectable) = (Vec::new(), 0.0f64);
    for &px in pixels {
        let mut m: [Moments; 3] = Default::default();
        for rep in 0..reps {
            let key = StreamKey { seed: 2024, testbed: variant, estimator: id, budget: spp, rep, integral: px as u64 };
            let task = Task::new(&bed, px, budget);
            let v = est.estimate(&task, &mut key.rng()).unwrap();
            for ch in 0..3 {
                m[ch].push(v[ch]);
            }
        }
        let reference = bed.reference().value[px];
        for ch in 0..3 {
            p_values.push(one_sample_t(m[ch].mean(), m[ch].std_err(), reps, reference[ch]).p_value);
            detectable = detectable
                .max(mcbench_core::stats::detectable_shift(m[ch].std_err(), ALPHA, 0.5) / reference[ch].abs());
        }
    }
    let min_adjusted_p = holm_bonferroni(&p_values).into_iter().fold(1.0, f64::min);
    eprintln!(
        "{id} on {variant}: {reps} x {spp} spp, min Holm p {min_adjusted_p:.3e}, detectable bias {detectable:.4}"
    );
    Verdict { min_adjusted_p, detectable_rel_bias: detectable }
}

fn build(id: &str, params: &Params) -> Box<dyn Estimator> {
    (builtins::estimator(id).unwrap().build)(params).unwrap()
}

const NEW_IDS: [&str; 6] = ["is0_cv1", "is0_cv2", "is1_cv0", "is1_cv1", "is1_cv2", "brdf_is1_cv2"];
const ALL_PIXELS: [usize; 16] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];

/// Default variant: every new id passes at 16 spp (the cache refines twice within the budget),
/// and the same test, same size, flags the clamped control.
#[test]
fn unbiased_on_the_default_variant_and_the_control_is_flagged() {
    for id in NEW_IDS {
        let v = unbiasedness(build(id, &Params::new()).as_ref(), id, "default", &ALL_PIXELS, 4000, 16);
        assert!(!v.rejects(), "{id}: Holm-adjusted p = {:e}", v.min_adjusted_p);
        assert!(v.detectable_rel_bias < 0.02, "{id}: the run only detects {:.3} relative bias", v.detectable_rel_bias);
    }
    let control = unbiasedness(
        build("clamped_is0_cv0", &Params::new()).as_ref(),
        "clamped_is0_cv0",
        "default",
        &ALL_PIXELS,
        4000,
        16,
    );
    assert!(control.rejects(), "the clamped control was not flagged: p = {:e}", control.min_adjusted_p);
}

/// The snapshot rule has teeth: the same estimator reading the cache *after* adding its record is
/// biased, and the test flags it at the size that passes the correct one.
#[test]
fn reading_the_cache_after_the_record_is_flagged() {
    let est = SmcSurface::from_params(Sampling::Cache, ControlVariate::Bilinear, &SurfaceSmcParams::default())
        .reading_after_record();
    let v = unbiasedness(&est, "is1_cv2_after", "default", &ALL_PIXELS, 4000, 16);
    assert!(v.rejects(), "post-record snapshot not flagged: p = {:e}", v.min_adjusted_p);
}

/// Stiff variant (Phong n = 10000): finite and unbiased. The lobe covers 1e-4 of the hemisphere, so
/// uniform-start estimators hit it rarely and a t-test needs many repetitions to be valid; four
/// pixels at 16 spp with 20000 repetitions give about 30 lobe hits per pixel for the uniform ones.
#[test]
fn unbiased_on_the_stiff_variant_and_the_control_is_flagged() {
    let pixels = [0, 5, 10, 15];
    for id in NEW_IDS {
        let v = unbiasedness(build(id, &Params::new()).as_ref(), id, "stiff", &pixels, 20_000, 16);
        assert!(!v.rejects(), "{id}: Holm-adjusted p = {:e}", v.min_adjusted_p);
    }
    let control = unbiasedness(
        build("clamped_is0_cv0", &Params::new()).as_ref(),
        "clamped_is0_cv0",
        "stiff",
        &pixels,
        20_000,
        16,
    );
    assert!(control.rejects(), "the clamped control was not flagged on stiff: p = {:e}", control.min_adjusted_p);
}

/// Single precision storage is unbiased too, and reports half-size cells.
#[test]
fn f32_storage_is_unbiased_and_smaller() {
    let mut params = Params::new();
    params.0.insert("storage".into(), mcbench_core::params::ParamValue::Text("f32".into()));
    let v = unbiasedness(build("is1_cv2", &params).as_ref(), "is1_cv2_f32", "default", &ALL_PIXELS, 600, 64);
    assert!(!v.rejects(), "f32: Holm-adjusted p = {:e}", v.min_adjusted_p);
    let bed = GradientPlane::new("default", &Params::new().with("resolution", 4.0)).unwrap();
    let cell_bytes = |p: &Params| {
        let task = Task::new(&bed, 3, Budget::samples(1024).unwrap());
        build("is1_cv2", p).estimate(&task, &mut mcbench_core::rng::stream(1, "bytes")).unwrap();
        let d = task.diagnostics();
        let get = |n: &str| d.iter().find(|(k, _)| *k == n).map(|(_, v)| *v).unwrap();
        (get("cell_bytes"), get("cells"), get("refinements"))
    };
    let (b64, cells, depth) = cell_bytes(&Params::new());
    let (b32, _, _) = cell_bytes(&params);
    // Paper 001 Table 1: criterion 8 reaches depth 4, 256 cells, 9 KB (36 bytes per cell).
    assert_eq!((cells, depth, b64, b32), (256.0, 4.0, 9216.0, 5120.0));
}

#[test]
fn parameters_are_validated_and_named() {
    for id in NEW_IDS {
        let entry = builtins::estimator(id).unwrap();
        assert!((entry.build)(&Params::new()).is_ok());
        let err = |p: Params| (entry.build)(&p).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(err(Params::new().with("criterion", 0.5)).contains("criterion"));
        assert!(err(Params::new().with("max_depth", 13.0)).contains("max_depth"));
        assert!(err(Params::new().with("bogus", 1.0)).contains("bogus"));
    }
    let p = parse::<CacheSmcParams>("is1_cv2", &Params::new().with("criterion", 16.0)).unwrap();
    let est = SmcSurface::from_params(Sampling::Cache, ControlVariate::Bilinear, &p.surface());
    assert_eq!((est.config().criterion, est.config().max_depth), (16.0, 8));
    assert_eq!((p.medium().criterion, p.medium().max_depth), (16.0, 5));
}

/// Paper 001's cache operations are exact: every sample reads the pixel's cache once (`G`, the
/// drawn direction, `g`) and writes one record, and every refinement is one more. Four samples
/// stay below the criterion (8 records per cell), so the cache of one cell never refines.
#[test]
fn cache_operations_are_a_read_and_a_record_per_sample_plus_refinements() {
    let bed = GradientPlane::new("default", &Params::new().with("resolution", 4.0)).unwrap();
    for id in ["is0_cv1", "is0_cv2", "is1_cv0", "is1_cv1", "is1_cv2"] {
        let est = build(id, &Params::new());
        let task = Task::new(&bed, 5, Budget::samples(4).unwrap());
        est.estimate(&task, &mut mcbench_core::rng::stream(1, id)).unwrap();
        assert_eq!(task.costs().cache_ops, 8, "{id}");
        for spp in [64u64, 1024] {
            let task = Task::new(&bed, 5, Budget::samples(spp).unwrap());
            est.estimate(&task, &mut mcbench_core::rng::stream(2, id)).unwrap();
            let refinements = task.diagnostics().iter().find(|(n, _)| *n == "refinements").unwrap().1 as u64;
            assert!(refinements > 0, "{id} at {spp} spp refined");
            assert_eq!(task.costs().cache_ops, 2 * spp + refinements, "{id} at {spp} spp");
            assert_eq!(task.costs().target_evals, 0, "{id}");
        }
    }
    // The tracked estimator records every sample whose direction lies in the cache's hemisphere
    // (a BRDF draw below the horizon has none): between one and two operations per sample.
    let task = Task::new(&bed, 5, Budget::samples(256).unwrap());
    build("brdf_is1_cv2", &Params::new()).estimate(&task, &mut mcbench_core::rng::stream(3, "tracked")).unwrap();
    let refinements = task.diagnostics().iter().find(|(n, _)| *n == "refinements").unwrap().1 as u64;
    let ops = task.costs().cache_ops - refinements;
    assert!((256..=512).contains(&ops), "{ops}");
    // The independent estimators keep no cache.
    for id in ["is0_cv0", "brdf_is0_cv0"] {
        let task = Task::new(&bed, 5, Budget::samples(64).unwrap());
        build(id, &Params::new()).estimate(&task, &mut mcbench_core::rng::stream(4, id)).unwrap();
        assert_eq!((task.costs().cache_ops, task.costs().target_evals), (0, 0), "{id}");
    }
}

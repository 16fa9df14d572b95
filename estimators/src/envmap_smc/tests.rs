//! Unbiasedness of the paper 004 estimators against the exact reference at a small size
//! (per-integral one-sample t-tests, Holm-Bonferroni at family-wise alpha 1e-3), with the
//! biased control flagged; and the all-weights-zero fallback.

use crate::builtins;
use mcbench_core::brdf::Phong;
use mcbench_core::budget::Budget;
use mcbench_core::envmap::{EnvFrame, EnvMap};
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::Params;
use mcbench_core::rng::StreamKey;
use mcbench_core::stats::{holm_bonferroni, one_sample_t, Moments};
use mcbench_core::task::Task;
use mcbench_core::testbed::{EnvQuantity, EnvSequenceScene, Needs, Reference, ReferenceKind, ShadingPoint, TestBed};

fn bed(variant: &str) -> Box<dyn TestBed> {
    let p = Params::new()
        .with("resolution", 2.0)
        .with("frames", 4.0)
        .with("env_width", 64.0)
        .with("env_height", 32.0)
        .with("sun", 200.0);
    (builtins::testbed("envmap-sequence").unwrap().build)(variant, &p, &crate::built_in_references::BUILT_IN).unwrap()
}

/// Smallest Holm-adjusted p-value of an estimator's per-integral t-tests over `reps` runs.
fn holm_p(bed: &dyn TestBed, id: &str, params: Params, n: u64, reps: u64) -> f64 {
    let est = (builtins::estimator(id).unwrap().build)(&params).unwrap();
    let f = bed.sequence_length();
    let mut m = vec![[Moments::default(), Moments::default(), Moments::default()]; bed.integrals()];
    for rep in 0..reps {
        for s in 0..bed.integrals() / f {
            let mut rng =
                StreamKey { seed: 9, testbed: "t", estimator: id, budget: n, rep, integral: (s * f) as u64 }.rng();
            let tasks: Vec<Task<'_>> =
                (s * f..(s + 1) * f).map(|i| Task::new(bed, i, Budget::samples(n).unwrap())).collect();
            for (k, v) in est.estimate_sequence(&tasks, &mut rng).unwrap().into_iter().enumerate() {
                assert!(v.is_finite());
                for c in 0..3 {
                    m[s * f + k][c].push(v[c]);
                }
            }
        }
    }
    let r = bed.reference();
    let bound = match &r.kind {
        ReferenceKind::Exact { bound, .. } => *bound,
        ReferenceKind::Stored { .. } => 0.0,
    };
    let ps: Vec<f64> = m
        .iter()
        .enumerate()
        .flat_map(|(i, mi)| (0..3).map(move |c| (i, c, mi[c].clone())))
        .map(|(i, c, mc)| {
            // As the harness: a constant estimate within the reference's error bound is no evidence.
            if mc.std_err() == 0.0 && (mc.mean() - r.value[i][c]).abs() <= bound {
                1.0
            } else {
                one_sample_t(mc.mean(), mc.std_err(), reps, r.value[i][c]).p_value
            }
        })
        .collect();
    holm_bonferroni(&ps).into_iter().fold(1.0, f64::min)
}

#[test]
fn bidirectional_is_is_unbiased_for_lr_and_lns() {
    for variant in ["mixed", "specular-lns"] {
        let p = holm_p(bed(variant).as_ref(), "bidirectional_is", Params::new().with("candidates", 16.0), 4, 3000);
        assert!(p > 1e-3, "{variant}: p = {p}");
    }
}

#[test]
fn smc_and_smc_bridge_are_unbiased() {
    let b = bed("mixed");
    for (id, params) in [("smc", Params::new().with("moves", 2.0)), ("smc_bridge", Params::new().with("bridges", 3.0))]
    {
        let p = holm_p(b.as_ref(), id, params.with("candidates", 16.0), 4, 3000);
        assert!(p > 1e-3, "{id}: p = {p}");
    }
}

/// Teeth: the self-normalised control at M = 2 is flagged by the same test.
#[test]
fn the_self_normalised_control_is_flagged() {
    let p = holm_p(bed("mixed").as_ref(), "bidirectional_is_sn", Params::new().with("candidates", 2.0), 4, 3000);
    assert!(p < 1e-3, "p = {p}");
}

/// A scene whose lit band moves a quarter turn each frame: every particle of frame n-1 lands on
/// black in frame n, so every incremental weight is zero.
struct QuarterTurn {
    map: EnvMap,
    point: ShadingPoint,
    reference: Reference,
}

impl TestBed for QuarterTurn {
    fn id(&self) -> &'static str {
        "quarter-turn"
    }
    fn variant(&self) -> &str {
        "default"
    }
    fn provides(&self) -> Needs {
        Needs::ENV_SEQUENCE
    }
    fn resolution(&self) -> (usize, usize) {
        (1, 1)
    }
    fn reference(&self) -> &Reference {
        &self.reference
    }
    fn env_sequence(&self) -> Option<&dyn EnvSequenceScene> {
        Some(self)
    }
    fn sequence_length(&self) -> usize {
        3
    }
}

impl EnvSequenceScene for QuarterTurn {
    fn frames(&self) -> usize {
        3
    }
    fn quantity(&self) -> EnvQuantity {
        EnvQuantity::Reflected
    }
    fn shading(&self, _pixel: usize) -> ShadingPoint {
        self.point
    }
    fn environment(&self, frame: usize) -> EnvFrame<'_> {
        EnvFrame { map: &self.map, rotation: frame as f64 * std::f64::consts::FRAC_PI_2, scale: 1.0 }
    }
    fn visible(&self, _pixel: usize, wi: Vec3) -> bool {
        wi.z >= 0.0
    }
}

#[test]
fn every_incremental_weight_zero_falls_back_without_nan() {
    let (w, h) = (16, 8);
    let texels = (0..w * h).map(|t| if t % w < 2 && t / w < 4 { Rgb::splat(5.0) } else { Rgb::ZERO }).collect();
    let scene = QuarterTurn {
        map: EnvMap::new(w, h, texels).unwrap(),
        point: ShadingPoint {
            position: Vec3::default(),
            normal: Vec3::Z,
            wo: Vec3::Z,
            brdf: Phong { kd: Rgb::splat(0.8), ks: Rgb::ZERO, n: 1.0 },
        },
        reference: Reference {
            kind: ReferenceKind::Exact { method: String::new(), bound: 0.0 },
            value: vec![Rgb::ZERO; 3],
            std_err: vec![Rgb::ZERO; 3],
        },
    };
    for id in ["smc", "smc_bridge", "smc_path", "smc_adaptive"] {
        let est = (builtins::estimator(id).unwrap().build)(&Params::new()).unwrap();
        let tasks: Vec<Task<'_>> = (0..3).map(|i| Task::new(&scene, i, Budget::samples(8).unwrap())).collect();
        let v = est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(1, "fallback")).unwrap();
        assert!(v.iter().all(|x| x.is_finite() && x[0] > 0.0), "{id}: {v:?}");
        for t in &tasks[1..] {
            assert_eq!(t.diagnostics().iter().find(|(n, _)| *n == "fallback").map(|d| d.1), Some(1.0), "{id}");
        }
    }
}

/// Stability: sun dynamic range above 1e6 and 30 degree rotations per frame;
/// every estimator returns finite estimates, and the unbiased ones stay unbiased.
#[test]
fn stable_under_a_1e6_sun_and_30_degree_rotations() {
    let p = Params::new()
        .with("resolution", 2.0)
        .with("frames", 4.0)
        .with("env_width", 128.0)
        .with("env_height", 64.0)
        .with("sun", 1e5)
        .with("rotation", 30.0);
    let b =
        (builtins::testbed("envmap-sequence").unwrap().build)("specular", &p, &crate::built_in_references::BUILT_IN)
            .unwrap();
    for id in ["bidirectional_is", "smc", "smc_bridge", "smc_path", "smc_adaptive"] {
        let est = (builtins::estimator(id).unwrap().build)(&Params::new()).unwrap();
        for rep in 0..20 {
            let tasks: Vec<Task<'_>> = (0..4).map(|i| Task::new(b.as_ref(), i, Budget::samples(8).unwrap())).collect();
            let v = est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(rep, id)).unwrap();
            assert!(v.iter().all(|x| x.is_finite() && x.0.iter().all(|c| *c >= 0.0)), "{id}: {v:?}");
        }
    }
    let mixed =
        (builtins::testbed("envmap-sequence").unwrap().build)("mixed", &p, &crate::built_in_references::BUILT_IN)
            .unwrap();
    for (id, params) in [("bidirectional_is", Params::new()), ("smc", Params::new().with("moves", 2.0))] {
        let p = holm_p(mixed.as_ref(), id, params.with("candidates", 16.0), 4, 1500);
        eprintln!("stability (sun 1e5, 30 degrees a frame) {id}: Holm p = {p:e}");
        if id == "bidirectional_is" {
            assert!(p > 1e-3, "{id}: p = {p}");
        }
    }
}

/// The target evaluations of one pixel's frames under `id`, with its estimates' `fallback` notes.
fn frame_counts(id: &str, params: Params, n: u64) -> Vec<(u64, u64, bool)> {
    let b = bed("mixed");
    let est = (builtins::estimator(id).unwrap().build)(&params).unwrap();
    let f = b.sequence_length();
    let tasks: Vec<Task<'_>> = (0..f).map(|i| Task::new(b.as_ref(), i, Budget::samples(n).unwrap())).collect();
    est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(5, id)).unwrap();
    tasks
        .iter()
        .map(|t| {
            let c = t.costs();
            (c.target_evals, c.samples, t.diagnostics().iter().any(|(name, v)| *name == "fallback" && *v > 0.0))
        })
        .collect()
}

/// Bidirectional importance sampling evaluates the target once per candidate on every frame:
/// M per frame, whatever N.
#[test]
fn bidirectional_is_evaluates_the_target_once_per_candidate() {
    for (m, n) in [(16u64, 4u64), (128, 8)] {
        for (evals, samples, _) in frame_counts("bidirectional_is", Params::new().with("candidates", m as f64), n) {
            assert_eq!((evals, samples), (m, m), "M = {m}, N = {n}");
        }
    }
}

/// SMC (Algorithm 1): the first frame is bidirectional (M evaluations); every later frame
/// reweights the N carried particles (N evaluations, Eq. 3) and moves each K times (one
/// evaluation per MH proposal, local or independent): N (1 + K).
#[test]
fn smc_evaluates_the_target_at_each_reweight_and_each_move() {
    let (m, n) = (16u64, 6u64);
    for k in [1u64, 3] {
        let counts = frame_counts("smc", Params::new().with("candidates", m as f64).with("moves", k as f64), n);
        assert_eq!(counts[0].0, m, "K = {k}: frame 0");
        for (frame, (evals, samples, fallback)) in counts.iter().enumerate().skip(1) {
            assert!(!fallback, "K = {k}: frame {frame} fell back");
            assert_eq!(*evals, n * (1 + k), "K = {k}: frame {frame}");
            assert_eq!(evals, samples, "every sample of paper 004 is one target evaluation");
        }
    }
}

/// SMC with P bridges (Algorithm 2): N reweighting evaluations, then per bridge one MH move per
/// particle that evaluates both frames' products at its proposal (Eq. 11): N (1 + 2P).
#[test]
fn bridged_smc_evaluates_both_frames_at_each_proposal() {
    let (m, n, p) = (16u64, 5u64, 3u64);
    let counts = frame_counts("smc_bridge", Params::new().with("candidates", m as f64).with("bridges", p as f64), n);
    assert_eq!(counts[0].0, m);
    for (frame, (evals, _, fallback)) in counts.iter().enumerate().skip(1) {
        assert!(!fallback, "frame {frame} fell back");
        assert_eq!(*evals, n * (1 + 2 * p), "frame {frame}");
    }
}

/// Counting does not draw random numbers or change an estimate: two runs from the same stream
/// agree bit for bit, and no cache operation is counted where there is no cache.
#[test]
fn counted_runs_repeat_bit_for_bit_and_count_no_cache() {
    let b = bed("mixed");
    let est = (builtins::estimator("smc").unwrap().build)(&Params::new()).unwrap();
    let run = || {
        let tasks: Vec<Task<'_>> = (0..4).map(|i| Task::new(b.as_ref(), i, Budget::samples(8).unwrap())).collect();
        let v = est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(11, "repeat")).unwrap();
        (v, tasks.iter().map(Task::costs).collect::<Vec<_>>())
    };
    let (a, b2) = (run(), run());
    assert_eq!(a, b2);
    assert!(a.1.iter().all(|c| c.cache_ops == 0 && c.target_evals > 0), "{:?}", a.1);
}

/// `recompute`: every that many frames `L_ns` is estimated afresh from M environment-map
/// candidates (paper 004 §7), M more target evaluations on those frames only, noted as
/// `recomputed`; the other frames cost what they did.
#[test]
fn recompute_adds_m_target_evaluations_on_its_frames() {
    let (m, n, k) = (16u64, 6u64, 2u64);
    let base = Params::new().with("candidates", m as f64).with("recompute", 2.0);
    for (id, params, per_frame) in [
        ("smc", base.clone().with("moves", k as f64), n * (1 + k)),
        ("smc_bridge", base.clone().with("bridges", k as f64), n * (1 + 2 * k)),
        ("smc_path", base.with("bridges", k as f64), n * (1 + 2 * k)),
    ] {
        let b = bed("mixed");
        let est = (builtins::estimator(id).unwrap().build)(&params).unwrap();
        let tasks: Vec<Task<'_>> = (0..4).map(|i| Task::new(b.as_ref(), i, Budget::samples(n).unwrap())).collect();
        est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(5, id)).unwrap();
        for (frame, t) in tasks.iter().enumerate().skip(1) {
            let again = frame == 2;
            let noted = t.diagnostics().iter().any(|(name, v)| *name == "recomputed" && *v > 0.0);
            assert_eq!(noted, again, "{id} frame {frame}");
            let extra = if again { m } else { 0 };
            assert_eq!(t.costs().target_evals, per_frame + extra, "{id} frame {frame}");
        }
    }
}

/// A `recompute` that never fires draws nothing: the estimates are the default's bit for bit.
#[test]
fn recompute_that_never_fires_changes_nothing() {
    let b = bed("mixed-lns");
    for id in ["smc", "smc_bridge", "smc_path"] {
        let run = |p: Params| {
            let est = (builtins::estimator(id).unwrap().build)(&p).unwrap();
            let tasks: Vec<Task<'_>> = (0..4).map(|i| Task::new(b.as_ref(), i, Budget::samples(8).unwrap())).collect();
            est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(4, id)).unwrap()
        };
        let default = run(Params::new());
        assert_eq!(default, run(Params::new().with("recompute", 0.0)), "{id}");
        assert_eq!(default, run(Params::new().with("recompute", 1000.0)), "{id}");
        assert_ne!(default[2..], run(Params::new().with("recompute", 2.0))[2..], "{id}");
    }
}

/// With `recompute = 1` every frame's `L_ns` is a fresh bidirectional estimate: the channel mean
/// of Eq. 9 on `L_ns` is exactly that normaliser (`sum_j W_j mean_c(p~_c) / p~ = 1`), so with many
/// candidates it sits on the exact reference whatever the particles did (about 1% noise at
/// M = 2^16; checked at 6%).
#[test]
fn recompute_every_frame_tracks_the_reference() {
    let b = bed("mixed-lns");
    let reference = &b.reference().value;
    for id in ["smc", "smc_path"] {
        let p = Params::new().with("recompute", 1.0).with("candidates", 65536.0);
        let est = (builtins::estimator(id).unwrap().build)(&p).unwrap();
        for pixel in 0..4 {
            let tasks: Vec<Task<'_>> =
                (0..4).map(|f| Task::new(b.as_ref(), pixel * 4 + f, Budget::samples(4).unwrap())).collect();
            let v = est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(pixel as u64, id)).unwrap();
            for (f, e) in v.iter().enumerate().skip(1) {
                let exact = reference[pixel * 4 + f].mean();
                assert!((e.mean() / exact - 1.0).abs() < 0.06, "{id} pixel {pixel} frame {f}: {} vs {exact}", e.mean());
            }
        }
    }
}

#[test]
fn recompute_is_refused_past_the_longest_sequence() {
    for id in ["smc", "smc_bridge", "smc_path"] {
        let e = (builtins::estimator(id).unwrap().build)(&Params::new().with("recompute", 1001.0)).err().unwrap();
        assert!(e.to_string().contains("recompute"), "{id}: {e}");
    }
}

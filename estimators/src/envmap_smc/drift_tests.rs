//! Tests of [`super`]: the drift rule, its costs and its default (off, bit-identical).

use super::*;
use crate::builtins;
use mcbench_core::budget::Budget;
use mcbench_core::math::Rgb;
use mcbench_core::params::Params;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;

fn bed(variant: &str) -> Box<dyn TestBed> {
    let p = Params::new()
        .with("resolution", 2.0)
        .with("frames", 5.0)
        .with("env_width", 64.0)
        .with("env_height", 32.0)
        .with("rotation", 5.0);
    (builtins::testbed("envmap-sequence").unwrap().build)(variant, &p, &crate::built_in_references::BUILT_IN).unwrap()
}

/// One pixel's sequence: the estimates and each frame's task (costs and notes).
fn run<'a>(b: &'a dyn TestBed, id: &str, p: &Params, n: u64, seed: u64) -> (Vec<Rgb>, Vec<Task<'a>>) {
    let est = (builtins::estimator(id).unwrap().build)(p).unwrap();
    let tasks: Vec<Task<'_>> = (0..5).map(|i| Task::new(b, i, Budget::samples(n).unwrap())).collect();
    let v = est.estimate_sequence(&tasks, &mut mcbench_core::rng::stream(seed, id)).unwrap();
    (v, tasks)
}

fn recomputed(t: &Task<'_>) -> bool {
    t.diagnostics().iter().any(|(name, v)| *name == "recomputed" && *v > 0.0)
}

#[test]
fn the_rule_fires_past_tau_either_way_and_never_at_zero() {
    assert!(!drifted(0.0, 5.0, 0.0), "tau 0 is off");
    assert!(!drifted(0.5, 0.5, 0.0) && !drifted(0.5, -0.5, 0.0), "at tau exactly: kept");
    assert!(drifted(0.5, 0.51, 0.0) && drifted(0.5, -0.51, 0.0));
    assert!(drifted(0.5, f64::NEG_INFINITY, 0.0) && drifted(0.5, f64::NAN, 0.0));
}

/// `drift = 0` is the default; a tau no carried estimate reaches never fires: both are the
/// default's estimates bit for bit, at the default's costs.
#[test]
fn drift_off_or_never_reached_changes_nothing() {
    let b = bed("moving");
    for id in ["smc", "smc_bridge", "smc_path"] {
        let (default, dt) = run(b.as_ref(), id, &Params::new(), 8, 3);
        for p in [Params::new().with("drift", 0.0), Params::new().with("drift", 50.0).with("recompute_candidates", 7.0)]
        {
            let (v, t) = run(b.as_ref(), id, &p, 8, 3);
            assert_eq!(default, v, "{id} {p:?}");
            assert_eq!(dt.iter().map(Task::costs).collect::<Vec<_>>(), t.iter().map(Task::costs).collect::<Vec<_>>());
            assert!(!t.iter().any(recomputed), "{id}");
        }
    }
}

/// A firing re-estimate costs exactly `recompute_candidates` target evaluations on its frame and
/// is noted `recomputed`; with a tiny tau every propagated frame of a rotating map fires (each
/// frame's carried estimate moves off the last explicit one).
#[test]
fn a_firing_rule_costs_m_target_evaluations_on_its_frame() {
    let b = bed("moving");
    let (m, n) = (37u64, 6u64);
    for id in ["smc", "smc_bridge", "smc_path"] {
        let (_, base) = run(b.as_ref(), id, &Params::new(), n, 11);
        let p = Params::new().with("drift", 1e-9).with("recompute_candidates", m as f64);
        let (_, fired) = run(b.as_ref(), id, &p, n, 11);
        assert!(!recomputed(&fired[0]), "{id}: the first frame is explicit already");
        for (frame, (a, f)) in base.iter().zip(&fired).enumerate().skip(1) {
            assert!(recomputed(f), "{id} frame {frame}");
            // The first frame and the transitions draw what they did: only the re-estimate adds.
            if frame == 1 {
                assert_eq!(f.costs().target_evals, a.costs().target_evals + m, "{id} frame {frame}");
            }
        }
    }
}

/// With a tiny tau and many candidates every propagated frame's `L_ns` is a fresh explicit
/// estimate: the channel mean of Eq. 9 on `L_ns` is exactly that normaliser, so it sits on the
/// exact reference (about 1% noise at M = 2^16; checked at 6%).
#[test]
fn re_estimates_replace_the_carried_normaliser() {
    let b = bed("moving-lns");
    let reference = &b.reference().value;
    let p = Params::new().with("drift", 1e-9).with("recompute_candidates", 65536.0);
    for id in ["smc", "smc_path"] {
        let (v, _) = run(b.as_ref(), id, &p, 4, 2);
        for (f, e) in v.iter().enumerate().skip(1) {
            let exact = reference[f].mean();
            assert!((e.mean() / exact - 1.0).abs() < 0.06, "{id} frame {f}: {} vs {exact}", e.mean());
        }
    }
}

#[test]
fn bad_drift_parameters_are_refused_naming_the_field() {
    for id in ["smc", "smc_bridge", "smc_path"] {
        let build = builtins::estimator(id).unwrap().build;
        for (field, v) in [("drift", -0.1), ("drift", 51.0), ("recompute_candidates", 0.0)] {
            let e = build(&Params::new().with(field, v)).err().expect("refused").to_string();
            assert!(e.contains(field), "{id} {field} = {v}: {e}");
        }
        assert!(build(&Params::new().with("drift", 0.3).with("recompute_candidates", 4096.0)).is_ok());
    }
}

/// A normaliser estimated afresh (by the drift rule, which decides from the carried estimate, or
/// every K frames) makes the estimate consistent, and the configuration declares so; without
/// either each estimator keeps its entry's declaration.
#[test]
fn the_drift_rule_declares_the_estimate_consistent() {
    use mcbench_core::estimator::Bias;
    for (id, entry) in [("smc", Bias::Unbiased), ("smc_bridge", Bias::Unbiased), ("smc_path", Bias::Consistent)] {
        let e = builtins::estimator(id).unwrap();
        assert_eq!(e.bias, entry, "{id}");
        let off = (e.build)(&Params::new()).unwrap();
        assert_eq!(off.bias(), None, "{id}");
        for on in [Params::new().with("drift", 0.1), Params::new().with("recompute", 2.0)] {
            assert_eq!((e.build)(&on).unwrap().bias(), Some(Bias::Consistent), "{id}");
        }
    }
}

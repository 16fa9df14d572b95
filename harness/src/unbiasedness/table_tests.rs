//! Unit tests of the `unbiasedness` table: verdict logic and the claims it feeds.

use super::*;

fn row(paper: &str, verdict: &str, p: f64) -> Row {
    let mut r = not_run("e", "t", "v", Bias::Unbiased, "x", None);
    r.paper_bias = paper.into();
    r.verdict = verdict.into();
    r.test = "holm_t".into();
    r.p_value = p;
    r.detectable_rel_bias = 0.01;
    r.reps = 100;
    r.reps_for_target = reps_for_target(0.01, 100, 1.0);
    r.rel_bias = 0.0;
    r.rel_bias_se = 0.003;
    judge(&mut r);
    r
}

#[test]
fn verdicts_follow_the_papers_claims() {
    let ok = row("unbiased", "pass", 0.5);
    assert_eq!(ok.agrees, Some(true));
    let fail = row("unbiased", "biased", 1e-6);
    assert_eq!(fail.agrees, Some(false));
    assert!(fail.note.contains("FAILS") && fail.note.contains("measured relative bias"), "{}", fail.note);
    assert_eq!(row("biased", "biased", 1e-9).agrees, Some(true));
    let missed = row("biased", "pass", 0.2);
    assert_eq!(missed.agrees, Some(false));
    assert!(missed.note.contains("NOT flagged"), "{}", missed.note);
    let consistent = row("consistent", "biased", 1e-9);
    assert_eq!(consistent.agrees, None);
    assert!(consistent.note.contains("consistent only"), "{}", consistent.note);
    let open = row("unbiased", "inconclusive", 0.4);
    assert_eq!(open.agrees, None, "inconclusive neither agrees nor fails");
    assert!(open.note.starts_with("inconclusive"), "{}", open.note);
    let weak = row("biased", "inconclusive", 0.4);
    assert_eq!(weak.agrees, Some(false), "a control that is not flagged is a miss");
}

#[test]
fn exempt_controls_are_expected_to_pass() {
    let mut r = row("biased", "pass", 0.5);
    r.estimator = "bidirectional_is_sn[candidates=5]".into();
    r.testbed = "envmap-sequence".into();
    r.variant = "mixed-lns".into();
    let registry = crate::registry::Registry::new().with_catalog(mcbench_papers::catalog());
    r.exempt = super::super::run::exemption(&registry, "bidirectional_is_sn", &r.testbed, &r.variant);
    judge(&mut r);
    assert_eq!(r.agrees, Some(true));
    assert!(r.note.starts_with("not a control here"), "{}", r.note);
    r.verdict = "biased".into();
    judge(&mut r);
    assert_eq!(r.agrees, Some(false), "an exempt control flagged is a finding, not a pass");
    let exemption = |id, bed, variant| super::super::run::exemption(&registry, id, bed, variant);
    assert!(exemption("ray_marching", "canonical-1d", "constant-T0.5").is_some());
    assert!(exemption("ray_marching", "canonical-1d", "cosine-T0.99").is_some());
    assert!(exemption("ray_marching", "canonical-1d", "cosine-T0.5").is_none());
    assert!(exemption("rm_is1_cv2", "gradient-box", "albedo-0.8").is_none());
}

#[test]
fn a_control_that_is_not_flagged_fails_its_claim() {
    let control = |verdict: &str, variant: &str| {
        let mut r = row("biased", verdict, if verdict == "biased" { 1e-9 } else { 0.3 });
        r.estimator = "clamped_is0_cv0".into();
        r.variant = variant.into();
        judge(&mut r);
        r
    };
    let held = |rows: &[Row]| {
        claims(rows).into_iter().find(|c| c.claim.contains("clamped_is0_cv0 is flagged")).and_then(|c| c.held)
    };
    let good = vec![control("biased", "a"), control("biased", "b"), row("unbiased", "pass", 0.4)];
    assert_eq!(held(&good), Some(true));
    let bad = vec![control("biased", "a"), control("pass", "b")];
    assert_eq!(held(&bad), Some(false));
    // The aggregate claim over unbiased ids fails on one flagged row.
    let all = claims(&[row("unbiased", "pass", 0.4), row("unbiased", "biased", 1e-8)]);
    assert_eq!(all.last().and_then(|c| c.held), Some(false));
    // A row's claim carries its p-value in the column of its own.
    assert_eq!((all[0].p_value, all[1].p_value), (Some(0.4), Some(1e-8)));
    // One `paper` entry per row, plus the aggregates.
    assert_eq!(claims(&good).len(), 3 + 2);
}

/// The claim over all unbiased ids is family-wise: among 330 rows, one at p = 5e-4 is flagged by
/// its own test (its row disagrees) but not after Holm over the 330; one at p = 1e-9 is.
#[test]
fn the_claim_over_unbiased_ids_is_family_wise() {
    let headline = |odd: Row| {
        let mut rows: Vec<Row> = (0..329).map(|i| row("unbiased", "pass", 0.5 + i as f64 * 1e-3)).collect();
        rows.push(odd);
        let all = claims(&rows);
        assert!(all.last().is_some_and(|c| c.claim.starts_with("papers: every estimator they call unbiased")));
        all.last().cloned().unwrap()
    };
    let chance = row("unbiased", "biased", 5e-4);
    assert_eq!(chance.agrees, Some(false), "the row's own verdict stays");
    let c = headline(chance);
    assert_eq!(c.held, None, "{}", c.note);
    assert!(c.note.contains("0 flagged after Holm-Bonferroni over the 330 rows"), "{}", c.note);
    assert!(c.note.contains("alpha 0.001 flags 1 (e on t/v (p 5.00e-4))"), "{}", c.note);
    let c = headline(row("unbiased", "biased", 1e-9));
    assert_eq!(c.held, Some(false), "{}", c.note);
    assert!(c.note.contains("1 flagged after Holm-Bonferroni") && c.note.contains("adjusted p 3.30e-7"), "{}", c.note);
    let c = headline(row("unbiased", "pass", 0.9));
    assert_eq!(c.held, Some(true), "{}", c.note);
    assert!(c.note.contains("flags 0, where 0.33 would be flagged by chance"), "{}", c.note);
}

#[test]
fn repetitions_for_a_tenth_of_a_percent() {
    assert_eq!(reps_for_target(0.01, 100, 1.0), Some(10_000.0));
    assert_eq!(reps_for_target(0.0005, 100, 1.0), Some(25.0));
    // Half the tested variance from a stored reference with 0.5% detectable on its own: no R helps.
    assert_eq!(reps_for_target(0.01, 100, 0.5), None);
    assert_eq!(reps_for_target(f64::NAN, 100, 1.0), None);
}

/// A tiny sweep end to end (well under a second): independent MC passes behind a pilot on its own
/// seed, and the clamped control is flagged.
#[test]
fn a_tiny_sweep_passes_the_estimator_and_flags_the_control() {
    use crate::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};
    use crate::plan::Plan;
    use crate::run::runner::{run, RunOptions, Silent};
    use mcbench_core::budget::Budget;
    use mcbench_core::params::Params;
    let sweep = Sweep {
        experiment: "unbiasedness-test".into(),
        testbeds: vec![TestBedSpec {
            id: "gradient-plane".into(),
            variant: Some("default".into()),
            params: Params::new().with("resolution", 2.0),
        }],
        estimators: vec![EstimatorSpec::new("is0_cv0"), EstimatorSpec::new("clamped_is0_cv0")],
        budgets: vec![Budget::samples(16).unwrap()],
        reps: 64,
        seed: 3,
        mode: Mode::Quick,
        baseline: None,
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    };
    let plan = Plan::prepare(
        sweep,
        &crate::registry::Registry::new().with_catalog(mcbench_papers::catalog()).with_references(
            crate::store::references::ReferenceDir::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../estimators/references"
            )),
        ),
    )
    .unwrap();
    let opts = RunOptions { threads: Some(1), store: None, observer: &Silent };
    let results = run(&plan, &opts).unwrap();
    let pilot_plan = Plan::prepare(
        Sweep { seed: super::super::run::pilot_seed(plan.sweep.seed), ..plan.sweep.clone() },
        &crate::registry::Registry::new().with_catalog(mcbench_papers::catalog()),
    )
    .unwrap();
    let pilot = run(&pilot_plan, &opts).unwrap();
    let reference = plan.beds[0].bed.reference();
    let rows: Vec<Row> = results
        .cells
        .iter()
        .zip(&pilot.cells)
        .map(|((_, ei, cell), (_, _, p))| {
            let gate = crate::analysis::Gate::from_cell(p, "pilot", 1.0);
            let bias = plan.estimators[*ei].bias();
            let tests = crate::analysis::unbiasedness(cell, reference, bias, Some(&gate), 0.1);
            row_from_tests(cell, bias, &tests, None)
        })
        .collect();
    assert_eq!((rows[0].verdict.as_str(), rows[0].agrees), ("pass", Some(true)), "{:?}", rows[0]);
    assert_eq!((rows[1].verdict.as_str(), rows[1].agrees), ("biased", Some(true)), "{:?}", rows[1]);
    assert!(rows[0].detectable_rel_bias > 0.0 && rows[0].gate == "pilot");
}

/// Every variant of every built-in test bed is in some part (each declares an unbiasedness case
/// for each of its variants).
#[test]
fn every_built_in_variant_is_in_a_part() {
    use crate::config::Mode;
    use crate::unbiasedness::parts;
    let registry = crate::registry::Registry::new().with_catalog(mcbench_papers::catalog());
    let in_mode = |mode: Mode, id: &str, v: &str| {
        parts(&registry, mode)
            .iter()
            .any(|p| p.sweep.testbeds.iter().any(|b| b.id == id && b.variant.as_deref() == Some(v)))
    };
    let full_only = crate::unbiasedness::full_only(&registry);
    for t in registry.test_beds() {
        for v in t.variants {
            assert!(in_mode(Mode::Full, t.id, v), "{}/{v} is in no part", t.id);
            // A variant leaves the quick mode only through a case declared full-only.
            let quick = in_mode(Mode::Quick, t.id, v);
            assert!(quick || full_only.contains(&format!("{}/{v}", t.id)), "{}/{v} is in no quick part", t.id);
        }
    }
}

#[test]
fn a_reference_made_by_the_estimator_is_recognised_from_its_command() {
    use super::super::run::made_by;
    let delta = "mcbench reference perlin-medium --variant multiple --samples 20000 (delta tracking, seed 20170001)";
    assert!(made_by(delta, "delta_tracking"));
    assert!(!made_by(delta, "ratio_tracking"));
    assert!(!made_by("an integrator without null collisions", "delta_tracking"));
}

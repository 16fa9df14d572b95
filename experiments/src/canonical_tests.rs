//! Tests of `canonical-sweep`'s analysis: the agreement verdicts, the winners' merging of exact
//! equivalents and ties, and a mini sweep end to end (the control is flagged, the trackers pass,
//! refusals keep their reason, every file is written).

use crate::canonical_cells::{Agreement, CellRow, Measured};
use crate::canonical_sweep::{family_of, spec, FAMILIES, IDS};
use crate::canonical_sweep_post::Analysis;
use crate::canonical_winners::cell_win;
use mcbench::config::{Mode, Sweep, TestBedSpec};
use mcbench::run::execute::{execute, prepare, ExecOptions};
use mcbench::run::runner::Silent;
use mcbench_core::budget::Budget;
use mcbench_core::estimator::Bias;
use mcbench_core::estimator::EstimateMoments;
use mcbench_core::params::Params;
use mcbench_papers::testbeds::canonical_profiles::Profile;

fn family(key: &str) -> usize {
    FAMILIES.iter().position(|f| f.key == key).unwrap()
}

fn row(key: &str, ratio: f64, variance: f64, predicted: EstimateMoments) -> CellRow {
    CellRow {
        profile: Profile::Hole,
        target: 0.5,
        reference: 0.5,
        family: family(key),
        ratio: Some(ratio),
        estimator: spec(&FAMILIES[family(key)], Some(ratio)).name(),
        claim: Bias::Unbiased,
        measured: Some(Measured { reps: 400, rays: 32.0, fetches: 10.0, mean: 0.5, variance, test: None }),
        predicted: Some(predicted),
        skipped: None,
    }
}

/// Normal-like moments: relative variance `v`, fourth central moment `3 v^2`.
fn normal(v: f64) -> EstimateMoments {
    EstimateMoments {
        mean: 0.5,
        rel_variance: v,
        rel_central4: 3.0 * v * v,
        rel_central3: 0.0,
        rel_central6: 15.0 * v * v * v,
    }
}

#[test]
fn agreement_verdicts_follow_the_error_bar() {
    // Error bar of the sample variance at 400 reps: V sqrt(2/399) = 7.1% of V.
    let v = 0.25 * 0.04;
    let z = |measured: f64| row("double", 1.0, measured, normal(0.04)).agreement(5.0);
    assert_eq!(z(v * 1.2), Agreement::Agrees);
    assert_eq!(z(v * 1.5), Agreement::Disagrees);
    assert_eq!(z(v * 0.6), Agreement::Disagrees);
    // Heavy tails: kurtosis 1000 gives an error bar of 1.6 V: not resolved, whatever is measured.
    let heavy = EstimateMoments { rel_central4: 1000.0 * 0.04 * 0.04, ..normal(0.04) };
    assert_eq!(row("double", 1.0, v * 0.1, heavy).agreement(5.0), Agreement::Unresolved);
    // Zero variance predicted: rounding noise agrees, a real variance does not.
    assert_eq!(row("double-cv-linear", 1.0, 1e-33, normal(0.0)).agreement(5.0), Agreement::ZeroVariance);
    assert_eq!(row("double-cv-linear", 1.0, 1e-6, normal(0.0)).agreement(5.0), Agreement::Disagrees);
    assert_eq!(
        CellRow { predicted: None, ..row("double", 1.0, v, normal(0.04)) }.agreement(5.0),
        Agreement::NotPredicted
    );
}

/// Skewed estimates (the mean of 32 exponential rays) have a right-skewed sample variance: the
/// acceptance interval shifts right by the Cornish-Fisher term g (z^2 - 1) / 6, so a high measured
/// variance that a normal error bar would reject agrees, and a low one is judged more strictly.
#[test]
fn the_acceptance_interval_follows_the_skew_of_the_sample_variance() {
    let exp =
        EstimateMoments { mean: 0.5, rel_variance: 1.0, rel_central3: 2.0, rel_central4: 9.0, rel_central6: 265.0 };
    let p = exp.mean_of(32.0);
    let (zc, reps) = (5.0, 400.0);
    let shift = p.sample_variance_skewness(reps) * (zc * zc - 1.0) / 6.0;
    assert!(shift > 0.5 && shift < 0.5 * zc, "{shift}");
    let sd = p.sample_variance_sd(reps);
    let at = |z: f64| row("double", 1.0, p.variance() + z * sd, p).agreement(zc);
    assert_eq!(at(zc + 0.5 * shift), Agreement::Agrees);
    assert_eq!(at(-zc + 0.5 * shift), Agreement::Disagrees);
    assert_eq!(at(zc + 1.5 * shift), Agreement::Disagrees);
}

#[test]
fn winners_merge_exact_equivalents_and_mark_ties() {
    let p = normal(0.04);
    let rows = vec![
        row("ratio", 2.0, 0.010, p),
        row("double", 2.0, 0.0098, p),
        row("single-nonterm", 2.0, 0.0102, p),
        row("delta", 2.0, 0.05, p),
        row("double-cv-linear", 2.0, 0.001, p),
        row("double", 0.5, 0.02, p),
        row("single-nonterm", 0.5, 0.04, p),
    ];
    let a = Analysis::new(rows, false);
    let w = cell_win(&a, Profile::Hole, 0.5, 2.0, true).unwrap();
    assert_eq!((w.label.as_str(), w.tie), ("DP+L", None));
    // Without control variates: RT and DP are one estimator at ratio >= 1; SN is within 2 error bars.
    let w = cell_win(&a, Profile::Hole, 0.5, 2.0, false).unwrap();
    assert_eq!(w.label, "RT/DP");
    assert_eq!((w.best.family, w.colour_family()), (family("double"), family("ratio")));
    assert_eq!(w.tie.as_deref(), Some("SN"));
    // Below ratio 1 the double particle model is itself (no merging) and wins clearly.
    let w = cell_win(&a, Profile::Hole, 0.5, 0.5, false).unwrap();
    assert_eq!((w.label.as_str(), w.tie), ("DP", None));
}

/// A small sweep end to end: ray marching (the control) is flagged where its bias is large, the
/// trackers pass, delta tracking below the majorant and the terminating model where r > 2/(a+1)
/// are listed with their reasons, and every file (cells, winners, heat maps) is written.
#[test]
fn a_mini_sweep_flags_the_control_and_passes_the_trackers() {
    let dir = tempfile::tempdir().unwrap();
    let with = |id: &str, control: Option<f64>, ratio: Option<f64>| {
        let f = FAMILIES.iter().find(|f| f.id == id && f.control == control).unwrap();
        spec(f, ratio)
    };
    let estimators = vec![
        with("ratio_tracking", None, Some(1.0)),
        with("delta_tracking", None, Some(0.5)),
        with("double_particle", Some(2.0), Some(0.5)),
        with("single_particle_nonterminating", None, Some(0.75)),
        with("single_particle_terminating", None, Some(1.5)),
        with("residual_ratio_tracking", Some(1.0), None),
        with("ray_marching", None, None),
    ];
    assert!(estimators.iter().all(|e| family_of(e).is_some() && IDS.contains(&e.id.as_str())));
    let bed = |v: &str| TestBedSpec { id: "canonical-1d".into(), variant: Some(v.into()), params: Params::new() };
    let sweep = Sweep {
        experiment: "canonical-sweep".into(),
        testbeds: vec![bed("linear-up-T0.1"), bed("hole-T0.5")],
        estimators,
        budgets: vec![Budget::samples(16).unwrap()],
        reps: 200,
        seed: 3,
        mode: Mode::Quick,
        baseline: None,
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    };
    let registry = crate::test_registry();
    let opts = ExecOptions {
        results_root: dir.path().join("results"),
        plots_root: dir.path().join("plots"),
        threads: Some(1),
        observer: &Silent,
        plots: true,
        wait: false,
        registry: &registry,
        integrals: Default::default(),
    };
    let def = crate::canonical_sweep::DEF.experiment();
    let out = execute(&prepare(sweep, &registry).unwrap(), Some(&def), &opts).unwrap();
    let claim = |start: &str| out.report.paper.iter().find(|c| c.claim.starts_with(start)).unwrap().clone();
    let unbiased = claim("no unbiased cell is flagged biased");
    assert_eq!(unbiased.held, Some(true), "{}", unbiased.note);
    let control = claim("harness: the biased control");
    assert_eq!((control.held, control.our_value), (Some(true), Some(2.0)), "{}", control.note);
    let cells = std::fs::read_to_string(out.results_dir.join("cells.csv")).unwrap();
    assert!(cells.contains("delta_tracking.sigma_samp_ratio = 0.5: delta_tracking needs a majorant"), "{cells}");
    assert!(cells.contains("2/(a+1)"), "the terminating model's refusal at ratio 0.75 and below is listed");
    assert!(!cells.contains("DISAGREES"), "{cells}");
    let winners = std::fs::read_to_string(out.results_dir.join("winners.md")).unwrap();
    assert!(winners.contains("## hole") && winners.contains("DP+M"), "{winners}");
    for stem in ["heat_best_estimator", "heat_var_cost", "heat_agreement"] {
        assert!(out.plots_dir.join(format!("{stem}.png")).is_file(), "{stem}");
    }
    let grid = std::fs::read_to_string(out.plots_dir.join("heat_var_cost.svg")).unwrap();
    assert!(grid.contains("profile: hole") && grid.contains("profile: linear-up"), "a heading per profile run");
    assert!(!grid.contains("profile: step"), "no panels of profiles not run");
}

/// The sweep's unbiasedness claim is family-wise: a p-value that one cell's own alpha would flag
/// is chance among many cells, while one far below alpha over the cell count is flagged.
#[test]
fn unbiased_cells_are_judged_over_the_whole_sweep() {
    use crate::canonical_cells::Verdict;
    let tested = |p: f64| {
        let mut r = row("ratio", 1.0, 0.01, normal(0.04));
        let verdict = if p < 1e-3 { "biased" } else { "inconclusive" };
        let test = Verdict { test: "combined".into(), p, verdict: verdict.into(), detectable: 0.02 };
        r.measured.as_mut().unwrap().test = Some(test);
        r
    };
    let judge = |chance: f64| {
        let mut rows: Vec<CellRow> = (0..500).map(|i| tested(0.01 + 0.9 * i as f64 / 500.0)).collect();
        rows.push(tested(chance));
        rows.push(tested(f64::NAN));
        let claims = crate::canonical_sweep_claims::claims(&Analysis::new(rows, false));
        claims.into_iter().find(|c| c.claim.starts_with("no unbiased cell is flagged")).unwrap()
    };
    let chance = judge(5e-4);
    assert_eq!((chance.held, chance.our_value), (Some(true), Some(0.0)), "{}", chance.note);
    assert!(
        chance.note.contains("the tests flag 1,") && chance.note.contains("1 without a valid test"),
        "{}",
        chance.note
    );
    let biased = judge(1e-7);
    assert_eq!((biased.held, biased.our_value), (Some(false), Some(1.0)), "{}", biased.note);
}

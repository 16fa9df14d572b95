use super::outcome::{classify, Outcome};
use super::table::SettingRow;
use super::*;
use crate::config::claim_spec::ClaimSpec;
use crate::verdict::Verdict;

const FILE: &str = r#"
name = "s"
reproduces = "r"
summary = "s"
[[parts]]
id = "a"
paper = "p"
headline = "h"
vary = "estimator.smc.moves"
values = [1, 5]
default = 5
paper_like = 1
open = "o"
testbed = { id = "envmap-sequence", variant = "mixed" }
estimators = [{ id = "smc", params = { moves = 5 } }, { id = "bidirectional_is" }]
baseline = "smc[moves=5]"
claim = { kind = "ratio", testbed = "envmap-sequence/mixed", estimator = "smc[moves=5]", baseline = "bidirectional_is", text = "smc[moves=5] wins" }
ceiling = "work_ratio"
quick = { reps = 4, budgets = [4, 16, 64] }
full = { reps = 8, budgets = [4, 16, 64, 256] }
"#;

fn file_with(replace: (&str, &str)) -> std::result::Result<SensitivityFile, String> {
    SensitivityFile::parse(&FILE.replace(replace.0, replace.1))
}

#[test]
fn settings_rewrite_the_sweep_and_the_names_the_claim_uses() {
    let f = file_with(("", "")).unwrap();
    let p = &f.parts[0];
    let (sweep, claim) = p.setting("s", 3, Mode::Quick, &p.values[0]).unwrap();
    assert_eq!((sweep.seed, sweep.reps, sweep.budgets.len()), (3, 4, 3));
    assert_eq!(sweep.estimators[0].name(), "smc[moves=1]");
    assert_eq!(sweep.baseline.as_deref(), Some("smc[moves=1]"));
    assert_eq!(claim.estimators(), vec!["smc[moves=1]", "bidirectional_is"]);
    let ClaimSpec::Ratio { text, .. } = &claim else { panic!("kind kept") };
    assert_eq!(text, "smc[moves=5] wins", "the claim's words are not renamed");

    let f = file_with((
        "vary = \"estimator.smc.moves\"\nvalues = [1, 5]\ndefault = 5\npaper_like = 1",
        "vary = \"budget_max\"\nvalues = [16, 64]\ndefault = 64",
    ))
    .unwrap();
    let p = &f.parts[0];
    assert_eq!(p.setting("s", 1, Mode::Quick, &p.values[0]).unwrap().0.budgets.len(), 2);

    let f = file_with((
        "vary = \"estimator.smc.moves\"\nvalues = [1, 5]\ndefault = 5\npaper_like = 1",
        "vary = \"variant\"\nvalues = [\"mixed\", \"specular\"]\ndefault = \"mixed\"",
    ))
    .unwrap();
    let p = &f.parts[0];
    let (sweep, claim) = p.setting("s", 1, Mode::Full, &p.values[1]).unwrap();
    assert_eq!(sweep.testbeds[0].variant.as_deref(), Some("specular"));
    assert_eq!(claim.testbed(), Some("envmap-sequence/specular"));
    assert!(p.setting("s", 1, Mode::Full, &mcbench_core::params::ParamValue::Number(2.0)).is_err());
}

#[test]
fn bad_files_are_refused_with_the_part_named() {
    let e = file_with(("default = 5", "default = 7")).unwrap_err();
    assert!(e.contains("part a") && e.contains("default 7"), "{e}");
    let e = file_with(("paper_like = 1", "paper_like = 2")).unwrap_err();
    assert!(e.contains("paper-like setting 2"), "{e}");
    let e = file_with(("vary = \"estimator.smc.moves\"", "vary = \"moves\"")).unwrap_err();
    assert!(e.contains("is not testbed"), "{e}");
    assert!(file_with(("open = \"o\"", "open = \"o\"\nextra = 1")).is_err());
    let twice = format!("{FILE}{}", &FILE[FILE.find("[[parts]]").unwrap()..]);
    assert!(SensitivityFile::parse(&twice).unwrap_err().contains("listed twice"));
}

fn row(setting: &str, role: &str, value: f64, verdict: Verdict, ceiling: Option<f64>) -> SettingRow {
    SettingRow {
        part: "a".into(),
        paper: "p".into(),
        headline: "h".into(),
        vary: "estimator.smc.moves".into(),
        setting: setting.into(),
        role: role.into(),
        testbed: "t/v".into(),
        paper_value: Some(15.3),
        value: Some(value),
        low: Some(value * 0.9),
        high: Some(value * 1.1),
        verdict,
        ceiling,
        pair: String::new(),
        regime: String::new(),
        reason: String::new(),
        bound_kind: if ceiling.is_some() { "exact".into() } else { String::new() },
        best_measured: None,
        limit: None,
    }
}

/// A setting with a best measured value and no bound.
fn measured(setting: &str, role: &str, value: f64, verdict: Verdict, best: f64) -> SettingRow {
    SettingRow {
        best_measured: Some(best),
        bound_kind: "best measured".into(),
        ..row(setting, role, value, verdict, None)
    }
}

#[test]
fn a_best_measured_value_below_the_claim_never_says_cannot_hold() {
    let f = file_with(("", "")).unwrap();
    let p = &f.parts[0];
    let (a, b) =
        (measured("1", "paper-like", 4.0, Verdict::NotHeld, 5.0), measured("5", "default", 2.0, Verdict::NotHeld, 3.0));
    let o = classify(p, &[&a, &b]);
    assert!(matches!(o, Outcome::NotHeldAnywhere { .. }), "{o:?}");
    assert!(
        o.sentence().ends_with("best measured here (not a bound) at most 5.000 at estimator.smc.moves = 1"),
        "{}",
        o.sentence()
    );
    let (a, b) = (
        measured("1", "paper-like", 4.0, Verdict::Inconclusive, 5.0),
        measured("5", "default", 2.0, Verdict::Inconclusive, 3.0),
    );
    assert!(matches!(classify(p, &[&a, &b]), Outcome::InconclusiveEverywhere { measured: Some(_), .. }));
    // A limit below the claim (a narrower family's bound) is said, and decides nothing either.
    let mut q = p.clone();
    q.limit = Some(Bound { method: "exact cache".into(), command: "c".into(), values: vec![2.0, 1.0] });
    let (a, b) = (
        SettingRow { limit: Some(2.0), ..measured("1", "paper-like", 4.0, Verdict::NotHeld, 5.0) },
        SettingRow { limit: Some(1.0), ..measured("5", "default", 2.0, Verdict::NotHeld, 3.0) },
    );
    let o = classify(&q, &[&a, &b]);
    assert!(matches!(o, Outcome::NotHeldAnywhere { .. }), "{o:?}");
    assert!(
        o.sentence()
            .ends_with("exact cache (not a bound of the claim's family) at most 2.000 at estimator.smc.moves = 1"),
        "{}",
        o.sentence()
    );
    // With a proven bound below the claim at every setting the part cannot hold, and says which.
    let mut q = p.clone();
    q.bound = Some(Bound { method: "exact cache".into(), command: "c".into(), values: vec![5.0, 3.0] });
    let (a, b) = (
        row("1", "paper-like", 4.0, Verdict::NotHeld, Some(5.0)),
        row("5", "default", 2.0, Verdict::NotHeld, Some(3.0)),
    );
    let o = classify(&q, &[&a, &b]);
    assert!(o.sentence().starts_with("cannot hold on this scene: the ceiling (exact cache)"), "{}", o.sentence());
}

#[test]
fn a_bound_needs_one_positive_value_per_setting() {
    let c = "ceiling = \"work_ratio\"";
    let ok = file_with((c, "bound = { method = \"m\", command = \"c\", values = [2.0, 3.0] }")).unwrap();
    assert_eq!(ok.parts[0].bound.as_ref().map(|b| b.values.len()), Some(2));
    let e = file_with((c, "bound = { method = \"m\", command = \"c\", values = [2.0] }")).unwrap_err();
    assert!(e.contains("part a") && e.contains("1 values for 2 settings"), "{e}");
    let e = file_with((c, "bound = { method = \"m\", command = \"c\", values = [2.0, -1.0] }")).unwrap_err();
    assert!(e.contains("not a positive number"), "{e}");
}

#[test]
fn the_outcome_is_decided_in_order() {
    let f = file_with(("", "")).unwrap();
    let p = &f.parts[0];
    let (a, b) = (
        row("1", "paper-like", 16.0, Verdict::Held, Some(20.0)),
        row("5", "default", 2.0, Verdict::NotHeld, Some(3.0)),
    );
    assert!(matches!(classify(p, &[&a, &b]), Outcome::HeldAtPaperLike { .. }));
    let (a, b) = (
        row("1", "paper-like", 4.0, Verdict::NotHeld, Some(5.0)),
        row("5", "default", 16.0, Verdict::Held, Some(30.0)),
    );
    let o = classify(p, &[&a, &b]);
    assert!(matches!(o, Outcome::HoldsWhere { .. }) && o.sentence().contains("estimator.smc.moves = 5"), "{o:?}");
    let (a, b) = (row("1", "paper-like", 4.0, Verdict::Held, None), row("5", "default", 16.0, Verdict::Held, None));
    let mut q = p.clone();
    q.paper_like = None;
    let o = classify(&q, &[&a, &b]);
    assert!(o.sentence().contains("every setting tried") && o.sentence().contains("4.000 to 16.000"), "{o:?}");
    let (a, b) = (
        row("1", "paper-like", 4.0, Verdict::NotHeld, Some(5.0)),
        row("5", "default", 2.0, Verdict::NotHeld, Some(3.0)),
    );
    let o = classify(p, &[&a, &b]);
    assert!(matches!(o, Outcome::CannotHold { .. }) && o.sentence().contains("5.000"), "{o:?}");
    let (a, b) = (
        row("1", "paper-like", 4.0, Verdict::NotHeld, Some(50.0)),
        row("5", "default", 2.0, Verdict::Inconclusive, None),
    );
    assert!(matches!(classify(p, &[&a, &b]), Outcome::NotHeldAnywhere { .. }), "a missing ceiling decides nothing");
    let mut q = p.clone();
    q.unsupportable = Some("the paper's own numbers give 3x".into());
    assert_eq!(classify(&q, &[&a, &b]).kind(), "unsupportable as written");
}

#[test]
fn a_claim_held_only_where_a_monotone_trend_passes_it_is_called_a_crossing() {
    let f = file_with(("values = [1, 5]\ndefault = 5", "values = [1, 2, 4, 8]\ndefault = 8")).unwrap();
    let p = &f.parts[0];
    let rows = |v: [f64; 4], held: [bool; 4]| -> Vec<SettingRow> {
        ["1", "2", "4", "8"]
            .iter()
            .zip(v.iter().zip(held))
            .map(|(s, (v, h))| row(s, "", *v, if h { Verdict::Held } else { Verdict::NotHeld }, None))
            .collect()
    };
    fn refs(r: &[SettingRow]) -> Vec<&SettingRow> {
        r.iter().collect()
    }
    // Decreasing through the paper's 15.3, held only at 2: a crossing between 2 and 4.
    let r = rows([20.0, 16.0, 12.0, 9.0], [false, true, false, false]);
    let o = classify(p, &refs(&r));
    assert!(
        o.sentence().contains("a crossing, not a range")
            && o.sentence().contains("passes the paper's 15.3 between 2 and 4"),
        "{}",
        o.sentence()
    );
    // Held at an end (a half-line of the trend): a range, no crossing clause.
    let r = rows([20.0, 16.0, 12.0, 9.0], [true, true, false, false]);
    assert!(!classify(p, &refs(&r)).sentence().contains("crossing"));
    // Not monotone: no trend to speak of.
    let r = rows([20.0, 16.0, 17.0, 9.0], [false, true, false, false]);
    assert!(!classify(p, &refs(&r)).sentence().contains("crossing"));
    // Inconclusive beside the held setting: not shown to fail on that side.
    let mut r = rows([20.0, 16.0, 12.0, 9.0], [false, true, false, false]);
    r[0].verdict = Verdict::Inconclusive;
    assert!(!classify(p, &refs(&r)).sentence().contains("crossing"));
}

#[test]
fn not_held_anywhere_needs_a_not_held_setting_and_inconclusive_everywhere_says_so() {
    let f = file_with(("", "")).unwrap();
    let p = &f.parts[0];
    // Every setting inconclusive (no ceiling, no reason): nothing is decided either way.
    let (a, b) = (
        row("1", "paper-like", 4.0, Verdict::Inconclusive, None),
        row("5", "default", 2.0, Verdict::Inconclusive, None),
    );
    let o = classify(p, &[&a, &b]);
    assert!(matches!(o, Outcome::InconclusiveEverywhere { .. }), "{o:?}");
    assert_eq!(o.kind(), "inconclusive at every setting tried");
    assert!(o.sentence().starts_with("inconclusive at every setting tried; the closest: "), "{}", o.sentence());
    assert!(!o.sentence().contains("not held at any"), "{}", o.sentence());
    // One setting not held, the other inconclusive, none held: not held at any setting tried.
    let (a, b) =
        (row("1", "paper-like", 4.0, Verdict::NotHeld, None), row("5", "default", 2.0, Verdict::Inconclusive, None));
    let o = classify(p, &[&a, &b]);
    assert!(matches!(o, Outcome::NotHeldAnywhere { .. }), "{o:?}");
    assert_eq!(o.kind(), "not held at any setting tried");
    // A held setting still wins over both.
    let (a, b) =
        (row("1", "paper-like", 4.0, Verdict::Inconclusive, None), row("5", "default", 2.0, Verdict::Held, None));
    assert!(matches!(classify(p, &[&a, &b]), Outcome::HoldsWhere { .. }));
}

#[test]
fn the_work_ratio_ceiling_divides_error_times_rays_by_the_claims_own_error() {
    use super::run::ceiling;
    let mut report = crate::output::plot::tests::synthetic_report();
    let template = report.rows[0].clone();
    report.rows.clear();
    // (name, budget, variance, MSE, Err, rays)
    for (name, budget, var, mse, err, rays) in [
        ("a", 16, 1.0, 1.5, 3.0, 16.0),
        ("b", 16, 2.0, 6.0, 9.0, 32.0),
        ("a", 64, 0.5, 0.5, 1.0, 64.0),
        ("b", 64, 4.0, 4.0, 8.0, 64.0),
    ] {
        let mut r = template.clone();
        (r.estimator, r.budget, r.variance, r.mse, r.p_err, r.rays) = (name.into(), budget, var, mse, err, rays);
        report.rows.push(r);
    }
    let spec = |text: &str| -> ClaimSpec {
        toml::from_str(&format!("testbed = 'gradient-plane/default'\ntext = 't'\nestimator = 'a'\n{text}"))
            .expect("claim")
    };
    // speedup: variance x rays at the largest budget, baseline from the sweep.
    let c = ceiling(Ceiling::WorkRatio, &spec("kind = 'speedup'\nvalue = 2.0"), Some("b"), &report);
    assert_eq!(c, Some(8.0));
    // ratio on efficiency_mse at the claim's budget: MSE x rays.
    let r = "kind = 'ratio'\nbaseline = 'b'\nbudget = 16\n";
    let c = ceiling(Ceiling::WorkRatio, &spec(&format!("{r}metric = 'efficiency_mse'")), None, &report);
    assert_eq!(c, Some(6.0 * 32.0 / (1.5 * 16.0)));
    // ratio on p_eff: paper 003's Err x rays.
    let c = ceiling(Ceiling::WorkRatio, &spec(&format!("{r}metric = 'p_eff'")), None, &report);
    assert_eq!(c, Some(9.0 * 32.0 / (3.0 * 16.0)));
    // an error ratio has no work ratio.
    assert_eq!(ceiling(Ceiling::WorkRatio, &spec(&format!("{r}metric = 'rmse'")), None, &report), None);
}

#[test]
fn sensitivity_md_escapes_the_files_text_and_the_reasons() {
    let tag = "<img src=x onerror=alert(1)>";
    let f = file_with(("open = \"o\"", "open = \"<script>alert(1)</script>\"")).unwrap();
    let mut p = f.parts[0].clone();
    p.headline = format!("h {tag}");
    let mut a = row("1", "paper-like", 4.0, Verdict::NotHeld, Some(5.0));
    a.reason = format!("because {tag} | and\nmore");
    let b = row("5", "default", 2.0, Verdict::NotHeld, Some(3.0));
    let outcome = classify(&p, &[&a, &b]);
    let md = super::table::markdown(&[(&p, outcome)], &[a, b]);
    assert!(!md.contains('<') && !md.contains('>'), "{md}");
    assert!(
        md.contains("&lt;script&gt;alert(1)&lt;/script&gt;") && md.contains("h &lt;img src=x onerror=alert(1)&gt;")
    );
    assert!(md.contains("| because &lt;img src=x onerror=alert(1)&gt; \\| and more |"), "{md}");
}

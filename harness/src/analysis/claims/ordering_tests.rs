//! Unit tests of [`super`].

use crate::config::claim_spec::ClaimSpec;
use crate::output::RunReport;
use crate::verdict::Verdict;

/// A report with one row per (name, MSE, MSE standard error) at budget 64, 16 repetitions,
/// FoM = 1 / (MSE x 10).
fn report(cells: &[(&str, f64, f64)]) -> RunReport {
    let mut report = crate::output::plot::tests::synthetic_report();
    let template = report.rows[0].clone();
    report.rows.clear();
    for (name, m, s) in cells {
        let mut r = template.clone();
        (r.estimator, r.budget, r.mse, r.rmse, r.mse_se, r.reps) = ((*name).into(), 64, *m, m.sqrt(), *s, 16);
        r.fom = Some(1.0 / (m * 10.0));
        report.rows.push(r);
    }
    report
}

fn judge(toml_text: &str, report: &RunReport) -> crate::output::Claim {
    let spec: ClaimSpec = toml::from_str(&format!("testbed = 'gradient-plane/default'\ntext = 't'\n{toml_text}"))
        .unwrap_or_else(|e| panic!("{e}"));
    spec.judge(report)
}

const ORDERING: &str = "kind = 'ordering'\nestimators = ['a']\nothers = ['b', 'c']\nmetric = 'mse'\n";

#[test]
fn orderings_are_judged_on_bonferroni_intervals_of_every_pair() {
    // a's MSE is half b's and a third of c's, 5% relative errors: held.
    let r = report(&[("a", 1.0, 0.05), ("b", 2.0, 0.1), ("c", 3.0, 0.15)]);
    let held = judge(ORDERING, &r);
    assert_eq!((held.verdict, held.held), (Some(Verdict::Held), Some(true)), "{held:?}");
    // The binding pair is the one closest to 1: a vs b, at level 1 - 0.05 / 2.
    assert_eq!((held.pair.as_str(), held.our_value), ("a vs b", Some(0.5)), "{held:?}");
    let [lo, hi] = held.interval.expect("interval");
    let q = mcbench_core::stats::hypothesis::t_quantile(1.0 - 0.025 / 2.0, 15.0);
    let w = (q * 2f64.sqrt() * 0.05).exp();
    assert!((lo - 0.5 / w).abs() < 1e-12 && (hi - 0.5 * w).abs() < 1e-12, "{lo} {hi}");
    assert!(held.reason.contains("Bonferroni over 2 pairs"), "{}", held.reason);
    // "Highest" is the other side: not held.
    let highest = judge(&format!("{ORDERING}order = 'highest'\n"), &r);
    assert_eq!((highest.verdict, highest.held), (Some(Verdict::NotHeld), Some(false)), "{highest:?}");
    // One competitor beats a: not held, even though a beats the other.
    let r = report(&[("a", 1.0, 0.05), ("b", 0.5, 0.025), ("c", 3.0, 0.15)]);
    let not = judge(ORDERING, &r);
    assert_eq!((not.verdict, not.pair.as_str()), (Some(Verdict::NotHeld), "a vs b"), "{not:?}");
    // A noisy competitor straddles: inconclusive, with the repetitions that would decide.
    let r = report(&[("a", 1.0, 0.05), ("b", 1.1, 0.4), ("c", 3.0, 0.15)]);
    let open = judge(ORDERING, &r);
    assert_eq!((open.verdict, open.held), (Some(Verdict::Inconclusive), None), "{open:?}");
    assert!(open.reason.contains("a vs b") && open.reason.contains("repetitions would decide"), "{}", open.reason);
    // A missing row: inconclusive, naming it.
    let r = report(&[("a", 1.0, 0.05), ("b", 2.0, 0.1)]);
    let gone = judge(ORDERING, &r);
    assert_eq!((gone.verdict, gone.held), (Some(Verdict::Inconclusive), None), "{gone:?}");
    assert!(gone.reason.contains("no cell for c at budget 64"), "{}", gone.reason);
}

const OPTIMUM: &str = "kind = 'optimum'\ninside = ['p1', 'p2']\noutside = ['p3', 'p4']\nmetric = 'fom'\n";

#[test]
fn optima_compare_the_best_inside_with_the_best_outside_at_a_selection_level() {
    // FoM is highest at p2 (smallest MSE), inside: held; the value is FoM(p2) / FoM(p3).
    let r = report(&[("p1", 2.0, 0.1), ("p2", 1.0, 0.05), ("p3", 1.5, 0.075), ("p4", 3.0, 0.15)]);
    let held = judge(OPTIMUM, &r);
    assert_eq!((held.verdict, held.pair.as_str()), (Some(Verdict::Held), "p2 vs p3"), "{held:?}");
    assert!((held.our_value.expect("value") - 1.5).abs() < 1e-12, "{held:?}");
    let [lo, hi] = held.interval.expect("interval");
    let q = mcbench_core::stats::hypothesis::t_quantile(1.0 - 0.05 / 8.0, 15.0);
    let w = (q * 2f64.sqrt() * 0.05).exp();
    assert!((lo - 1.5 / w).abs() < 1e-12 && (hi - 1.5 * w).abs() < 1e-12, "{lo} {hi}");
    assert!(held.reason.contains("Bonferroni over 2 inside x 2 outside"), "{}", held.reason);
    // The best is outside and beats every inside candidate: not held.
    let r = report(&[("p1", 2.0, 0.1), ("p2", 1.5, 0.075), ("p3", 1.0, 0.05), ("p4", 3.0, 0.15)]);
    assert_eq!(judge(OPTIMUM, &r).verdict, Some(Verdict::NotHeld));
    // An error metric: the lowest is best, so the same cells judged on MSE hold the optimum
    // outside too (p3 has the lowest MSE).
    assert_eq!(judge(&OPTIMUM.replace("fom", "mse"), &r).verdict, Some(Verdict::NotHeld));
    // Close and noisy: inconclusive.
    let r = report(&[("p1", 2.0, 0.1), ("p2", 1.0, 0.3), ("p3", 1.05, 0.3), ("p4", 3.0, 0.15)]);
    let open = judge(OPTIMUM, &r);
    assert_eq!((open.verdict, open.held), (Some(Verdict::Inconclusive), None), "{open:?}");
    assert!(open.reason.contains("repetitions would decide"), "{}", open.reason);
    // A candidate that did not run: inconclusive, naming it.
    let r = report(&[("p1", 2.0, 0.1), ("p2", 1.0, 0.05), ("p3", 1.5, 0.075)]);
    let gone = judge(OPTIMUM, &r);
    assert_eq!(gone.verdict, Some(Verdict::Inconclusive));
    assert!(gone.reason.contains("no cell for p4"), "{}", gone.reason);
}

#[test]
fn ratios_of_ratios_join_two_intervals() {
    let text = "kind = 'ratio_of_ratios'\nnumerator = ['s1', 's10']\ndenominator = ['b1', 'b10']\nmetric = 'mse'\nside = 'below'\n";
    // More moves: 1.1x lower MSE; more bridges: 4x. (1.1 / 4) lies below 1: held.
    let r = report(&[("s1", 1.1, 0.05), ("s10", 1.0, 0.05), ("b1", 4.0, 0.2), ("b10", 1.0, 0.05)]);
    let held = judge(text, &r);
    assert_eq!((held.verdict, held.our_value), (Some(Verdict::Held), Some(1.1 / 4.0)), "{held:?}");
    let [lo, hi] = held.interval.expect("interval");
    assert!(lo < 1.1 / 4.0 && 1.1 / 4.0 < hi && hi < 1.0, "{lo} {hi}");
    // The same reduction on both: inconclusive; the reverse: not held.
    let r = report(&[("s1", 2.0, 0.3), ("s10", 1.0, 0.15), ("b1", 2.0, 0.3), ("b10", 1.0, 0.15)]);
    assert_eq!(judge(text, &r).verdict, Some(Verdict::Inconclusive));
    let r = report(&[("s1", 4.0, 0.2), ("s10", 1.0, 0.05), ("b1", 1.1, 0.05), ("b10", 1.0, 0.05)]);
    assert_eq!(judge(text, &r).verdict, Some(Verdict::NotHeld));
    let r = report(&[("s1", 4.0, 0.2), ("s10", 1.0, 0.05), ("b1", 1.1, 0.05)]);
    let gone = judge(text, &r);
    assert_eq!(gone.verdict, Some(Verdict::Inconclusive));
    assert!(gone.reason.contains("no cell for b10"), "{}", gone.reason);
}

#[test]
fn self_comparisons_are_refused() {
    let r = report(&[("a", 1.0, 0.05), ("b", 2.0, 0.1)]);
    for text in [
        "kind = 'ordering'\nestimators = ['a']\nothers = ['b', 'a']\n",
        "kind = 'optimum'\ninside = ['a']\noutside = ['a']\n",
        "kind = 'ratio'\nestimator = 'a'\nbaseline = 'a'\nbudget = 64\n",
        "kind = 'ratio_of_ratios'\nnumerator = ['a', 'a']\ndenominator = ['a', 'b']\n",
    ] {
        let spec: ClaimSpec = toml::from_str(&format!("testbed = 'gradient-plane/default'\ntext = 't'\n{text}"))
            .unwrap_or_else(|e| panic!("{e}"));
        let err = spec.check().expect_err(text).to_string();
        assert!(err.contains("compares a with itself"), "{err}");
        let c = spec.judge(&r);
        assert_eq!((c.verdict, c.held), (Some(Verdict::NotMeasured), None), "{c:?}");
        assert!(c.reason.contains("refused"), "{c:?}");
    }
    let empty: ClaimSpec =
        toml::from_str("kind = 'ordering'\ntestbed = 'a/b'\ntext = 't'\nestimators = ['a']\nothers = []\n")
            .expect("parses");
    assert!(empty.check().is_err());
}

#[test]
fn a_claim_without_a_budget_uses_the_largest() {
    let r = report(&[("a", 1.0, 0.05), ("b", 2.0, 0.1)]);
    let c = judge("kind = 'ratio'\nestimator = 'a'\nbaseline = 'b'\nmetric = 'mse'\nside = 'below'\n", &r);
    assert_eq!((c.verdict, c.our_value), (Some(Verdict::Held), Some(0.5)), "{c:?}");
    assert!(c.note.contains("at 64"), "{}", c.note);
}

#[test]
fn detectable_ratio_reads_the_log_standard_error_off_the_interval() {
    use super::{detectable_ratio, repetitions_to_detect};
    // [0.9, 1.1] at 95%: se = ln(1.1 / 0.9) / (2 x 1.95996) = 0.05119, d = exp(0.05119 x 2.80158).
    let d = detectable_ratio((0.9, 1.1), 0.95).unwrap();
    assert!((d - (0.051_19_f64 * 2.801_58).exp()).abs() < 1e-4, "{d}");
    // A wider interval or a stricter level detects only larger ratios.
    assert!(detectable_ratio((0.8, 1.25), 0.95).unwrap() > d);
    assert!(detectable_ratio((0.9, 1.1), 0.99).unwrap() < d, "same width at a stricter level: smaller se");
    assert_eq!(detectable_ratio((0.0, 1.1), 0.95), None);
    assert_eq!(detectable_ratio((1.0, 1.0), 0.95), None);
    // Repetitions scale with the square of the log ratio: half the log needs four times as many.
    let n = repetitions_to_detect(1.21, 16, 1.1);
    assert!((64.0..=65.0).contains(&n), "{n}");
}

//! Unit tests of [`super`].

use super::*;

fn claim(text: &str) -> ClaimSpec {
    toml::from_str(text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// The claim's error, as (field, problem).
fn refused(c: &ClaimSpec, ran: Option<&Ran<'_>>) -> (&'static str, ClaimProblem) {
    let e = match ran {
        None => c.check(),
        Some(r) => c.check_against(r),
    }
    .expect_err("refused");
    (e.field, e.problem)
}

#[test]
fn every_number_of_a_claim_is_finite_and_in_its_range() {
    let cases = [
        ("kind = 'slope'\ntestbed = 'a/b'\nestimator = 'e'\nvalue = nan\ntext = 't'", "value"),
        ("kind = 'slope_below'\ntestbed = 'a/b'\nestimator = 'e'\nvalue = -0.5\npaper = inf\ntext = 't'", "paper"),
        ("kind = 'speedup'\ntestbed = 'a/b'\nestimator = 'e'\nvalue = -inf\ntext = 't'", "value"),
        (
            "kind = 'ratio'\ntestbed = 'a/b'\nestimator = 'e'\nbaseline = 'f'\nthreshold = nan\ntext = 't'",
            "threshold",
        ),
        ("kind = 'ratio'\ntestbed = 'a/b'\nestimator = 'e'\nbaseline = 'f'\nvalue = nan\ntext = 't'", "value"),
        ("kind = 'ordering'\ntestbed = 'a/b'\nestimators = ['e']\nothers = ['f']\nvalue = inf\ntext = 't'", "value"),
        ("kind = 'optimum'\ntestbed = 'a/b'\ninside = ['e']\noutside = ['f']\nvalue = nan\ntext = 't'", "value"),
        (
            "kind = 'ratio_of_ratios'\ntestbed = 'a/b'\nnumerator = ['e', 'f']\ndenominator = ['g', 'h']\nthreshold = inf\ntext = 't'",
            "threshold",
        ),
        (
            "kind = 'diagnostic'\ntestbed = 'a/b'\nestimator = 'e'\nbudget = 4\nname = 'n'\nvalue = 1.0\ntolerance = nan\ntext = 't'",
            "tolerance",
        ),
    ];
    for (text, field) in cases {
        assert_eq!(refused(&claim(text), None), (field, ClaimProblem::NotFinite), "{text}");
    }
    let ranges = [
        ("kind = 'speedup'\ntestbed = 'a/b'\nestimator = 'e'\nvalue = 0.0\ntext = 't'", "value"),
        ("kind = 'ratio'\ntestbed = 'a/b'\nestimator = 'e'\nbaseline = 'f'\nthreshold = -1.0\ntext = 't'", "threshold"),
        (
            "kind = 'diagnostic'\ntestbed = 'a/b'\nestimator = 'e'\nbudget = 4\nname = 'n'\nvalue = 1.0\ntolerance = -0.1\ntext = 't'",
            "tolerance",
        ),
    ];
    for (text, field) in ranges {
        let (f, p) = refused(&claim(text), None);
        assert!(f == field && matches!(p, ClaimProblem::OutOfRange(_)), "{text}: {f} {p:?}");
    }
    let fine =
        "kind = 'ratio'\ntestbed = 'a/b'\nestimator = 'e'\nbaseline = 'f'\nvalue = 6.8\nthreshold = 0.5\ntext = 't'";
    assert_eq!(claim(fine).check(), Ok(()));
    let empty = claim("kind = 'optimum'\ntestbed = 'a/b'\ninside = ['e']\noutside = []\ntext = 't'");
    assert_eq!(refused(&empty, None), ("outside", ClaimProblem::EmptySide));
}

/// Two test beds (`t/a` runs `e` and `f[k=1]`; `t/b` runs `e`, skips `f[k=1]`) at budgets 4, 16.
fn ran<'a>(pairs: &'a [(usize, usize)], skipped: &'a [Skipped], baseline: Option<&'a str>) -> Ran<'a> {
    Ran {
        beds: vec!["t/a".into(), "t/b".into()],
        estimators: vec!["e", "f[k=1]"],
        pairs,
        skipped,
        budgets: vec![4, 16],
        baseline,
    }
}

#[test]
fn a_claim_names_only_what_the_plan_runs() {
    let pairs = [(0, 0), (0, 1), (1, 0)];
    let skipped = [Skipped {
        testbed: "t".into(),
        variant: "b".into(),
        estimator: "f[k=1]".into(),
        reason: "needs a medium".into(),
    }];
    let r = ran(&pairs, &skipped, Some("e"));
    let ok = [
        "kind = 'slope'\ntestbed = 't/a'\nestimator = 'f[k=1]'\nvalue = -0.5\ntext = 't'",
        "kind = 'ratio'\ntestbed = 't/a'\nestimator = 'f[k=1]'\nbaseline = 'e'\nbudget = 16\ntext = 't'",
        "kind = 'speedup'\ntestbed = 't/a'\nestimator = 'f[k=1]'\nvalue = 2.0\ntext = 't'",
        "kind = 'control_flagged'\nestimator = 'f[k=1]'",
    ];
    for text in ok {
        assert_eq!(claim(text).check_against(&r), Ok(()), "{text}");
    }
    let typo = claim("kind = 'slope'\ntestbed = 't/a'\nestimator = 'f[k=2]'\nvalue = -0.5\ntext = 't'");
    assert_eq!(refused(&typo, Some(&r)), ("estimator", ClaimProblem::UnknownEstimator("e, f[k=1]".into())));
    let bed = claim("kind = 'slope'\ntestbed = 't/c'\nestimator = 'e'\nvalue = -0.5\ntext = 't'");
    assert_eq!(refused(&bed, Some(&r)), ("testbed", ClaimProblem::UnknownTestbed("t/a, t/b".into())));
    let no_variant = claim("kind = 'slope'\ntestbed = 't'\nestimator = 'e'\nvalue = -0.5\ntext = 't'");
    assert_eq!(refused(&no_variant, Some(&r)).0, "testbed");
    let skipped_pair = claim("kind = 'ordering'\ntestbed = 't/b'\nestimators = ['e']\nothers = ['f[k=1]']\ntext = 't'");
    let not_run = ClaimProblem::NotRun { testbed: "t/b".into(), reason: "needs a medium".into() };
    assert_eq!(refused(&skipped_pair, Some(&r)), ("others", not_run));
    for (text, field) in [
        ("kind = 'optimum'\ntestbed = 't/a'\ninside = ['e']\noutside = ['g']\ntext = 't'", "outside"),
        (
            "kind = 'ratio_of_ratios'\ntestbed = 't/a'\nnumerator = ['e', 'f[k=1]']\ndenominator = ['e', 'x']\ntext = 't'",
            "denominator",
        ),
        ("kind = 'speedup'\ntestbed = 't/a'\nestimator = 'e'\nbaseline = 'z'\nvalue = 2.0\ntext = 't'", "baseline"),
    ] {
        let (f, p) = refused(&claim(text), Some(&r));
        assert!(f == field && matches!(p, ClaimProblem::UnknownEstimator(_)), "{text}: {f} {p:?}");
    }
    let budget = claim("kind = 'ratio'\ntestbed = 't/a'\nestimator = 'e'\nbaseline = 'f[k=1]'\nbudget = 8\ntext = 't'");
    assert_eq!(refused(&budget, Some(&r)), ("budget", ClaimProblem::UnknownBudget("4, 16".into())));
    // A speed-up against the sweep's baseline needs one, other than itself.
    let speedup = claim("kind = 'speedup'\ntestbed = 't/a'\nestimator = 'e'\nvalue = 2.0\ntext = 't'");
    assert_eq!(refused(&speedup, Some(&r)), ("estimator", ClaimProblem::SelfComparison("e".into())));
    assert_eq!(refused(&speedup, Some(&ran(&pairs, &skipped, None))), ("baseline", ClaimProblem::NoBaseline));
    let nowhere = claim("kind = 'control_flagged'\nestimator = 'f[k=1]'");
    assert_eq!(refused(&nowhere, Some(&ran(&[(0, 0)], &[], None))), ("estimator", ClaimProblem::RunsNowhere));
}

#[test]
fn the_error_names_the_claim_its_text_and_the_field_on_one_line() {
    let c = claim("kind = 'slope'\ntestbed = 'a/b'\nestimator = 'e'\nvalue = nan\ntext = \"\"\"two\nlines\"\"\"");
    let e = config_error(3, &c, c.check().expect_err("nan")).to_string();
    assert_eq!(e, "invalid claims[3].value = NaN: not a finite number (the claim: \"two lines\")");
    let bed = claim("kind = 'slope'\ntestbed = \"t/a\\nt/c\"\nestimator = 'e'\nvalue = -0.5\ntext = 't'");
    let (pairs, skipped) = ([(0, 0), (1, 0)], []);
    let e = config_error(0, &bed, bed.check_against(&ran(&pairs, &skipped, None)).expect_err("no such bed"));
    assert_eq!(
        e.to_string(),
        "invalid claims[0].testbed = t/a t/c: the sweep runs no such test bed (it runs: t/a, t/b) (the claim: \"t\")"
    );
}

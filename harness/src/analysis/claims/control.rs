//! Claims decided by the unbiasedness tests: an estimator is unbiased, a biased control is flagged.

use crate::analysis::TestRow;
use crate::output::query::Query;
use crate::output::{Claim, RunReport};
use crate::verdict::Verdict;

/// The test that decides unbiasedness for one (variant, estimator): its `combined` row (with
/// `suffix` appended to the name), whose verdict is `pass`, `inconclusive` or `biased`.
pub fn decisive_test<'a>(tests: &'a [TestRow], variant: &str, estimator: &str, suffix: &str) -> Option<&'a TestRow> {
    Query::new(tests).variant(variant).estimator(estimator).iter().find(|t| t.test == format!("combined{suffix}"))
}

/// The verdict of a claim that an estimator is unbiased, from its deciding test row: `held` on
/// `pass`, `not held` on `biased`, `inconclusive` otherwise, with the row's reason.
pub fn unbiased_verdict(t: &TestRow) -> (Option<bool>, Verdict, String) {
    let verdict = match t.verdict.as_str() {
        "pass" => Verdict::Held,
        "biased" => Verdict::NotHeld,
        _ => Verdict::Inconclusive,
    };
    (verdict.held(), verdict, t.reason.clone())
}

/// "The biased control is flagged by the unbiasedness test" on every variant it ran on: `held`
/// only when its deciding test says `biased` on each (the largest p is the value), so a control
/// missed on one variant does not hold. A variant where it was missed is `not held` when its row
/// could have seen the control's measured bias (more than the row's detectable bias and two
/// standard errors from zero), and `inconclusive` when the bias is below what the row detects,
/// with the repetitions that would bring the row to it: a test with too few repetitions to see a
/// small control bias is not a test without teeth.
pub fn control_flagged(report: &RunReport, control: &str) -> Claim {
    let mut variants: Vec<&str> = Vec::new();
    for t in Query::new(&report.tests).estimator(control) {
        if !variants.contains(&t.variant.as_str()) {
            variants.push(&t.variant);
        }
    }
    let decisive: Vec<&TestRow> =
        variants.iter().filter_map(|v| decisive_test(&report.tests, v, control, "")).collect();
    let max_p = decisive.iter().map(|t| if t.p_value.is_nan() { 1.0 } else { t.p_value }).fold(0.0, f64::max);
    let missed: Vec<&TestRow> = decisive.iter().copied().filter(|t| t.verdict != "biased").collect();
    // The measured bias of a missed control, and whether its row could see it.
    let visible = |t: &TestRow| {
        let b = t.rel_bias.abs();
        b.is_finite() && b > t.detectable_rel_bias && b > 2.0 * t.rel_bias_se
    };
    let used: Vec<String> =
        decisive.iter().map(|t| format!("{}/{}: {} p = {:.2e}", t.testbed, t.variant, t.verdict, t.p_value)).collect();
    let (verdict, reason) = if decisive.is_empty() {
        (Verdict::NotMeasured, "no unbiasedness row of the control".to_string())
    } else if missed.is_empty() {
        (Verdict::Held, format!("flagged on all {} variants", decisive.len()))
    } else if missed.iter().any(|t| visible(t)) {
        let seen: Vec<String> = missed
            .iter()
            .filter(|t| visible(t))
            .map(|t| {
                format!(
                    "{}/{} (bias {:+.2}% ± {:.2}%, detectable {:.2}%)",
                    t.testbed,
                    t.variant,
                    100.0 * t.rel_bias,
                    100.0 * t.rel_bias_se,
                    100.0 * t.detectable_rel_bias
                )
            })
            .collect();
        (Verdict::NotHeld, format!("missed where its row could see the bias: {}", seen.join(", ")))
    } else {
        let under: Vec<String> = missed
            .iter()
            .map(|t| {
                let b = t.rel_bias.abs();
                let reps = report
                    .rows
                    .iter()
                    .find(|r| {
                        (&r.testbed, &r.variant, &r.estimator, r.budget)
                            == (&t.testbed, &t.variant, &t.estimator, t.budget)
                    })
                    .map(|r| r.reps);
                let need = reps
                    .filter(|_| b > 0.0 && t.detectable_rel_bias.is_finite())
                    .map(|r| (r as f64 * (t.detectable_rel_bias / b).powi(2)).ceil());
                format!(
                    "{}/{}: bias {:+.2}% ± {:.2}% below the {:.2}% the row detects{}",
                    t.testbed,
                    t.variant,
                    100.0 * t.rel_bias,
                    100.0 * t.rel_bias_se,
                    100.0 * t.detectable_rel_bias,
                    need.map_or(String::new(), |n| format!(" (about {n} repetitions would resolve it)"))
                )
            })
            .collect();
        (Verdict::Inconclusive, under.join("; "))
    };
    Claim {
        testbed: decisive.first().map(|t| t.testbed.clone()).unwrap_or_default(),
        claim: format!(
            "harness: the biased control {control} is flagged by the unbiasedness test (family-wise alpha 1e-3) on every variant it runs on"
        ),
        paper_value: None,
        our_value: (!decisive.is_empty()).then_some(max_p),
        p_value: (!decisive.is_empty()).then_some(max_p),
        held: verdict.held(),
        note: if missed.is_empty() {
            format!("flagged on all {} variants (largest p shown): {}", decisive.len(), used.join("; "))
        } else {
            let names: Vec<String> = missed.iter().map(|t| format!("{}/{}", t.testbed, t.variant)).collect();
            format!("NOT flagged on {}: {}", names.join(", "), used.join("; "))
        },
        verdict: Some(verdict),
        reason,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use crate::analysis::TestRow;
    use crate::verdict::Verdict;

    /// A control's combined rows on two variants: (variant, verdict, relative bias, its standard
    /// error, detectable bias).
    fn report(rows: &[(&str, &str, f64, f64, f64)]) -> crate::output::RunReport {
        let mut report = crate::output::plot::tests::synthetic_report();
        let template = report.rows[0].clone();
        report.rows.clear();
        report.tests.clear();
        for (variant, verdict, b, se, d) in rows {
            let mut r = template.clone();
            (r.variant, r.estimator, r.budget, r.reps) = ((*variant).into(), "ctl".into(), 64, 16);
            report.rows.push(r);
            report.tests.push(TestRow {
                testbed: template.testbed.clone(),
                variant: (*variant).into(),
                estimator: "ctl".into(),
                test: "combined".into(),
                budget: 64,
                p_value: if *verdict == "biased" { 1e-9 } else { 0.5 },
                verdict: (*verdict).into(),
                rel_bias: *b,
                rel_bias_se: *se,
                detectable_rel_bias: *d,
                claim: "biased".into(),
                ..Default::default()
            });
        }
        report
    }

    #[test]
    fn a_control_missed_where_its_row_cannot_see_it_is_inconclusive_not_a_test_without_teeth() {
        let held = super::control_flagged(
            &report(&[("a", "biased", 0.05, 0.005, 0.02), ("b", "biased", 0.03, 0.005, 0.02)]),
            "ctl",
        );
        assert_eq!((held.verdict, held.held), (Some(Verdict::Held), Some(true)));
        // Missed on b, whose row detects 4% against a 1% bias: inconclusive, with the repetitions
        // (16 x 4^2 = 256) that would resolve it.
        let under = super::control_flagged(
            &report(&[("a", "biased", 0.05, 0.005, 0.02), ("b", "inconclusive", 0.01, 0.01, 0.04)]),
            "ctl",
        );
        assert_eq!((under.verdict, under.held), (Some(Verdict::Inconclusive), None), "{under:?}");
        assert!(under.reason.contains("256 repetitions"), "{}", under.reason);
        // Missed on b although its row detects 2% and the bias is 5% ± 0.5%: not held.
        let blind = super::control_flagged(
            &report(&[("a", "biased", 0.05, 0.005, 0.02), ("b", "pass", 0.05, 0.005, 0.02)]),
            "ctl",
        );
        assert_eq!((blind.verdict, blind.held), (Some(Verdict::NotHeld), Some(false)), "{blind:?}");
    }
}

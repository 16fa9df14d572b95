//! One experiment's run counted for the console: its claims per verdict, its unbiasedness
//! decisions per verdict, the claims that did not hold and the tests that contradict what the
//! registry says of the estimator.
//!
//! A run decides hundreds of cells at `alpha` each, so a few unbiased estimators read `biased` by
//! chance in most runs. The list of contradictions says, for each flag of an estimator registered
//! unbiased, whether it survives Holm's correction over the experiment's decisions of unbiased
//! estimators (the family "none of them is biased"); a control that passes where the registry
//! exempts it on that test bed ([`Registry::exemption`]) contradicts nothing.

use crate::output::report::sig;
use crate::output::RunReport;
use crate::registry::Registry;
use crate::verdict::Verdict;
use mcbench_core::stats::hypothesis::holm_bonferroni_finite;

/// The unbiasedness decision of a cell is its `combined` test row (the Holm and pooled rows feed
/// it and are not counted).
const DECISION: &str = "combined";

/// What the console says of one experiment's run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tally {
    /// The experiment's name.
    pub experiment: String,
    /// Wall-clock seconds the experiment took.
    pub seconds: f64,
    /// Claims per verdict, in [`Verdict::ALL`] order.
    pub claims: [usize; 5],
    /// Unbiasedness decisions that read `pass`.
    pub pass: usize,
    /// Unbiasedness decisions that read `biased`.
    pub biased: usize,
    /// Unbiasedness decisions that read `inconclusive`.
    pub inconclusive: usize,
    /// The claims that did not hold, one line each.
    pub not_held: Vec<String>,
    /// Decisions that contradict the estimator's registered claim (an unbiased one flagged, a
    /// biased control passed), one line each.
    pub contradicting: Vec<String>,
    /// Pairs that did not run.
    pub skipped: usize,
    /// Estimators the experiment names that are not registered.
    pub unavailable: usize,
}

impl Tally {
    /// Counts `report`, an experiment that took `seconds`, with the exemptions of `registry`.
    pub fn of(report: &RunReport, seconds: f64, registry: &Registry) -> Self {
        let mut t = Tally {
            experiment: report.meta.experiment.clone(),
            seconds,
            skipped: report.skipped.len(),
            unavailable: report.unavailable.len(),
            ..Tally::default()
        };
        for c in &report.paper {
            let v = c.verdict();
            t.claims[Verdict::ALL.iter().position(|x| *x == v).unwrap_or(0)] += 1;
            if v == Verdict::NotHeld {
                t.not_held.push(format!("{}: {}{}", t.experiment, c.claim, values(c)));
            }
        }
        let decisions: Vec<&crate::analysis::TestRow> = report.tests.iter().filter(|r| r.test == DECISION).collect();
        // Holm over the tested decisions of estimators registered unbiased (as the unbiasedness
        // experiment's headline claim), in their order.
        let unbiased: Vec<f64> = decisions.iter().filter(|r| r.claim == "unbiased").map(|r| r.p_value).collect();
        let tested = unbiased.iter().filter(|p| !p.is_nan()).count();
        let mut holm = holm_bonferroni_finite(&unbiased).into_iter();
        for row in decisions {
            match row.verdict.as_str() {
                "pass" => t.pass += 1,
                "biased" => t.biased += 1,
                _ => t.inconclusive += 1,
            }
            let adjusted = if row.claim == "unbiased" { holm.next() } else { None };
            let id = row.estimator.split('[').next().unwrap_or_default();
            let exempt = registry.exemption(id, &row.testbed, &row.variant).is_some();
            let family = match adjusted {
                Some(q) if row.verdict == "biased" && q > row.alpha => format!(
                    "; p {} at its own level, not significant after Holm over the {tested} decisions of unbiased estimators",
                    sig(row.p_value, 2)
                ),
                _ => String::new(),
            };
            let contradicts = (row.verdict == "biased" && row.claim == "unbiased")
                || (row.verdict == "pass" && row.claim == "biased" && !exempt);
            if contradicts {
                t.contradicting.push(format!(
                    "{}: {} on {}/{} at {} reads {} (registered {}{family})",
                    t.experiment, row.estimator, row.testbed, row.variant, row.budget, row.verdict, row.claim
                ));
            }
        }
        t
    }

    /// Adds `other`'s counts (not its lines) to these.
    pub fn add(&mut self, other: &Tally) {
        for (a, b) in self.claims.iter_mut().zip(other.claims) {
            *a += b;
        }
        self.pass += other.pass;
        self.biased += other.biased;
        self.inconclusive += other.inconclusive;
        self.skipped += other.skipped;
        self.unavailable += other.unavailable;
    }

    /// `claims 3 held, 1 not held` (verdicts with no claim left out; `no claims` when none).
    pub fn claims_text(&self) -> String {
        let parts: Vec<String> = Verdict::ALL
            .iter()
            .zip(self.claims)
            .filter(|(_, n)| *n > 0)
            .map(|(v, n)| format!("{n} {}", v.as_str()))
            .collect();
        if parts.is_empty() {
            "no claims".into()
        } else {
            format!("claims {}", parts.join(", "))
        }
    }

    /// `tests 40 pass, 6 biased, 12 inconclusive` (`no tests` when the run decided none).
    pub fn tests_text(&self) -> String {
        if self.pass + self.biased + self.inconclusive == 0 {
            return "no tests".into();
        }
        format!("tests {} pass, {} biased, {} inconclusive", self.pass, self.biased, self.inconclusive)
    }

    /// The experiment's line: name, seconds, claims, tests, and what did not run.
    pub fn line(&self, name_width: usize) -> String {
        let mut line = format!(
            "{:<name_width$} {:>7.1} s  {} | {}",
            self.experiment,
            self.seconds,
            self.claims_text(),
            self.tests_text()
        );
        if self.skipped > 0 {
            line.push_str(&format!(" | {} skipped", self.skipped));
        }
        if self.unavailable > 0 {
            line.push_str(&format!(" | {} not registered", self.unavailable));
        }
        line
    }
}

/// ` (paper 15.3, ours 2.18 [1.90, 2.41])`, or empty when the claim carries no numbers.
fn values(c: &crate::output::Claim) -> String {
    let ours = match (c.our_value, c.interval) {
        (Some(v), Some([lo, hi])) => Some(format!("{} [{}, {}]", sig(v, 3), sig(lo, 3), sig(hi, 3))),
        (Some(v), None) => Some(sig(v, 3)),
        (None, _) => None,
    };
    match (c.paper_value, ours) {
        (Some(p), Some(o)) => format!(" (paper {}, ours {o})", sig(p, 3)),
        (None, Some(o)) => format!(" (ours {o})"),
        (Some(p), None) => format!(" (paper {})", sig(p, 3)),
        (None, None) => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::TestRow;
    use crate::output::Claim;

    fn test_row(estimator: &str, test: &str, verdict: &str, claim: &str) -> TestRow {
        TestRow {
            testbed: "bed".into(),
            variant: "v".into(),
            estimator: estimator.into(),
            test: test.into(),
            budget: 64,
            verdict: verdict.into(),
            claim: claim.into(),
            ..TestRow::default()
        }
    }

    fn claim(text: &str, verdict: Verdict) -> Claim {
        Claim {
            testbed: "bed".into(),
            claim: text.into(),
            paper_value: Some(2.0),
            our_value: Some(1.5),
            verdict: Some(verdict),
            interval: Some([1.2, 1.8]),
            ..Claim::default()
        }
    }

    fn report() -> RunReport {
        let mut r = crate::output::plot::tests::synthetic_report();
        r.meta.experiment = "exp".into();
        r.skipped.clear();
        r.unavailable.clear();
        r.tests = vec![
            test_row("a", "combined", "pass", "unbiased"),
            test_row("a", "holm_t", "inconclusive", "unbiased"),
            test_row("a", "pooled_t", "pass", "unbiased"),
            test_row("b", "combined", "biased", "unbiased"),
            test_row("c", "combined", "pass", "biased"),
            test_row("d", "combined", "biased", "biased"),
            test_row("e", "combined", "inconclusive", "unbiased"),
        ];
        r.paper = vec![claim("A beats B", Verdict::Held), claim("C beats D", Verdict::NotHeld)];
        r
    }

    #[test]
    fn counts_only_the_decisions_and_names_what_contradicts_the_claim() {
        let t = Tally::of(&report(), 1.25, &Registry::empty());
        assert_eq!((t.pass, t.biased, t.inconclusive), (2, 2, 1), "the combined rows only");
        assert_eq!(t.contradicting.len(), 2, "{:?}", t.contradicting);
        assert!(t.contradicting[0].contains("b on bed/v at 64 reads biased (registered unbiased)"));
        assert!(t.contradicting[1].contains("c on bed/v at 64 reads pass (registered biased)"));
        assert_eq!(t.not_held, vec!["exp: C beats D (paper 2.00, ours 1.50 [1.20, 1.80])".to_string()]);
        assert_eq!(t.claims_text(), "claims 1 held, 1 not held");
        assert_eq!(t.tests_text(), "tests 2 pass, 2 biased, 1 inconclusive");
        let line = t.line(5);
        assert!(line.starts_with("exp       1.2 s  claims 1 held, 1 not held | tests 2 pass"), "{line}");
    }

    #[test]
    fn a_flag_that_does_not_survive_holm_says_so_and_an_exempt_control_contradicts_nothing() {
        let mut r = report();
        // 300 decisions of unbiased estimators: one flagged at p 5e-4 (below alpha 1e-3 at its
        // own level, 0.15 after Holm), one at 1e-9 (significant after Holm too).
        r.tests = (0..300)
            .map(|i| {
                let (verdict, p) = match i {
                    0 => ("biased", 5e-4),
                    1 => ("biased", 1e-9),
                    _ => ("pass", 0.5),
                };
                TestRow { p_value: p, alpha: 1e-3, ..test_row(&format!("u{i}[k=1]"), "combined", verdict, "unbiased") }
            })
            .collect();
        r.tests.push(test_row("clamped", "combined", "pass", "biased"));
        r.tests.push(TestRow { variant: "w".into(), ..test_row("clamped", "combined", "pass", "biased") });
        let registry = Registry::empty().with_exemption("clamped", "bed", &["v"], "never clamps here");
        let t = Tally::of(&r, 1.0, &registry);
        assert_eq!(t.contradicting.len(), 3, "{:#?}", t.contradicting);
        assert!(
            t.contradicting[0].contains("u0[k=1] on bed/v at 64 reads biased (registered unbiased; p 5.0e-4 at its own level, not significant after Holm over the 300 decisions"),
            "{}",
            t.contradicting[0]
        );
        assert!(
            t.contradicting[1].ends_with("u1[k=1] on bed/v at 64 reads biased (registered unbiased)"),
            "{}",
            t.contradicting[1]
        );
        assert!(
            t.contradicting[2].contains("clamped on bed/w"),
            "the exemption covers variant v only: {}",
            t.contradicting[2]
        );
        assert_eq!(t.biased, 2, "the counts stay the rows' own verdicts");
    }

    #[test]
    fn the_words_are_the_reports() {
        let t = Tally::of(&report(), 0.0, &Registry::empty());
        assert!(!t.line(3).contains("did NOT"), "the verdict words of the result files");
        let mut total = Tally::default();
        total.add(&t);
        total.add(&t);
        assert_eq!((total.pass, total.claims[1]), (4, 2));
        assert!(total.not_held.is_empty(), "adding counts leaves the lines to the experiments");
        assert_eq!(Tally::default().claims_text(), "no claims");
        assert_eq!(Tally::default().tests_text(), "no tests");
    }
}

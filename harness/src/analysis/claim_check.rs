//! Claims checked before a run writes anything, so that a typo or a non-number is bad input (exit
//! 2) rather than a verdict:
//!
//! - on its own ([`ClaimSpec::check`], when the sweep is validated): every number is finite, a
//!   factor or threshold is positive and a tolerance is not negative, an ordering or optimum names
//!   estimators on both sides, and no estimator is compared with itself;
//! - against the plan ([`ClaimSpec::check_against`], once the test beds and estimators are built):
//!   its test bed is an `id/variant` the sweep runs, every estimator it names (`estimator`,
//!   `baseline` (the sweep's for a `speedup` without one), `estimators`, `others`, `inside`,
//!   `outside`, `numerator`, `denominator`) runs on that test bed, a `control_flagged` estimator runs
//!   on some test bed, and a `budget` is one of the sweep's budgets.
//!
//! Which fields a kind needs and which it takes is checked when the file is read (an unknown or
//! missing field is a parse error naming it).

use crate::config::claim_spec::ClaimSpec;
use crate::plan::Skipped;
use thiserror::Error;

/// What is wrong with a claim: the field, its value and the problem.
#[derive(Clone, Debug, PartialEq, Error)]
#[error("{field} = {value}: {problem}")]
pub struct ClaimError {
    /// The claim's field (`value`, `estimator`, `others`, ...).
    pub field: &'static str,
    /// Its value as written (one name of a list).
    pub value: String,
    /// The problem.
    pub problem: ClaimProblem,
}

/// The problem of a [`ClaimError`].
#[derive(Clone, Debug, PartialEq, Error)]
#[non_exhaustive]
pub enum ClaimProblem {
    /// A number that is NaN or infinite.
    #[error("not a finite number")]
    NotFinite,
    /// A number outside the range its field takes (the reason says which).
    #[error("{0}")]
    OutOfRange(&'static str),
    /// An ordering or optimum with no estimator on one side.
    #[error("names no estimator (an ordering or optimum needs estimators on both sides)")]
    EmptySide,
    /// The claim compares an estimator with itself.
    #[error("the claim compares {0} with itself")]
    SelfComparison(String),
    /// A test bed the sweep does not run (the ones it runs).
    #[error("the sweep runs no such test bed (it runs: {0})")]
    UnknownTestbed(String),
    /// An estimator the sweep does not run (the ones it runs).
    #[error("names no estimator of the sweep (valid: {0})")]
    UnknownEstimator(String),
    /// An estimator of the sweep that does not run on the claim's test bed.
    #[error("does not run on {testbed}: {reason}")]
    NotRun {
        /// The claim's `id/variant`.
        testbed: String,
        /// Why the pair does not run.
        reason: String,
    },
    /// A `control_flagged` estimator that runs on no test bed of the sweep.
    #[error("runs on no test bed of the sweep")]
    RunsNowhere,
    /// A budget the sweep does not run (its budgets).
    #[error("not a budget of the sweep (budgets: {0})")]
    UnknownBudget(String),
    /// A `speedup` without `baseline` in a sweep without one.
    #[error("a speed-up needs a baseline: the claim names none and the sweep has no `baseline`")]
    NoBaseline,
}

fn err(field: &'static str, value: impl ToString, problem: ClaimProblem) -> ClaimError {
    ClaimError { field, value: value.to_string(), problem }
}

/// What a plan runs, as a claim is checked against it.
pub struct Ran<'a> {
    /// `id/variant` of each built test bed (by bed index).
    pub beds: Vec<String>,
    /// Name of each built estimator (by estimator index).
    pub estimators: Vec<&'a str>,
    /// (bed index, estimator index) pairs that run.
    pub pairs: &'a [(usize, usize)],
    /// Pairs that do not, with their reasons.
    pub skipped: &'a [Skipped],
    /// The sweep's budgets (amounts).
    pub budgets: Vec<u64>,
    /// The sweep's baseline.
    pub baseline: Option<&'a str>,
}

impl Ran<'_> {
    fn runs_on(&self, estimator: &str, testbed: &str) -> bool {
        self.pairs.iter().any(|&(b, e)| self.beds[b] == testbed && self.estimators[e] == estimator)
    }

    /// Refuses `name` (in `field`) unless it runs on `testbed` (on any test bed when `None`).
    fn check_runs(&self, field: &'static str, name: &str, testbed: Option<&str>) -> Result<(), ClaimError> {
        if !self.estimators.contains(&name) {
            return Err(err(field, name, ClaimProblem::UnknownEstimator(self.estimators.join(", "))));
        }
        match testbed {
            None if self.pairs.iter().any(|&(_, e)| self.estimators[e] == name) => Ok(()),
            None => Err(err(field, name, ClaimProblem::RunsNowhere)),
            Some(t) if self.runs_on(name, t) => Ok(()),
            Some(t) => {
                let reason = self
                    .skipped
                    .iter()
                    .find(|s| s.estimator == name && format!("{}/{}", s.testbed, s.variant) == t)
                    .map_or_else(|| "skipped".to_string(), |s| s.reason.clone());
                Err(err(field, name, ClaimProblem::NotRun { testbed: t.to_string(), reason }))
            }
        }
    }
}

impl ClaimSpec {
    /// The claim's text (none for `control_flagged`).
    pub fn text(&self) -> Option<&str> {
        match self {
            ClaimSpec::Slope { text, .. }
            | ClaimSpec::SlopeBelow { text, .. }
            | ClaimSpec::Speedup { text, .. }
            | ClaimSpec::Ratio { text, .. }
            | ClaimSpec::Ordering { text, .. }
            | ClaimSpec::Optimum { text, .. }
            | ClaimSpec::RatioOfRatios { text, .. }
            | ClaimSpec::Diagnostic { text, .. } => Some(text),
            ClaimSpec::ControlFlagged { .. } => None,
        }
    }

    /// Every estimator the claim names, with the field that names it (a `speedup`'s default
    /// baseline is not among them).
    pub fn named(&self) -> Vec<(&'static str, &str)> {
        fn all<'a>(field: &'static str, v: &'a [String]) -> Vec<(&'static str, &'a str)> {
            v.iter().map(|n| (field, n.as_str())).collect()
        }
        match self {
            ClaimSpec::Slope { estimator, .. }
            | ClaimSpec::SlopeBelow { estimator, .. }
            | ClaimSpec::Diagnostic { estimator, .. }
            | ClaimSpec::ControlFlagged { estimator } => vec![("estimator", estimator.as_str())],
            ClaimSpec::Speedup { estimator, baseline, .. } => std::iter::once(("estimator", estimator.as_str()))
                .chain(baseline.as_deref().map(|b| ("baseline", b)))
                .collect(),
            ClaimSpec::Ratio { estimator, baseline, .. } => vec![("estimator", estimator), ("baseline", baseline)],
            ClaimSpec::Ordering { estimators, others, .. } => {
                [all("estimators", estimators), all("others", others)].concat()
            }
            ClaimSpec::Optimum { inside, outside, .. } => [all("inside", inside), all("outside", outside)].concat(),
            ClaimSpec::RatioOfRatios { numerator, denominator, .. } => {
                [all("numerator", numerator), all("denominator", denominator)].concat()
            }
        }
    }

    /// Every number of the claim with its field, and the range it must lie in beyond being finite
    /// (`None`: any finite number).
    fn numbers(&self) -> Vec<(&'static str, f64, Option<Range>)> {
        let paper = |field, v: &Option<f64>| v.map(|x| (field, x, None));
        match self {
            ClaimSpec::Slope { value, .. } => vec![("value", *value, None)],
            ClaimSpec::SlopeBelow { value, paper: p, .. } => {
                std::iter::once(("value", *value, None)).chain(paper("paper", p)).collect()
            }
            ClaimSpec::Speedup { value, .. } => vec![("value", *value, Some(Range::Positive))],
            ClaimSpec::Ratio { threshold, value, .. } | ClaimSpec::RatioOfRatios { threshold, value, .. } => {
                std::iter::once(("threshold", *threshold, Some(Range::Positive))).chain(paper("value", value)).collect()
            }
            ClaimSpec::Ordering { value, .. } | ClaimSpec::Optimum { value, .. } => {
                paper("value", value).into_iter().collect()
            }
            ClaimSpec::Diagnostic { value, tolerance, .. } => {
                vec![("value", *value, None), ("tolerance", *tolerance, Some(Range::NotNegative))]
            }
            ClaimSpec::ControlFlagged { .. } => Vec::new(),
        }
    }

    /// The budget the claim names, if any.
    pub fn budget(&self) -> Option<u64> {
        match self {
            ClaimSpec::Ratio { budget, .. }
            | ClaimSpec::Ordering { budget, .. }
            | ClaimSpec::Optimum { budget, .. }
            | ClaimSpec::RatioOfRatios { budget, .. } => *budget,
            ClaimSpec::Diagnostic { budget, .. } => Some(*budget),
            _ => None,
        }
    }

    /// Checks the claim on its own (see the module docs): the error names the field.
    pub fn check(&self) -> Result<(), ClaimError> {
        for (field, x, range) in self.numbers() {
            if !x.is_finite() {
                return Err(err(field, x, ClaimProblem::NotFinite));
            }
            match range {
                Some(Range::Positive) if x <= 0.0 => {
                    return Err(err(field, x, ClaimProblem::OutOfRange("a factor or ratio must be positive")))
                }
                Some(Range::NotNegative) if x < 0.0 => {
                    return Err(err(field, x, ClaimProblem::OutOfRange("a relative tolerance must not be negative")))
                }
                _ => {}
            }
        }
        let same = |field: &'static str, n: &str| Err(err(field, n, ClaimProblem::SelfComparison(n.to_string())));
        match self {
            ClaimSpec::Speedup { estimator, baseline: Some(b), .. } if estimator == b => same("baseline", b),
            ClaimSpec::Ratio { estimator, baseline, .. } if estimator == baseline => same("baseline", baseline),
            ClaimSpec::Ordering { estimators: a, others: b, .. } | ClaimSpec::Optimum { inside: a, outside: b, .. } => {
                let (fa, fb) = side(self);
                if a.is_empty() || b.is_empty() {
                    return Err(err(if a.is_empty() { fa } else { fb }, "[]", ClaimProblem::EmptySide));
                }
                let named = self.named();
                match named.iter().enumerate().find(|(i, n)| named[..*i].iter().any(|m| m.1 == n.1)) {
                    Some((_, (field, n))) => same(field, n),
                    None => Ok(()),
                }
            }
            ClaimSpec::RatioOfRatios { numerator: n, denominator: d, .. } => {
                match [("numerator", n), ("denominator", d)].into_iter().find(|(_, p)| p[0] == p[1]) {
                    Some((field, p)) => same(field, &p[0]),
                    None => Ok(()),
                }
            }
            _ => Ok(()),
        }
    }

    /// Checks the claim against what the plan runs (see the module docs): the error names the
    /// field.
    pub fn check_against(&self, ran: &Ran<'_>) -> Result<(), ClaimError> {
        let testbed = self.testbed();
        if let Some(t) = testbed {
            if !ran.beds.iter().any(|b| b == t) {
                let runs: Vec<&str> = ran
                    .beds
                    .iter()
                    .enumerate()
                    .filter(|(i, b)| !ran.beds[..*i].contains(b))
                    .map(|(_, b)| b.as_str())
                    .collect();
                return Err(err("testbed", t, ClaimProblem::UnknownTestbed(runs.join(", "))));
            }
        }
        for (field, name) in self.named() {
            ran.check_runs(field, name, testbed)?;
        }
        if let ClaimSpec::Speedup { estimator, baseline: None, .. } = self {
            let b = ran.baseline.ok_or_else(|| err("baseline", "(none)", ClaimProblem::NoBaseline))?;
            if b == estimator {
                return Err(err("estimator", estimator, ClaimProblem::SelfComparison(b.to_string())));
            }
            ran.check_runs("baseline", b, testbed)?;
        }
        if let Some(b) = self.budget() {
            if !ran.budgets.contains(&b) {
                let all: Vec<String> = ran.budgets.iter().map(u64::to_string).collect();
                return Err(err("budget", b, ClaimProblem::UnknownBudget(all.join(", "))));
            }
        }
        Ok(())
    }

    /// The claim as an error names it: its text in quotes (shortened, on one line), or its kind
    /// for `control_flagged`.
    pub fn describe(&self) -> String {
        match self.text() {
            Some(t) => format!("\"{}\"", crate::output::report::shorten(&one_line(t), 60)),
            None => "control_flagged".to_string(),
        }
    }
}

fn side(c: &ClaimSpec) -> (&'static str, &'static str) {
    match c {
        ClaimSpec::Optimum { .. } => ("inside", "outside"),
        _ => ("estimators", "others"),
    }
}

/// The range a number of a claim must lie in.
#[derive(Clone, Copy)]
enum Range {
    /// Above zero (a factor, a ratio's threshold).
    Positive,
    /// Zero or above (a tolerance).
    NotNegative,
}

/// `text` with every control character (a line break among them) as a space.
fn one_line(text: &str) -> String {
    text.chars().map(|c| if c.is_control() { ' ' } else { c }).collect()
}

/// The error of the claim at `index` of a sweep, as bad input: one line naming the claim, its
/// text and the field.
pub fn config_error(index: usize, claim: &ClaimSpec, e: ClaimError) -> mcbench_core::error::ConfigError {
    mcbench_core::error::ConfigError::invalid(
        format!("claims[{index}].{}", e.field),
        one_line(&e.value),
        one_line(&format!("{} (the claim: {})", e.problem, claim.describe())),
    )
}

#[cfg(test)]
#[path = "claim_check_tests.rs"]
mod tests;

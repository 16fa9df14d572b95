//! The estimator cases of the `stability` experiment (book: stability.md) and their runner: each case runs
//! one configured estimator on one (small) test-bed variant for a number of repetitions and ends
//! in one of three outcomes:
//! - `correct`: every estimate finite, and the harness's own unbiasedness test
//!   ([`mcbench::analysis::unbiasedness`], the deciding Holm or pooled test of
//!   [`mcbench::analysis::claims::decisive_test`]) agrees with the estimator's registered bias claim;
//! - `refused`: the test bed, the estimator, its validation or an estimate refused with a typed
//!   error (its one-line text is recorded);
//! - `FAILED`: a panic, a non-finite estimate, or a mean off the reference beyond its error bars.
//!
//! A panic is caught per repetition ([`std::panic::catch_unwind`]) so one bad case cannot abort
//! the run.
//!
//! The cases themselves, and the table of places where a pdf can be zero, are data:
//! `stability_cases.toml` beside this file, embedded and read by [`CaseFile::load`].

use mcbench::analysis::claims::decisive_test;
use mcbench::analysis::unbiasedness;
use mcbench::config::Mode;
use mcbench::error::HarnessError;
use mcbench::registry::Registry;
use mcbench::run::guarded::{self, one_line, Stopped};
use mcbench_core::budget::Budget;
use mcbench_core::error::EstimateError;
use mcbench_core::params::Params;
use mcbench_core::rng::StreamKey;
use mcbench_core::stats::Moments;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What theory says a case must do (`expect = "correct"` or `"refused"` in the case file).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Expect {
    /// Finite and unbiased (or as its bias claim says) within error bars.
    Correct,
    /// Refused with a typed one-line error.
    Refused,
}

/// One estimator case (a `[[case]]` of `stability_cases.toml`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Short id (`stability.csv` column `case`).
    pub id: String,
    /// The stability item (or pdf-zero site) it covers (book: stability.md).
    pub spec_item: String,
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Test-bed parameters (none when left out).
    #[serde(default)]
    pub bed: Params,
    /// Estimator id.
    pub estimator: String,
    /// Estimator parameters (none when left out).
    #[serde(default)]
    pub params: Params,
    /// Samples per estimate.
    pub samples: u64,
    /// Repetitions (of every integral); the file holds the quick-mode count.
    pub reps: u64,
    /// What theory expects.
    pub expect: Expect,
}

/// One row of `pdf_zero.csv` (a `[[pdf_zero]]` of `stability_cases.toml`): a place where a
/// sampling pdf can be 0, and how it is guarded.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PdfZero {
    /// The source file (and function) of the guard.
    pub site: String,
    /// What the guard does.
    pub guard: String,
    /// The stability cases that exercise it (comma separated).
    pub cases: String,
}

/// The case file, `stability_cases.toml`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseFile {
    /// The estimator cases, in order, with their quick-mode repetitions (read them through
    /// [`CaseFile::cases`], which scales the repetitions to the mode).
    #[serde(rename = "case")]
    cases: Vec<Case>,
    /// Where a pdf can be zero in `estimators/src`.
    pub pdf_zero: Vec<PdfZero>,
}

/// Full mode runs this many times the repetitions the case file gives (those of quick mode).
pub const FULL_REPS_FACTOR: u64 = 4;

/// Where the case file lives (for messages).
const CASE_FILE: &str = "experiments/src/stability_cases.toml";

impl CaseFile {
    /// The embedded `stability_cases.toml`, unknown keys refused; an error names the line and the
    /// message (for an unknown key: the key and the valid ones).
    pub fn load() -> mcbench::error::Result<Self> {
        let text = include_str!("stability_cases.toml");
        toml::from_str(text).map_err(|e: toml::de::Error| {
            let line = e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            let at = line.map(|l| format!("line {l}: ")).unwrap_or_default();
            HarnessError::bad_file(CASE_FILE, format!("{at}{}", one_line(e.message())))
        })
    }

    /// The cases of a mode: the file's repetitions in quick mode, [`FULL_REPS_FACTOR`] times them
    /// in full mode.
    pub fn cases(&self, mode: Mode) -> Vec<Case> {
        let k = if mode == Mode::Quick { 1 } else { FULL_REPS_FACTOR };
        self.cases.iter().map(|c| Case { reps: c.reps * k, ..c.clone() }).collect()
    }
}

/// The outcome of a case (one row of `stability.csv`).
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// `correct`, `refused` or `FAILED`.
    pub outcome: &'static str,
    /// Our value (mean over integrals and repetitions, channel 0; or the measured quantity).
    pub value: f64,
    /// The reference of `value`.
    pub reference: f64,
    /// The deciding statistic: `|z|` of the pooled test or the relative error.
    pub statistic: f64,
    /// What `statistic` is (`z`, `holm_t p`, `rel_err`, ...).
    pub statistic_name: String,
    /// The refusal or failure text (one line), or a note.
    pub text: String,
}

impl Outcome {
    fn refused(text: impl ToString) -> Self {
        Outcome {
            outcome: "refused",
            value: f64::NAN,
            reference: f64::NAN,
            statistic: f64::NAN,
            statistic_name: String::new(),
            text: one_line(&text.to_string()),
        }
    }
    fn failed(text: impl ToString) -> Self {
        Outcome { outcome: "FAILED", ..Outcome::refused(text) }
    }
}

/// One repetition's estimates of every integral, or the error that stopped it.
fn one_rep(
    est: &dyn mcbench_core::estimator::Estimator,
    bed: &dyn TestBed,
    case: &Case,
    seed: u64,
    rep: u64,
) -> Result<Vec<[f64; 3]>, String> {
    let budget = Budget::samples(case.samples).map_err(|e| e.to_string())?;
    let f = bed.sequence_length().max(1);
    let mut out = Vec::with_capacity(bed.integrals());
    for first in (0..bed.integrals()).step_by(f) {
        let key = StreamKey {
            seed,
            testbed: &case.id,
            estimator: &case.estimator,
            budget: case.samples,
            rep,
            integral: first as u64,
        };
        match guarded::sequence(est, bed, &key, budget, first) {
            Err(Stopped::Panicked(m)) => return Err(format!("panic: {m}")),
            Err(Stopped::Error(EstimateError::Refused(t))) => return Err(format!("refused: {t}")),
            Err(Stopped::Error(e)) => return Err(format!("failed: {e}")),
            Ok(v) => out.extend(v),
        }
    }
    Ok(out)
}

/// Runs one case (never panics: panics inside estimators are caught and reported).
pub fn run(case: &Case, seed: u64, registry: &Registry) -> Outcome {
    catch_unwind(AssertUnwindSafe(|| run_inner(case, seed, registry)))
        .unwrap_or_else(|p| Outcome::failed(format!("panic: {}", guarded::panic_message(p))))
}

fn run_inner(case: &Case, seed: u64, registry: &Registry) -> Outcome {
    let entry = match registry.test_bed(&case.testbed) {
        Ok(e) => e,
        Err(e) => return Outcome::refused(e),
    };
    let bed = match (entry.build)(&case.variant, &case.bed, registry.references()) {
        Ok(b) => b,
        Err(e) => return Outcome::refused(e),
    };
    let est_entry = match registry.estimator(&case.estimator) {
        Ok(e) => e,
        Err(e) => return Outcome::refused(e),
    };
    let est = match (est_entry.build)(&case.params) {
        Ok(e) => e,
        Err(e) => return Outcome::refused(e),
    };
    if let Some(why) = est_entry.skip_reason(bed.provides()) {
        return Outcome::refused(why);
    }
    if let Err(e) = est.validate(bed.as_ref()) {
        return Outcome::refused(e);
    }
    if let Err(why) = est.supports(bed.as_ref()) {
        return Outcome::refused(why);
    }
    let reps: Vec<Result<Vec<[f64; 3]>, String>> =
        (0..case.reps).into_par_iter().map(|rep| one_rep(est.as_ref(), bed.as_ref(), case, seed, rep)).collect();
    if let Some(Err(e)) = reps.iter().find(|r| matches!(r, Err(e) if !e.starts_with("refused: "))) {
        return Outcome::failed(e);
    }
    if let Some(Err(e)) = reps.iter().find(|r| r.is_err()) {
        let n = reps.iter().filter(|r| r.is_err()).count();
        let text = e.trim_start_matches("refused: ");
        return Outcome::refused(format!("{text} ({n} of {} repetitions)", case.reps));
    }
    let n = bed.integrals();
    let per_rep: Vec<Vec<[f64; 3]>> = reps.into_iter().flatten().collect();
    let budget =
        Budget::samples(case.samples).unwrap_or(Budget { kind: mcbench_core::budget::BudgetKind::Samples, amount: 1 });
    let cell = guarded::cell_of(bed.as_ref(), &case.estimator, budget, seed, &per_rep);
    let moments = &cell.moments;
    if moments.iter().flatten().any(|m| !m.mean().is_finite()) {
        return Outcome::failed("non-finite estimate");
    }
    let reference = bed.reference();
    let value = moments.iter().map(|m| m[0].mean()).sum::<f64>() / n as f64;
    let ref_value = reference.value.iter().map(|r| r[0]).sum::<f64>() / n as f64;
    if let Some(o) = exact_moments_test(est.as_ref(), bed.as_ref(), case, &cell.moments) {
        return Outcome { value, reference: ref_value, ..o };
    }
    // No independent gate here: a correct unbiased estimator is one the test does not flag.
    let rows = unbiasedness(&cell, reference, est_entry.bias, None, mcbench::analysis::DEFAULT_TOLERANCE);
    let Some(t) = decisive_test(&rows, &case.variant, &case.estimator, "") else {
        return Outcome::failed("no unbiasedness test could run");
    };
    let note = format!(
        "{} p = {:.3e} ({}), bias claim {}; mean {value:.6e} vs reference {ref_value:.6e}",
        t.test,
        t.p_value,
        t.verdict,
        est_entry.bias.name()
    );
    let correct = match est_entry.bias {
        mcbench_core::estimator::Bias::Unbiased => t.verdict != "biased",
        _ => t.agrees,
    };
    Outcome {
        outcome: if correct { "correct" } else { "FAILED" },
        value,
        reference: ref_value,
        statistic: t.p_value,
        statistic_name: format!("{} p", t.test),
        text: note,
    }
}

/// Where the estimator knows the exact variance of one sample on every integral (paper 002 §3.4
/// trackers, [`mcbench_core::estimator::Estimator::sample_moments`]), the error bars come from it: a
/// z-test of the summed deviation over the integrals (channel 0) against the exact standard error.
/// This is the only honest test for a rare-event configuration such as `sigma_samp = 1e-6 x
/// sigma_t`, whose collisions (weight `1 - r ~ -1e6`) a few hundred repetitions never see, so their
/// sample variance is 0 and a sample-based test would call an unbiased estimator biased. `None`
/// when any integral lacks exact moments or its variance is not finite.
fn exact_moments_test(
    est: &dyn mcbench_core::estimator::Estimator,
    bed: &dyn TestBed,
    case: &Case,
    moments: &[[Moments; 3]],
) -> Option<Outcome> {
    let budget = Budget::samples(case.samples).ok()?;
    let (mut dev, mut var, mut reference) = (0.0, 0.0, 0.0);
    for (i, m) in moments.iter().enumerate() {
        let exact = est.sample_moments(&Task::new(bed, i, budget))?;
        let v = exact.variance();
        if !v.is_finite() {
            return None;
        }
        let r = bed.reference().value[i][0];
        dev += m[0].mean() - r;
        reference += r;
        var += v / (case.samples * case.reps) as f64;
    }
    let t = mcbench_core::stats::z_test(reference + dev, var.sqrt(), reference);
    let agrees = t.p_value >= mcbench::analysis::UNBIASEDNESS_ALPHA
        || (var == 0.0 && dev.abs() <= 1e-12 * reference.abs().max(1e-300));
    Some(Outcome {
        outcome: if agrees { "correct" } else { "FAILED" },
        value: f64::NAN,
        reference: f64::NAN,
        statistic: t.p_value,
        statistic_name: "exact_z p".into(),
        text: format!(
            "z-test against the exact sample variance (paper 002 §3.4 moments): summed deviation {dev:.3e}, exact standard error {:.3e}, p = {:.3e}; sample-based standard error {:.3e}",
            var.sqrt(),
            t.p_value,
            moments.iter().map(|m| m[0].std_err().powi(2)).sum::<f64>().sqrt()
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::math::Rgb;
    use mcbench_core::rng::StreamRng;

    struct Panics;
    impl mcbench_core::estimator::Estimator for Panics {
        fn estimate(&self, _: &Task<'_>, _: &mut StreamRng) -> Result<Rgb, EstimateError> {
            panic!("boom\nsecond line")
        }
    }

    fn case(estimator: &str, params: Params, expect: Expect) -> Case {
        Case {
            id: "t".into(),
            spec_item: "test".into(),
            testbed: "canonical-1d".into(),
            variant: "constant-T0.5".into(),
            bed: Params::new().with("tau", 0.0),
            estimator: estimator.into(),
            params,
            samples: 2,
            reps: 8,
            expect,
        }
    }

    /// The case file parses, its case ids are unique, and every case names a registered test bed
    /// and estimator that build with its parameters (a misspelled parameter name fails here).
    #[test]
    fn every_case_of_the_file_builds() {
        let file = CaseFile::load().unwrap_or_else(|e| panic!("{e}"));
        assert!(!file.cases.is_empty() && !file.pdf_zero.is_empty());
        let registry = crate::test_registry();
        let mut ids = std::collections::BTreeSet::new();
        for c in &file.cases {
            assert!(ids.insert(c.id.as_str()), "case id {} appears twice", c.id);
            assert!(c.samples > 0 && c.reps > 0, "{}: no samples or repetitions", c.id);
            let bed = registry.test_bed(&c.testbed).unwrap_or_else(|e| panic!("{}: {e}", c.id));
            (bed.build)(&c.variant, &c.bed, registry.references()).unwrap_or_else(|e| panic!("{}: {e}", c.id));
            let est = registry.estimator(&c.estimator).unwrap_or_else(|e| panic!("{}: {e}", c.id));
            (est.build)(&c.params).unwrap_or_else(|e| panic!("{}: {e}", c.id));
        }
        let full = file.cases(Mode::Full);
        assert!(full.iter().zip(&file.cases).all(|(f, q)| f.reps == FULL_REPS_FACTOR * q.reps));
    }

    #[test]
    fn outcomes_are_correct_refused_or_failed_never_a_panic() {
        let ok = run(
            &case("delta_tracking", Params::new(), Expect::Correct),
            1,
            &Registry::new().with_catalog(mcbench_papers::catalog()),
        );
        assert_eq!(ok.outcome, "correct", "{ok:?}");
        // Optical depth ln 2 (the default of constant-T0.5): r = 1e6 > 2/(a+1), the model refuses.
        let terminating = Case {
            bed: Params::new(),
            ..case("single_particle_terminating", Params::new().with("sigma_samp_ratio", 1e-6), Expect::Refused)
        };
        let refused = run(&terminating, 1, &Registry::new().with_catalog(mcbench_papers::catalog()));
        assert!(refused.outcome == "refused" && refused.text.contains("sigma_samp"), "{refused:?}");
        let unknown = run(
            &case("no_such_estimator", Params::new(), Expect::Refused),
            1,
            &Registry::new().with_catalog(mcbench_papers::catalog()),
        );
        assert!(unknown.outcome == "refused" && unknown.text.contains("no_such_estimator"), "{unknown:?}");
        // A panicking estimator is caught and reported in one line.
        let c = case("delta_tracking", Params::new(), Expect::Correct);
        let bed = Registry::new()
            .with_catalog(mcbench_papers::catalog())
            .test_bed("canonical-1d")
            .unwrap()
            .build_exact(&c.variant, &c.bed)
            .unwrap();
        let err = one_rep(&Panics, bed.as_ref(), &c, 1, 0).unwrap_err();
        assert_eq!(err, "panic: boom");
    }
}

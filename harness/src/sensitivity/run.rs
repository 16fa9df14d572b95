//! Running a sensitivity file: every part at every setting into the experiment's results folder,
//! each claim judged on its setting's cells alone.

use super::outcome::{classify, Outcome};
use super::table::{self, SettingRow};
use super::{setting_text, Ceiling, Part, SensitivityFile};
use crate::analysis;
use crate::config::{Mode, Sweep};
use crate::error::{HarnessError, Result};
use crate::output::{Claim, Diagnostic, RunReport};
use crate::plan::Plan;
use crate::registry::PostContext;
use crate::registry::{Experiment, Registry, Sweeps};
use crate::run::runner::{self, RunResults};
use crate::verdict::Verdict;
use std::path::{Path, PathBuf};

/// The sweep the experiment runs first (the first part at its default setting); the other
/// settings run in [`post`].
pub fn first_sweep(file: &SensitivityFile, mode: Mode) -> Result<Sweep> {
    let part = file.parts.first().ok_or_else(|| HarnessError::bad_file("sensitivity file", "no parts"))?;
    Ok(part.setting(&file.name, 1, mode, &part.default)?.0)
}

/// The experiment of a sensitivity file, with the crate's own `post` and `preflight` (functions
/// that call [`post`] and [`preflight`] with the file).
pub fn experiment(
    file: &SensitivityFile,
    post: crate::registry::PostFn,
    preflight: crate::registry::PreflightFn,
) -> Result<Experiment> {
    Ok(Experiment {
        name: file.name.clone(),
        reproduces: file.reproduces.clone(),
        summary: file.summary.clone(),
        sweeps: Sweeps::Fixed {
            quick: Box::new(first_sweep(file, Mode::Quick)?),
            full: Box::new(first_sweep(file, Mode::Full)?),
        },
        claims: None,
        post: Some(post),
        preflight: Some(preflight),
    })
}

/// Every setting's sweep as it will run after `first` (seed and mode from it).
fn settings<'a>(
    file: &'a SensitivityFile,
    first: &Sweep,
) -> Result<Vec<(&'a Part, usize, Sweep, crate::config::claim_spec::ClaimSpec)>> {
    let mut out = Vec::new();
    for part in &file.parts {
        for (i, v) in part.values.iter().enumerate() {
            let (sweep, claim) = part.setting(&first.experiment, first.seed, first.mode, v)?;
            out.push((part, i, sweep, claim));
        }
    }
    Ok(out)
}

/// Checks, before anything is written, that every setting builds (names, parameters, stored
/// references) and that its stored cells read back.
pub fn preflight(file: &SensitivityFile, registry: &Registry, first: &Sweep, cells: &Path) -> Result<()> {
    let store = crate::store::Store::open(cells)?;
    for (_, _, sweep, _) in settings(file, first)? {
        let plan = Plan::prepare(sweep, registry)?;
        runner::preload_from(&plan, Some(&store))?;
    }
    Ok(())
}

/// The report of one setting's cells, as the claims read it: rows, fits, speed-ups, diagnostics.
pub fn setting_report(plan: &Plan, run: &RunResults, like: &RunReport) -> RunReport {
    let rows: Vec<_> = run.cells.iter().map(|(bi, ei, cell)| plan.summary_row(*bi, *ei, cell)).collect();
    let diagnostics = run.cells.iter().flat_map(|(_, _, cell)| Diagnostic::of_cell(cell)).collect();
    let fits = analysis::fits(&rows);
    let model = &plan.sweep.cost_model;
    let speedups =
        plan.sweep.baseline.as_deref().map(|b| analysis::speedups(&rows, &fits, b, model)).unwrap_or_default();
    RunReport {
        meta: like.meta.clone(),
        fits,
        tests: Vec::new(),
        paper: Vec::new(),
        speedups,
        skipped: plan.skipped.clone(),
        unavailable: Vec::new(),
        counts: rows.iter().map(Into::into).collect(),
        rows,
        labels: plan.estimators.iter().map(|e| (e.name.clone(), e.entry.label.to_string())).collect(),
        diagnostics,
        beds: like.beds.clone(),
    }
}

/// The error a work ratio multiplies by rays, read from a summary row.
type ErrorOf = fn(&crate::analysis::metrics::SummaryRow) -> f64;

/// The best measured limit of `claim` on one setting's report (not a bound: [`Ceiling`]).
pub(super) fn ceiling(
    kind: Ceiling,
    claim: &crate::config::claim_spec::ClaimSpec,
    sweep_baseline: Option<&str>,
    report: &RunReport,
) -> Option<f64> {
    use crate::analysis::claims::RatioMetric;
    use crate::analysis::metrics::SummaryRow;
    use crate::config::claim_spec::ClaimSpec;
    match kind {
        Ceiling::WorkRatio => {
            // The error measure the claim's efficiency divides by, and the budget it is read at.
            let (estimator, base, error, budget): (&str, &str, ErrorOf, Option<u64>) = match claim {
                ClaimSpec::Speedup { estimator, baseline, .. } => {
                    (estimator, baseline.as_deref().or(sweep_baseline)?, |r| r.variance, None)
                }
                ClaimSpec::Ratio { estimator, baseline, metric, budget, .. } => {
                    let error: ErrorOf = match metric {
                        RatioMetric::EfficiencyMse => |r| r.mse,
                        RatioMetric::PEff => |r| r.p_err,
                        _ => return None,
                    };
                    (estimator, baseline, error, *budget)
                }
                _ => return None,
            };
            let last = budget.or_else(|| report.query().largest_budget())?;
            let at = |name: &str| report.query().estimator(name).at(last).first();
            let (m, b) = (at(estimator)?, at(base)?);
            let work = |r: &SummaryRow| error(r) * r.rays.max(f64::MIN_POSITIVE);
            let v = work(b) / work(m);
            v.is_finite().then_some(v)
        }
    }
}

/// Runs every setting of every part (the first part's default is the experiment's own run),
/// judges each part's claim per setting, and writes `sensitivity.csv`, `sensitivity.md`, one
/// plot per part and one claim per part (its outcome) into the report.
pub fn post(file: &SensitivityFile, cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { plan, results: run, report, out: results, plots, registry } = cx;
    let threads = report.meta.threads;
    let mut rows: Vec<SettingRow> = Vec::new();
    for (part, i, sweep, claim) in settings(file, &plan.sweep)? {
        let value = &part.values[i];
        let sub = if sweep == plan.sweep {
            setting_report(plan, run, report)
        } else {
            let p = Plan::prepare(sweep.clone(), registry)?;
            let r = runner::run_stored(&p, results.join(crate::store::CELLS), threads)?;
            setting_report(&p, &r, report)
        };
        let judged = claim.judge(&sub);
        let measured = part.ceiling.and_then(|k| ceiling(k, &claim, sweep.baseline.as_deref(), &sub));
        let bound = part.bound.as_ref().map(|b| b.values[i]);
        rows.push(SettingRow::new(part, value, &judged, bound, measured));
    }
    let mut written = Vec::new();
    let mut outcomes: Vec<(&Part, Outcome)> = Vec::new();
    for part in &file.parts {
        let mine: Vec<&SettingRow> = rows.iter().filter(|r| r.part == part.id).collect();
        let outcome = classify(part, &mine);
        report.paper.push(outcome_claim(part, &mine, &outcome));
        if let Some(dir) = plots {
            written.extend(table::plot(dir, part, &mine)?);
        }
        outcomes.push((part, outcome));
    }
    results.write_csv("sensitivity.csv", &rows)?;
    results.write("sensitivity.md", table::markdown(&outcomes, &rows).as_bytes())?;
    report.meta.notes.push(format!(
        "sensitivity: {} parts, {} settings; each claim judged on its setting's cells alone (sensitivity.csv)",
        file.parts.len(),
        rows.len()
    ));
    Ok(written)
}

/// A part's outcome as a claim of the report: the verdict at the paper-like setting (else at our
/// default), the outcome in the note.
fn outcome_claim(part: &Part, rows: &[&SettingRow], outcome: &Outcome) -> Claim {
    let at = part.paper_like.as_ref().unwrap_or(&part.default);
    let row = rows.iter().find(|r| r.setting == setting_text(at));
    Claim {
        testbed: row.map(|r| r.testbed.clone()).unwrap_or_default(),
        claim: format!("paper {}: {} (against {})", part.paper, part.headline, part.vary),
        paper_value: row.and_then(|r| r.paper_value),
        our_value: row.and_then(|r| r.value),
        held: row.and_then(|r| r.verdict.held()),
        note: outcome.sentence(),
        verdict: Some(row.map_or(Verdict::NotMeasured, |r| r.verdict)),
        interval: row.and_then(|r| Some([r.low?, r.high?])),
        pair: row.map(|r| r.pair.clone()).unwrap_or_default(),
        regime: row.map(|r| r.regime.clone()).unwrap_or_default(),
        reason: format!("{}: {}", outcome.kind(), part.open),
        p_value: None,
    }
}

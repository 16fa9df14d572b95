//! The `calibration` experiment: the unbiasedness tests' own operating characteristics, measured.
//!
//! For each row family (an estimator on a test-bed case at the samples and repetitions of its
//! `unbiasedness` row) it runs the harness's test, gated by a pilot exactly as that experiment
//! does, on many independent seeds ([`measure`]), with no bias, with injected relative biases
//! ([`Scaled`]) and with a firefly rejection ([`FireflyRejection`]), and reports
//! ([`table`]): the false-flag rate at a nominal 5% with its interval, the power at 1% and 3%, the
//! detectable bias the rows report beside the bias measured to be flagged in 80% of seeds, and how
//! often each control is flagged.
//!
//! Families are derived from the registry like the `unbiasedness` parts: for every test-bed case,
//! the first unbiased estimators that run on it (registry order; one in quick mode, two in full,
//! [`unbiased_per_case`]) and every
//! biased control not exempted there. The experiment's own sweep is the first `unbiasedness` part's
//! first case at one seed; the analysis ([`post`]) measures every family.

pub mod measure;
pub mod report;
pub mod rounds;
pub mod size;
pub mod table;
pub mod wrap;

pub use wrap::{FireflyRejection, Scaled};

use crate::config::{Mode, Sweep};
use crate::error::Result;
use crate::plan::Plan;
use crate::registry::PostContext;
use crate::registry::{Experiment, Registry, Sweeps};
use mcbench_core::estimator::Bias;
use measure::Family;
use std::path::PathBuf;
use std::time::Instant;

/// The experiment's name.
pub const NAME: &str = "calibration";
/// Unbiased estimators per test-bed case in a mode.
pub fn unbiased_per_case(mode: Mode) -> usize {
    match mode {
        Mode::Quick => 1,
        Mode::Full => 2,
    }
}

/// Seeds per family in a mode.
pub fn seeds(mode: Mode) -> usize {
    match mode {
        Mode::Quick => 100,
        Mode::Full => 400,
    }
}

/// The `calibration` experiment over whatever registry it runs in.
pub fn experiment() -> Experiment {
    Experiment {
        name: NAME.into(),
        reproduces: "size, power and detectable bias of the unbiasedness tests, measured".into(),
        summary: "the unbiasedness tests over many seeds with injected biases: false-flag rate, power, detectable bias, controls".into(),
        sweeps: Sweeps::Derived(first_sweep),
        claims: None,
        post: Some(post),
        preflight: None,
    }
}

/// The row families of a registry in a mode (see the module docs): derived from the registry
/// before any `--estimators` / `--testbeds` selection ([`Registry::unselected`]) and then narrowed
/// to the selected estimators and test beds, so a family is the same (the same case, samples,
/// repetitions, seeds and streams) whichever other families run, and the table can be completed in
/// pieces.
pub fn families(registry: &Registry, mode: Mode) -> Vec<Family> {
    let full = registry.unselected();
    let mut out = Vec::new();
    // Every unbiased estimator's cheapest case (samples x repetitions x integrals, then registry
    // order), for the estimators no case's first-unbiased rule reaches.
    let mut cheapest: Vec<(u64, Family)> = Vec::new();
    for part in crate::unbiasedness::parts(&full, mode) {
        for bed in &part.sweep.testbeds {
            let one = Sweep { testbeds: vec![bed.clone()], ..part.sweep.clone() };
            let Ok((plans, _)) = crate::unbiasedness::run::prepare_valid(one, &full) else { continue };
            let mut unbiased = 0;
            for plan in &plans {
                let integrals = plan.beds.first().map_or(1, |b| b.bed.integrals()) as u64;
                for &(_, ei) in &plan.pairs {
                    let e = &plan.estimators[ei];
                    let variant = bed.variant.clone().unwrap_or_default();
                    let family = Family {
                        bed: bed.clone(),
                        estimator: e.spec.clone(),
                        samples: part.samples,
                        reps: part.sweep.reps,
                        bias: e.entry.bias,
                    };
                    let take = match e.entry.bias {
                        Bias::Unbiased if unbiased < unbiased_per_case(mode) => {
                            unbiased += 1;
                            true
                        }
                        Bias::Biased => {
                            crate::unbiasedness::run::exemption(&full, &e.spec.id, &bed.id, &variant).is_none()
                        }
                        _ => false,
                    };
                    if e.entry.bias == Bias::Unbiased {
                        let cost = part.samples * part.sweep.reps as u64 * integrals;
                        match cheapest.iter_mut().find(|(_, f)| f.estimator.id == e.spec.id) {
                            Some(c) if cost < c.0 => *c = (cost, family.clone()),
                            Some(_) => {}
                            None => cheapest.push((cost, family.clone())),
                        }
                    }
                    if take {
                        out.push(family);
                    }
                }
            }
        }
    }
    for (_, f) in cheapest {
        if !out.iter().any(|o| o.estimator.id == f.estimator.id) {
            out.push(f);
        }
    }
    out.retain(|f| {
        registry.estimators().iter().any(|e| e.id == f.estimator.id)
            && registry.test_beds().iter().any(|t| t.id == f.bed.id)
    });
    out
}

/// The families a run measures: every derived family when the run's sweep is the experiment's own,
/// otherwise the pairs of the sweep given (`--config`) at each of its sample budgets and its
/// repetitions: a researcher calibrates the rows of their own sweep.
pub fn families_of_run(plan: &Plan, registry: &Registry) -> Vec<Family> {
    let own = first_sweep(registry, plan.sweep.mode);
    let s = &plan.sweep;
    if s.testbeds == own.testbeds && s.estimators == own.estimators && s.budgets == own.budgets && s.reps == own.reps {
        return families(registry, plan.sweep.mode);
    }
    let mut out = Vec::new();
    for budget in s.budgets.iter().filter(|b| b.kind == mcbench_core::budget::BudgetKind::Samples) {
        for &(bi, ei) in &plan.pairs {
            out.push(Family {
                bed: s.testbeds[bi].clone(),
                estimator: plan.estimators[ei].spec.clone(),
                samples: budget.amount,
                reps: s.reps,
                bias: plan.estimators[ei].bias(),
            });
        }
    }
    out
}

/// The experiment's own sweep: the first `unbiasedness` part on its first test-bed case (cheap to
/// derive: no test bed is built).
fn first_sweep(registry: &Registry, mode: Mode) -> Sweep {
    let mut s = crate::unbiasedness::experiment().sweep(registry, mode);
    s.experiment = NAME.into();
    s.testbeds.truncate(1);
    s
}

/// Measures every family and writes `calibration.csv` and `calibration.md`, and the claims.
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    if !cx.plan.sweep.repetitions.is_fixed() {
        return rounds::post(cx);
    }
    let PostContext { plan, report, out: results, registry, .. } = cx;
    let t0 = Instant::now();
    let mode = plan.sweep.mode;
    let n = seeds(mode);
    let tolerance = plan.sweep.tolerance();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(report.meta.threads.max(1)).build();
    let mut rows = Vec::new();
    let mut seeds_p = Vec::new();
    let mut timing = Vec::new();
    for family in families_of_run(plan, registry) {
        let t = Instant::now();
        let m = match &pool {
            Ok(p) => p.install(|| measure::measure(&family, n, plan.sweep.seed, tolerance, mode, registry)),
            Err(_) => measure::measure(&family, n, plan.sweep.seed, tolerance, mode, registry),
        }?;
        rows.push(table::row(&family, &m, &family.estimator.name()));
        seeds_p.extend(size::seed_rows(&family, &m, &family.estimator.name()));
        timing.push(format!("{}/{} {:.1} s", family.bed.id, family.estimator.name(), t.elapsed().as_secs_f64()));
    }
    let header = format!(
        "{n} seeds per family (cell and pilot of the family's repetitions each, seed {}), tolerance {:.2}%, \
         alpha {} for verdicts, 5% for the false-flag rate; {:.0} s",
        plan.sweep.seed,
        100.0 * tolerance,
        crate::analysis::UNBIASEDNESS_ALPHA,
        t0.elapsed().as_secs_f64()
    );
    table::judge_size(&mut rows);
    results.write_csv("calibration.csv", &rows)?;
    results.write_csv("calibration-pvalues.csv", &seeds_p)?;
    results.write("calibration.md", report::markdown(&rows, &header).as_bytes())?;
    report.meta.notes.push(format!("calibration: {header}; per family: {}", timing.join(", ")));
    report.paper.extend(report::claims(&rows));
    Ok(Vec::new())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn registry() -> Registry {
        Registry::new().with_catalog(mcbench_papers::catalog()).with_references(
            crate::store::references::ReferenceDir::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../estimators/references"
            )),
        )
    }

    /// Every unbiased estimator and every control that is not exempted is a family somewhere, a
    /// case gets at most one first-unbiased family in quick mode (plus the estimators whose
    /// cheapest case it is), and each family carries its row's samples and repetitions.
    #[test]
    fn families_cover_every_unbiased_estimator_and_the_controls() {
        let registry = registry();
        let all = families(&registry, Mode::Quick);
        for e in registry.estimators().iter().filter(|e| matches!(e.bias, Bias::Biased | Bias::Unbiased)) {
            assert!(all.iter().any(|f| f.estimator.id == e.id), "{} is in no family", e.id);
        }
        // Beyond the first unbiased estimator of each case, an unbiased estimator has one family.
        let mut per_case = std::collections::HashMap::new();
        for f in all.iter().filter(|f| f.bias == Bias::Unbiased) {
            per_case
                .entry((f.bed.id.clone(), f.bed.variant.clone()))
                .or_insert_with(Vec::new)
                .push(f.estimator.id.clone());
        }
        for ids in per_case.values() {
            for id in &ids[unbiased_per_case(Mode::Quick).min(ids.len())..] {
                assert_eq!(all.iter().filter(|f| &f.estimator.id == id).count(), 1, "{id}: {ids:?}");
            }
        }
        let parts = crate::unbiasedness::parts(&registry, Mode::Quick);
        for f in &all {
            assert!(parts
                .iter()
                .any(|p| p.samples == f.samples && p.sweep.reps == f.reps && p.sweep.testbeds.contains(&f.bed)));
        }
    }

    /// A selection narrows the families without changing them: the families of a registry narrowed
    /// to some estimators are exactly the full registry's families of those estimators.
    #[test]
    fn a_selection_narrows_the_families_without_changing_them() {
        let registry = registry();
        let key = |f: &Family| (f.bed.clone(), f.estimator.name(), f.samples, f.reps);
        let all: Vec<_> = families(&registry, Mode::Quick).iter().map(key).collect();
        let only = crate::selection::Selection::new(Some("pmc_hi*,spm_*,delta_tracking"), None);
        let (narrowed, _) = only.apply(&registry).unwrap();
        let some: Vec<_> = families(&narrowed, Mode::Quick).iter().map(key).collect();
        let expected: Vec<_> = all
            .iter()
            .filter(|k| ["pmc_hi", "spm_", "delta_tracking"].iter().any(|p| k.1.starts_with(p)))
            .cloned()
            .collect();
        assert_eq!(some, expected);
        assert_eq!(some.iter().filter(|k| k.1 == "pmc_hi").count(), 1);
    }
}

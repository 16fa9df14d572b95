//! Turning a [`Sweep`] into built test beds and estimators, before anything is written: every
//! bad name or value is found here (exit 2, no files touched), including a claim naming a test
//! bed, estimator or budget the plan does not run ([`crate::analysis::claim_check`]), and pairs that cannot
//! run are listed with their reason.

pub(crate) mod budget_pilot;
pub mod cost_model;

use crate::config::{EstimatorSpec, Sweep, TestBedSpec};
use crate::error::Result;
use crate::registry::Registry;
use mcbench_core::budget::BudgetKind;
use mcbench_core::entry::{EstimatorEntry, TestBedEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::estimator::Estimator;
use mcbench_core::testbed::{Needs, TestBed};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// A built test bed.
pub struct PreparedBed {
    /// Its spec.
    pub spec: TestBedSpec,
    /// Resolved variant.
    pub variant: String,
    /// The scene with its reference.
    pub bed: Box<dyn TestBed>,
    /// Its parameters with every default filled in, as JSON (result files' `testbed_params`).
    pub params_json: String,
}

impl PreparedBed {
    /// `id/variant`, the stream label of the test bed.
    pub fn label(&self) -> String {
        format!("{}/{}", self.spec.id, self.variant)
    }
}

/// A built estimator.
pub struct PreparedEstimator {
    /// Its spec.
    pub spec: EstimatorSpec,
    /// Name in result files.
    pub name: String,
    /// Registry entry (label, bias claim, needs).
    pub entry: &'static EstimatorEntry,
    /// The configured estimator.
    pub estimator: Box<dyn Estimator>,
    /// Its parameters with every default filled in, as JSON (result files' `params`).
    pub params_json: String,
}

impl PreparedEstimator {
    /// What its expectation is declared to be: the configured estimator's own declaration where its
    /// parameters change it ([`Estimator::bias`]), else its registry entry's.
    pub fn bias(&self) -> mcbench_core::estimator::Bias {
        self.estimator.bias().unwrap_or(self.entry.bias)
    }
}

/// A pair that does not run, and why.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Skipped {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// The reason.
    pub reason: String,
}

/// A sweep with everything built.
pub struct Plan {
    /// The sweep.
    pub sweep: Sweep,
    /// Built test beds.
    pub beds: Vec<PreparedBed>,
    /// Built estimators.
    pub estimators: Vec<PreparedEstimator>,
    /// (bed index, estimator index) pairs that run.
    pub pairs: Vec<(usize, usize)>,
    /// Pairs that do not.
    pub skipped: Vec<Skipped>,
}

/// `Estimator::validate` of a pair, once per process and configuration: it depends on the
/// estimator's and the test bed's registry entries and resolved parameters and the variant only,
/// and on the media it integrates exact moments of up to 16 rays (a Perlin ray's quadrature takes
/// a tenth of a second), while a run plans the same pairs again and again (the preflight and the
/// run of every part of `unbiasedness`, each with its pilot, and a sweep re-planned per test bed
/// and estimator when one pair is invalid).
fn validate(bed_entry: &'static TestBedEntry, b: &PreparedBed, e: &PreparedEstimator) -> Result<()> {
    type Validated = Mutex<HashMap<String, std::result::Result<(), ConfigError>>>;
    static VALIDATED: OnceLock<Validated> = OnceLock::new();
    let key = format!("{:p}|{}|{:p}|{}|{}", e.entry, e.params_json, bed_entry, b.variant, b.params_json);
    let memo = VALIDATED.get_or_init(Default::default);
    if let Some(r) = memo.lock().unwrap_or_else(|p| p.into_inner()).get(&key) {
        return r.clone().map_err(Into::into);
    }
    let r = e.estimator.validate(b.bed.as_ref());
    memo.lock().unwrap_or_else(|p| p.into_inner()).insert(key, r.clone());
    r.map_err(Into::into)
}

impl Plan {
    /// The summary row of a cell of this plan (book: outputs.md), with the estimator's id, both parameter
    /// sets and the efficiency in the sweep's `renderer` cost regime.
    pub fn summary_row(
        &self,
        bi: usize,
        ei: usize,
        cell: &crate::run::cell::CellResult,
    ) -> crate::analysis::metrics::SummaryRow {
        let (b, e) = (&self.beds[bi], &self.estimators[ei]);
        let mut row = crate::analysis::metrics::summarize(cell, b.bed.reference());
        row.estimator_id = e.spec.id.clone();
        row.params = e.params_json.clone();
        row.testbed_params = b.params_json.clone();
        let renderer = self.sweep.cost_model.seconds(crate::plan::cost_model::Regime::Renderer, &row);
        row.efficiency_renderer = crate::analysis::metrics::inverse(row.variance * renderer);
        row
    }

    /// Validates and builds everything (computing exact references), looking names up in
    /// `registry`, and checks every claim of the sweep against what the plan runs.
    pub fn prepare(sweep: Sweep, registry: &Registry) -> Result<Plan> {
        let plan = Plan::prepare_unchecked(sweep, registry)?;
        plan.check_claims()?;
        Ok(plan)
    }

    /// [`Plan::prepare`] without checking the sweep's claims against the plan (each is still
    /// checked on its own): for the claims a named experiment brings to a sweep a `--config` has
    /// reshaped, which are `not measured` where the reshaped sweep lacks their cells, and for a
    /// merge, whose shards were checked when they ran.
    pub fn prepare_unchecked(sweep: Sweep, registry: &Registry) -> Result<Plan> {
        let _phase = crate::run::phases::enter(crate::run::phases::Phase::Build);
        sweep.validate()?;
        let mut beds = Vec::new();
        for spec in &sweep.testbeds {
            let entry = registry.test_bed(&spec.id)?;
            let variant = spec.variant.clone().unwrap_or_else(|| entry.variants[0].to_string());
            entry.check_variant(&variant)?;
            if beds
                .iter()
                .any(|b: &PreparedBed| b.spec.id == spec.id && b.variant == variant && b.spec.params == spec.params)
            {
                return Err(ConfigError::invalid("testbeds", format!("{}/{variant}", spec.id), "listed twice").into());
            }
            let bed = (entry.build)(&variant, &spec.params, registry.references())?;
            let params_json = (entry.params.resolve)(entry.id, &spec.params)?.to_string();
            beds.push(PreparedBed { spec: spec.clone(), variant, bed, params_json });
        }
        let mut estimators = Vec::new();
        for spec in &sweep.estimators {
            let entry = registry.estimator(&spec.id)?;
            let estimator = (entry.build)(&spec.params)?;
            let params_json = (entry.params.resolve)(entry.id, &spec.params)?.to_string();
            estimators.push(PreparedEstimator { name: spec.name(), spec: spec.clone(), entry, estimator, params_json });
        }
        let kind = sweep.budgets[0].kind;
        let (mut pairs, mut skipped) = (Vec::new(), Vec::new());
        for (bi, b) in beds.iter().enumerate() {
            for (ei, e) in estimators.iter().enumerate() {
                let reason = e
                    .entry
                    .skip_reason(b.bed.provides())
                    .or_else(|| e.estimator.supports(b.bed.as_ref()).err())
                    .or_else(|| {
                        (kind == BudgetKind::Fetches && !b.bed.provides().contains(Needs::MEDIUM))
                            .then(|| "a fetch budget needs a test bed with a medium".to_string())
                    });
                match reason {
                    None => {
                        // An invalid configuration (not merely an unsupported pair) is bad input.
                        validate(registry.test_bed(&b.spec.id)?, b, e)?;
                        pairs.push((bi, ei))
                    }
                    Some(reason) => skipped.push(Skipped {
                        testbed: b.spec.id.clone(),
                        variant: b.variant.clone(),
                        estimator: e.name.clone(),
                        reason,
                    }),
                }
            }
        }
        // A sweep in which nothing can run would only overwrite earlier results with empty files.
        if pairs.is_empty() {
            let why = skipped
                .first()
                .map(|s| format!(" (e.g. {} on {}/{}: {})", s.estimator, s.testbed, s.variant, s.reason));
            return Err(ConfigError::invalid(
                "estimators",
                &sweep.experiment,
                format!("no estimator of the sweep can run on any of its test beds{}", why.unwrap_or_default()),
            )
            .into());
        }
        if let Some(b) = &sweep.baseline {
            let runs = pairs.iter().any(|&(_, ei)| &estimators[ei].name == b);
            if !runs {
                let why = skipped.iter().find(|s| &s.estimator == b).map(|s| s.reason.clone()).unwrap_or_default();
                return Err(
                    ConfigError::invalid("baseline", b, format!("runs on no test bed of the sweep: {why}")).into()
                );
            }
        }
        Ok(Plan { sweep, beds, estimators, pairs, skipped })
    }

    /// Checks every claim of the sweep against what the plan runs
    /// ([`crate::config::claim_spec::ClaimSpec::check_against`]).
    pub(crate) fn check_claims(&self) -> Result<()> {
        let ran = crate::analysis::claim_check::Ran {
            beds: self.beds.iter().map(PreparedBed::label).collect(),
            estimators: self.estimators.iter().map(|e| e.name.as_str()).collect(),
            pairs: &self.pairs,
            skipped: &self.skipped,
            budgets: self.sweep.budgets.iter().map(|b| b.amount).collect(),
            baseline: self.sweep.baseline.as_deref(),
        };
        for (i, c) in self.sweep.claims.iter().enumerate() {
            c.check_against(&ran).map_err(|e| crate::analysis::claim_check::config_error(i, c, e))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Mode, SweepFile};

    fn sweep(estimators: &str) -> Sweep {
        let text = format!(
            "name='v'\nreps=2\nbudgets=[4]\n[[testbeds]]\nid='eq21-medium'\nvariant='single-scatter'\nparams={{resolution=2}}\n{estimators}"
        );
        toml::from_str::<SweepFile>(&text).unwrap().apply(None, Mode::Quick).unwrap()
    }

    /// A pair's validation is remembered per configuration: an invalid one is refused every time
    /// it is planned, with the same error, and another configuration of the same estimator is
    /// judged on its own.
    #[test]
    fn validation_is_remembered_per_configuration() {
        let registry = Registry::new().with_catalog(mcbench_papers::catalog());
        let bad = sweep("[[estimators]]\nid='delta_tracking'\nparams={sigma_samp=0.01}\n");
        let first = Plan::prepare(bad.clone(), &registry).err().expect("no majorant").to_string();
        assert!(first.contains("majorant"), "{first}");
        let again = Plan::prepare(bad, &registry).err().expect("still refused").to_string();
        assert_eq!(first, again);
        let good = sweep("[[estimators]]\nid='delta_tracking'\n");
        assert_eq!(Plan::prepare(good, &registry).expect("a majorant").pairs.len(), 1);
    }

    /// A parameter that selects a biased reading changes the declaration the tests judge against;
    /// the same estimator with its other parameters keeps its entry's.
    #[test]
    fn a_configured_estimator_may_declare_its_own_bias() {
        use mcbench_core::estimator::Bias;
        let registry = Registry::new().with_catalog(mcbench_papers::catalog());
        let text = "name='v'\nreps=2\nbudgets=[10]\n[[testbeds]]\nid='checker-image'\nparams={resolution=48}\n\
                    [[estimators]]\nid='pmc_ip'\n[[estimators]]\nid='pmc_ip'\nparams={combine='pooled'}\n";
        let sweep = toml::from_str::<SweepFile>(text).unwrap().apply(None, Mode::Quick).unwrap();
        let plan = Plan::prepare(sweep, &registry).expect("plan");
        let declared: Vec<(String, Bias)> = plan.estimators.iter().map(|e| (e.name.clone(), e.bias())).collect();
        assert_eq!(
            declared,
            vec![("pmc_ip".to_string(), Bias::Unbiased), ("pmc_ip[combine=pooled]".to_string(), Bias::Biased)]
        );
        assert!(plan.estimators.iter().all(|e| e.entry.bias == Bias::Unbiased), "the entry is unchanged");
    }
}

//! Sweeps and the config files that describe or override them (a TOML or JSON config file
//! describes a custom sweep; book: config.md).
//!
//! ```toml
//! name = "my-sweep"            # required when no experiment is named on the command line
//! seed = 7
//! reps = 8
//! budget_kind = "samples"      # samples | fetches | micros
//! budgets = [4, 16, 64, 256]
//! baseline = "is0_cv0"         # speed-ups are computed against it
//! [[testbeds]]
//! id = "gradient-plane"
//! variant = "glossy"
//! params = { resolution = 16 }
//! [[estimators]]
//! id = "clamped_is0_cv0"
//! params = { clamp = 4.0 }
//! ```

pub mod claim_spec;
pub mod declare;
pub mod limits;
mod repetitions;

use crate::config::claim_spec::ClaimSpec;
use crate::error::{HarnessError, Result};
pub use crate::plan::cost_model::CostModel;
use mcbench_core::budget::{Budget, BudgetKind};
use mcbench_core::error::ConfigError;
use mcbench_core::params::{ParamValue, Params};
pub use repetitions::Repetitions;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One test bed of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TestBedSpec {
    /// Registered id.
    pub id: String,
    /// Variant (the test bed's first variant when omitted).
    #[serde(default)]
    pub variant: Option<String>,
    /// Test-bed parameters.
    #[serde(default)]
    pub params: Params,
}

/// One estimator of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EstimatorSpec {
    /// Registered id.
    pub id: String,
    /// Estimator parameters.
    #[serde(default)]
    pub params: Params,
}

impl EstimatorSpec {
    /// An estimator with default parameters.
    pub fn new(id: &str) -> Self {
        EstimatorSpec { id: id.to_string(), params: Params::new() }
    }
    /// The name in result files: the id, followed by `[k=v,...]` when parameters are set.
    pub fn name(&self) -> String {
        if self.params.0.is_empty() {
            return self.id.clone();
        }
        let kv: Vec<String> = self
            .params
            .0
            .iter()
            .map(|(k, v)| match v {
                ParamValue::Number(x) => format!("{k}={}", compact_number(*x)),
                ParamValue::Text(t) => format!("{k}={t}"),
            })
            .collect();
        format!("{}[{}]", self.id, kv.join(","))
    }
}

/// A number as it appears in names: plain decimal (`0.4`, `1`, `20000`) where that is short, and
/// exponent form (`1e200`, `1e-9`) where plain decimal would run to dozens of digits.
pub fn compact_number(x: f64) -> String {
    let plain = format!("{x}");
    if plain.len() <= 24 {
        plain
    } else {
        format!("{x:e}")
    }
}

/// Quick (CI-sized) or full (the papers' sizes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Small sizes: every experiment in about a minute.
    Quick,
    /// The papers' sizes.
    Full,
}

impl Mode {
    /// Name written in `meta.mode`.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Quick => "quick",
            Mode::Full => "full",
        }
    }
}

/// A fully specified sweep: test beds x estimators x budgets x repetitions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sweep {
    /// Experiment name (the results folder).
    pub experiment: String,
    /// Test beds.
    pub testbeds: Vec<TestBedSpec>,
    /// Estimators.
    pub estimators: Vec<EstimatorSpec>,
    /// Budgets, increasing.
    pub budgets: Vec<Budget>,
    /// Repetitions per integral.
    pub reps: usize,
    /// Experiment seed.
    pub seed: u64,
    /// Quick or full.
    pub mode: Mode,
    /// Estimator name the speed-ups are computed against.
    pub baseline: Option<String>,
    /// Claims judged on the finished run ([`ClaimSpec`]).
    #[serde(default)]
    pub claims: Vec<ClaimSpec>,
    /// The relative bias an unbiasedness `pass` must be able to detect with 80% power (default
    /// [`crate::analysis::DEFAULT_TOLERANCE`], 1%).
    #[serde(default)]
    pub bias_tolerance: Option<f64>,
    /// Unit costs of the `renderer` cost regime ([`CostModel`]; its defaults unless set).
    #[serde(default)]
    pub cost_model: CostModel,
    /// How the `unbiasedness` experiment spends its repetitions ([`Repetitions`]); absent
    /// (fixed) in files written before it existed and in every fixed sweep.
    #[serde(default, skip_serializing_if = "Repetitions::is_fixed")]
    pub repetitions: Repetitions,
}

impl Sweep {
    /// The unbiasedness tolerance of this sweep.
    pub fn tolerance(&self) -> f64 {
        self.bias_tolerance.unwrap_or(crate::analysis::DEFAULT_TOLERANCE)
    }
}

/// `4^k` for `k` in `ks`: the papers' spp sweep.
pub fn powers_of_four(ks: std::ops::RangeInclusive<u32>) -> Vec<Budget> {
    ks.map(|k| Budget { kind: BudgetKind::Samples, amount: 4u64.pow(k) }).collect()
}

/// A TOML error as one line: the message, the line and column where it starts, and that line's
/// text (which holds the key, so the field is named even for a syntax error).
pub(crate) fn toml_reason(text: &str, e: &toml::de::Error) -> String {
    let msg = e.message().lines().next().unwrap_or("malformed").to_string();
    let Some(span) = e.span() else { return msg };
    let start = span.start.min(text.len());
    let before = text.get(..start).unwrap_or("");
    let line = before.matches('\n').count() + 1;
    let column = before.chars().rev().take_while(|&c| c != '\n').count() + 1;
    let source: String = text.lines().nth(line - 1).unwrap_or("").trim().chars().take(60).collect();
    format!("line {line}, column {column}: {msg} (in `{source}`)")
}

/// The optional fields of a config file; present fields override the named experiment's sweep.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// Experiment name (required for a custom sweep).
    pub name: Option<String>,
    /// Seed.
    pub seed: Option<u64>,
    /// Repetitions.
    pub reps: Option<usize>,
    /// Budget kind of `budgets`.
    pub budget_kind: Option<String>,
    /// Budgets.
    pub budgets: Option<Vec<u64>>,
    /// Baseline estimator name for speed-ups.
    pub baseline: Option<String>,
    /// Test beds.
    pub testbeds: Option<Vec<TestBedSpec>>,
    /// Estimators.
    pub estimators: Option<Vec<EstimatorSpec>>,
    /// Claims judged on the finished run (`[[claims]]` tables, [`ClaimSpec`]).
    pub claims: Option<Vec<ClaimSpec>>,
    /// The relative bias an unbiasedness `pass` must be able to detect (default 0.01).
    pub bias_tolerance: Option<f64>,
    /// Unit costs of the `renderer` cost regime (a `[cost_model]` table; unset fields keep their
    /// defaults).
    pub cost_model: Option<CostModel>,
}

impl SweepFile {
    /// Reads a `.toml` or `.json` file; any problem is a one-line error naming the file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| HarnessError::bad_file(path, e))?;
        let parsed = match path.extension().and_then(|e| e.to_str()) {
            Some("json") => serde_json::from_str(&text).map_err(|e| e.to_string()),
            Some("toml") => toml::from_str(&text).map_err(|e| toml_reason(&text, &e)),
            _ => Err("config files must end in .toml or .json".to_string()),
        };
        parsed.map_err(|reason| HarnessError::bad_file(path, reason.lines().next().unwrap_or("malformed").to_string()))
    }

    /// Applies the file to `base` (a named experiment's sweep) or builds a custom sweep.
    pub fn apply(self, base: Option<Sweep>, mode: Mode) -> Result<Sweep> {
        let mut sweep = match base {
            Some(s) => s,
            None => Sweep {
                experiment: self
                    .name
                    .clone()
                    .ok_or_else(|| ConfigError::invalid("name", "(missing)", "a custom sweep needs a name"))?,
                testbeds: Vec::new(),
                estimators: Vec::new(),
                budgets: Vec::new(),
                reps: 8,
                seed: 1,
                mode,
                baseline: None,
                claims: Vec::new(),
                bias_tolerance: None,
                cost_model: CostModel::default(),
                repetitions: Default::default(),
            },
        };
        if let Some(name) = self.name {
            sweep.experiment = name;
        }
        if let Some(seed) = self.seed {
            sweep.seed = seed;
        }
        if let Some(reps) = self.reps {
            sweep.reps = reps;
        }
        let kind = match self.budget_kind {
            Some(k) => BudgetKind::parse(&k)?,
            None => sweep.budgets.first().map(|b| b.kind).unwrap_or(BudgetKind::Samples),
        };
        if let Some(values) = self.budgets {
            sweep.budgets = values.into_iter().map(|v| Budget::new(kind, v)).collect::<Result<_, _>>()?;
        }
        if self.baseline.is_some() {
            sweep.baseline = self.baseline;
        }
        if let Some(t) = self.testbeds {
            sweep.testbeds = t;
        }
        if let Some(e) = self.estimators {
            sweep.estimators = e;
        }
        if let Some(c) = self.claims {
            sweep.claims = c;
        }
        if self.bias_tolerance.is_some() {
            sweep.bias_tolerance = self.bias_tolerance;
        }
        if let Some(m) = self.cost_model {
            sweep.cost_model = m;
        }
        Ok(sweep)
    }
}

impl Sweep {
    /// Checks what can be checked without building anything: the name, every count against
    /// [`crate::config::limits`], duplicate entries, that a `baseline` names one of the estimators, and
    /// each claim on its own ([`ClaimSpec::check`]).
    pub fn validate(&self) -> Result<()> {
        use crate::config::limits::{max_budget, MAX_BUDGETS, MAX_ENTRIES, MAX_REPS};
        let name_ok = !self.experiment.is_empty()
            && self.experiment.len() <= 64
            && self.experiment.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
        if !name_ok {
            return Err(
                ConfigError::invalid("name", &self.experiment, "use 1 to 64 letters, digits, '-' and '_'").into()
            );
        }
        if self.reps < 2 {
            return Err(
                ConfigError::invalid("reps", self.reps, "at least 2 repetitions are needed for variances").into()
            );
        }
        if self.reps > MAX_REPS {
            return Err(ConfigError::invalid("reps", self.reps, format!("at most {MAX_REPS} repetitions")).into());
        }
        if self.budgets.is_empty() || self.testbeds.is_empty() || self.estimators.is_empty() {
            return Err(ConfigError::invalid(
                "sweep",
                &self.experiment,
                "needs at least one test bed, estimator and budget",
            )
            .into());
        }
        if self.budgets.len() > MAX_BUDGETS {
            return Err(
                ConfigError::invalid("budgets", self.budgets.len(), format!("at most {MAX_BUDGETS} budgets")).into()
            );
        }
        if self.testbeds.len() > MAX_ENTRIES || self.estimators.len() > MAX_ENTRIES {
            let (field, n) = if self.testbeds.len() > MAX_ENTRIES {
                ("testbeds", self.testbeds.len())
            } else {
                ("estimators", self.estimators.len())
            };
            return Err(ConfigError::invalid(field, n, format!("at most {MAX_ENTRIES} entries")).into());
        }
        if let Some(b) = self.budgets.iter().find(|b| b.amount == 0) {
            return Err(ConfigError::invalid("budgets", b.amount, "budgets must be >= 1").into());
        }
        if let Some(b) = self.budgets.iter().find(|b| b.amount > max_budget(b.kind)) {
            return Err(ConfigError::invalid(
                "budgets",
                b.amount,
                format!("a {} budget is at most {} per estimate", b.kind.name(), max_budget(b.kind)),
            )
            .into());
        }
        if self.budgets.windows(2).any(|w| w[0].amount >= w[1].amount || w[0].kind != w[1].kind) {
            return Err(ConfigError::invalid(
                "budgets",
                format!("{:?}", self.budgets.iter().map(|b| b.amount).collect::<Vec<_>>()),
                "must be increasing and of one kind",
            )
            .into());
        }
        for (i, t) in self.testbeds.iter().enumerate() {
            if self.testbeds[..i].contains(t) {
                let v = t.variant.as_deref().unwrap_or("(default)");
                return Err(ConfigError::invalid("testbeds", format!("{}/{v}", t.id), "listed twice").into());
            }
        }
        let names: Vec<String> = self.estimators.iter().map(EstimatorSpec::name).collect();
        for (i, n) in names.iter().enumerate() {
            if names[..i].contains(n) {
                return Err(ConfigError::invalid("estimators", n, "listed twice").into());
            }
        }
        self.cost_model.validate()?;
        if let Some(t) = self.bias_tolerance {
            if !(t > 0.0 && t < 1.0) {
                return Err(ConfigError::invalid("bias_tolerance", t, "must lie in (0, 1): a relative bias").into());
            }
        }
        if let Some(b) = &self.baseline {
            if !names.contains(b) {
                return Err(ConfigError::invalid(
                    "baseline",
                    b,
                    format!("names no estimator of the sweep (valid: {})", names.join(", ")),
                )
                .into());
            }
        }
        for (i, c) in self.claims.iter().enumerate() {
            c.check().map_err(|e| crate::analysis::claim_check::config_error(i, c, e))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_names_include_parameters() {
        let mut e = EstimatorSpec::new("clamped_is0_cv0");
        assert_eq!(e.name(), "clamped_is0_cv0");
        e.params = Params::new().with("clamp", 4.0);
        assert_eq!(e.name(), "clamped_is0_cv0[clamp=4]");
    }

    #[test]
    fn custom_sweep_from_toml_and_validation() {
        let f: SweepFile = toml::from_str(
            "name='x'\nreps=4\nbudgets=[4,16]\n[[testbeds]]\nid='gradient-plane'\n[[estimators]]\nid='is0_cv0'\n",
        )
        .unwrap();
        let s = f.apply(None, Mode::Quick).unwrap();
        assert!(s.validate().is_ok());
        assert_eq!(s.budgets.len(), 2);
        let bad: SweepFile =
            toml::from_str("name='x'\nreps=1\nbudgets=[4]\n[[testbeds]]\nid='a'\n[[estimators]]\nid='b'\n").unwrap();
        assert!(bad.apply(None, Mode::Quick).unwrap().validate().unwrap_err().to_string().contains("reps"));
        assert!(toml::from_str::<SweepFile>("rep = 3").is_err());
    }
}

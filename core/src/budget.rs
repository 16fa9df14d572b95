//! Budgets: samples per integral (the papers' spp), medium fetches, or wall time.

use crate::error::ConfigError;
use serde::{Deserialize, Serialize};

/// The kind of a budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BudgetKind {
    /// Integrand samples per integral.
    Samples,
    /// Medium fetches per integral.
    Fetches,
    /// Single-thread microseconds per integral.
    Micros,
}

impl BudgetKind {
    /// The name used in result files (`budget_kind` column).
    pub fn name(self) -> &'static str {
        match self {
            BudgetKind::Samples => "samples",
            BudgetKind::Fetches => "fetches",
            BudgetKind::Micros => "micros",
        }
    }
    /// Parses a name as written by [`BudgetKind::name`].
    pub fn parse(s: &str) -> Result<Self, ConfigError> {
        match s {
            "samples" => Ok(BudgetKind::Samples),
            "fetches" => Ok(BudgetKind::Fetches),
            "micros" => Ok(BudgetKind::Micros),
            _ => Err(ConfigError::unknown("budget kind", s, ["samples", "fetches", "micros"])),
        }
    }
}

/// How much one estimate of one integral may spend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Budget {
    /// What is counted.
    pub kind: BudgetKind,
    /// How many (samples, fetches or microseconds); always >= 1.
    pub amount: u64,
}

impl Budget {
    /// A validated budget: `amount` must be at least 1.
    pub fn new(kind: BudgetKind, amount: u64) -> Result<Self, ConfigError> {
        if amount == 0 {
            return Err(ConfigError::invalid("budget", amount, "budgets must be >= 1"));
        }
        Ok(Budget { kind, amount })
    }
    /// A sample budget (the papers' spp), `n >= 1`.
    pub fn samples(n: u64) -> Result<Self, ConfigError> {
        Self::new(BudgetKind::Samples, n)
    }
}

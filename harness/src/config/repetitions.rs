//! How the `unbiasedness` experiment spends its repetitions (`--repetitions`, `--rounds-budget`;
//! book: unbiasedness.md), as a sweep carries it. Its JSON is the sweep's (a shard's manifest
//! digests it): a fixed sweep and a whole budget write nothing new, so those digests stay as they
//! were.

use serde::{Deserialize, Serialize};

/// How the `unbiasedness` experiment spends its repetitions (`--repetitions`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Repetitions {
    /// Every row runs its part's repetitions.
    #[default]
    Fixed,
    /// Rows run in rounds of doubling repetitions until decided or the budget is spent
    /// ([`crate::unbiasedness::rounds`]); `fixed_reps` is the first part's repetitions in the
    /// fixed mode (what `--reps` set), from which every part's first round and the budget follow.
    Rounds {
        /// The first part's fixed-mode repetitions.
        fixed_reps: usize,
        /// The share of the fixed mode's work the rounds may spend (`--rounds-budget`, in
        /// `(0, 1]`); 1, the whole of it, when absent, and not written when 1.
        #[serde(default = "whole_share", skip_serializing_if = "is_whole_share")]
        budget_share: f64,
    },
}

/// The budget share of a sweep that does not name one: the whole of the fixed mode's work.
fn whole_share() -> f64 {
    1.0
}

/// Whether `share` is the whole of the fixed mode's work (then it is not written).
fn is_whole_share(share: &f64) -> bool {
    *share == 1.0
}

impl Repetitions {
    /// Whether this is the fixed mode.
    pub fn is_fixed(&self) -> bool {
        *self == Repetitions::Fixed
    }
    /// `fixed` or `rounds`.
    pub fn name(&self) -> &'static str {
        match self {
            Repetitions::Fixed => "fixed",
            Repetitions::Rounds { .. } => "rounds",
        }
    }
    /// The share of the fixed mode's work the rounds may spend: 1 in the fixed mode.
    pub fn budget_share(&self) -> f64 {
        match self {
            Repetitions::Fixed => whole_share(),
            Repetitions::Rounds { budget_share, .. } => *budget_share,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_share_is_not_written_and_an_absent_one_reads_as_whole() {
        let whole = Repetitions::Rounds { fixed_reps: 512, budget_share: 1.0 };
        assert_eq!(serde_json::to_string(&whole).unwrap(), r#"{"rounds":{"fixed_reps":512}}"#);
        let read: Repetitions = serde_json::from_str(r#"{"rounds":{"fixed_reps":512}}"#).unwrap();
        assert_eq!(read, whole);
        assert_eq!(read.budget_share(), 1.0);
        let part = Repetitions::Rounds { fixed_reps: 512, budget_share: 0.3 };
        let text = serde_json::to_string(&part).unwrap();
        assert_eq!(text, r#"{"rounds":{"fixed_reps":512,"budget_share":0.3}}"#);
        assert_eq!(serde_json::from_str::<Repetitions>(&text).unwrap(), part);
        assert_eq!(serde_json::to_string(&Repetitions::Fixed).unwrap(), r#""fixed""#);
        assert_eq!(Repetitions::Fixed.budget_share(), 1.0);
    }
}

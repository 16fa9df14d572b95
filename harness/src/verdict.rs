//! The verdict of a paper claim ([`crate::output::Claim`]), written in the result files as one of
//! the words `held`, `not held`, `inconclusive`, `reported` and `not measured`.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// How a claim came out here.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Verdict {
    /// The claim held (`held`).
    #[serde(rename = "held")]
    Held,
    /// The claim did not hold (`not held`).
    #[serde(rename = "not held")]
    NotHeld,
    /// The interval or test does not decide (`inconclusive`).
    #[serde(rename = "inconclusive")]
    Inconclusive,
    /// A measurement shown beside the paper's number, with no verdict (`reported`).
    #[serde(rename = "reported")]
    Reported,
    /// Not measured in this run (`not measured`).
    #[serde(rename = "not measured")]
    NotMeasured,
}

/// A word that is not a claim verdict.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error("unknown claim verdict `{0}` (expected held, not held, inconclusive, reported or not measured)")]
pub struct UnknownVerdict(pub String);

impl Verdict {
    /// Every verdict, in the order reports count them.
    pub const ALL: [Verdict; 5] =
        [Verdict::Held, Verdict::NotHeld, Verdict::Inconclusive, Verdict::Reported, Verdict::NotMeasured];

    /// The word the result files use.
    pub const fn as_str(self) -> &'static str {
        match self {
            Verdict::Held => "held",
            Verdict::NotHeld => "not held",
            Verdict::Inconclusive => "inconclusive",
            Verdict::Reported => "reported",
            Verdict::NotMeasured => "not measured",
        }
    }

    /// The verdict as the claim's `held` field: `Some(true)` held, `Some(false)` not held, `None`
    /// otherwise.
    pub const fn held(self) -> Option<bool> {
        match self {
            Verdict::Held => Some(true),
            Verdict::NotHeld => Some(false),
            _ => None,
        }
    }

    /// Whether a reader should look at it: not held or inconclusive.
    pub const fn needs_attention(self) -> bool {
        matches!(self, Verdict::NotHeld | Verdict::Inconclusive)
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for Verdict {
    type Err = UnknownVerdict;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Verdict::ALL.into_iter().find(|v| v.as_str() == s).ok_or_else(|| UnknownVerdict(s.to_string()))
    }
}

/// Serde for `Claim.verdict`: `None` is the empty word, as in files written before claims carried
/// a verdict of their own; any other word must be a verdict.
pub(crate) mod word {
    use super::Verdict;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &Option<Verdict>, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(v.map_or("", Verdict::as_str))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Verdict>, D::Error> {
        let word = String::deserialize(d)?;
        if word.is_empty() {
            return Ok(None);
        }
        word.parse().map(Some).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_verdict_round_trips_through_its_word() {
        let words = ["held", "not held", "inconclusive", "reported", "not measured"];
        for (v, w) in Verdict::ALL.into_iter().zip(words) {
            assert_eq!(serde_json::to_string(&v).expect("serialises"), format!("\"{w}\""));
            assert_eq!(serde_json::from_str::<Verdict>(&format!("\"{w}\"")).expect("reads"), v);
            assert_eq!((v.as_str(), v.to_string(), w.parse::<Verdict>()), (w, w.to_string(), Ok(v)));
        }
    }

    #[test]
    fn an_unknown_word_is_refused_by_name() {
        let e = "untested".parse::<Verdict>().expect_err("not a verdict");
        assert_eq!(
            e.to_string(),
            "unknown claim verdict `untested` (expected held, not held, inconclusive, reported or not measured)"
        );
        let e = serde_json::from_str::<Verdict>("\"Held\"").expect_err("case matters");
        assert!(e.to_string().contains("unknown variant `Held`"), "{e}");
    }

    #[test]
    fn a_claim_reads_its_verdict_word_back_and_refuses_another() {
        use crate::output::Claim;
        let claim = Claim { held: Some(true), verdict: Some(Verdict::NotMeasured), ..Default::default() };
        let text = serde_json::to_string(&claim).expect("serialises");
        assert!(text.contains("\"verdict\":\"not measured\""), "{text}");
        assert_eq!(serde_json::from_str::<Claim>(&text).expect("reads back"), claim);
        let unset = Claim { held: Some(false), ..Default::default() };
        let text = serde_json::to_string(&unset).expect("serialises");
        assert!(text.contains("\"verdict\":\"\""), "{text}");
        let back: Claim = serde_json::from_str(&text).expect("reads back");
        assert_eq!((back.verdict, back.verdict()), (None, Verdict::NotHeld));
        let old = text.replace(",\"verdict\":\"\"", "");
        assert_ne!(old, text);
        assert_eq!(serde_json::from_str::<Claim>(&old).expect("reads a file written before it").verdict, None);
        let odd = text.replace("\"verdict\":\"\"", "\"verdict\":\"untested\"");
        let e = serde_json::from_str::<Claim>(&odd).expect_err("not a verdict");
        assert!(e.to_string().starts_with("unknown claim verdict `untested` (expected held,"), "{e}");
    }

    #[test]
    fn held_follows_the_verdict() {
        let held: Vec<Option<bool>> = Verdict::ALL.into_iter().map(Verdict::held).collect();
        assert_eq!(held, [Some(true), Some(false), None, None, None]);
    }
}

//! The words a run's pages use for what it judges: a run of your own plug-ins speaks of "claims",
//! and of "paper claims" only when one of its claims names a paper (`paper 001 Fig. 4: ...`).

use crate::output::Claim;

/// Whether a claim's text names a paper: the word `paper` followed by a number (`paper 003`).
pub fn names_a_paper(text: &str) -> bool {
    let lower = text.to_ascii_lowercase();
    lower.match_indices("paper ").any(|(i, m)| lower[i + m.len()..].starts_with(|c: char| c.is_ascii_digit()))
}

/// The heading of a run's claims: `Paper claims` when one names a paper, else `Claims`.
pub fn claims_heading(claims: &[Claim]) -> &'static str {
    if claims.iter().any(|c| names_a_paper(&c.claim)) {
        "Paper claims"
    } else {
        "Claims"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_claim_that_names_a_paper_makes_them_paper_claims() {
        assert!(names_a_paper("paper 001 Fig. 4: independent MC converges with slope -0.5"));
        assert!(names_a_paper("as in Paper 3, x"));
        assert!(!names_a_paper("papers: every estimator they call unbiased passes"));
        assert!(!names_a_paper("my estimator is twice as efficient"));
        let claim = |t: &str| Claim { claim: t.into(), ..Default::default() };
        assert_eq!(claims_heading(&[claim("mine converges at -1/2")]), "Claims");
        assert_eq!(claims_heading(&[claim("mine"), claim("paper 002 §4.1: adaptive")]), "Paper claims");
        assert_eq!(claims_heading(&[]), "Claims");
    }
}

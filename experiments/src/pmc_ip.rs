//! `pmc-ip` (paper 003 Table 1, Fig. 4): `checker-image` (default, and `occluded` with soft
//! shadows as in the paper's Buddha) at equal sample counts: uniform image-plane sampling at 10,
//! 16 and 32 spp against PMC-IP 2+4+4 (`pmc_ip` at 10 spp) and 4+6+6 (`pmc_ip[initial=4]` at
//! 16 spp), with the perceptual error `Err` and `P-Eff` (book: outputs.md) beside our plain efficiency,
//! and the threshold-stopping control of paper 003 §2 that the unbiasedness test must flag.

use crate::{pmc_ip_post, ExperimentDef};
use mcbench::analysis::metrics::SummaryRow;
use mcbench::output::query::Query;
use mcbench::output::{Claim, RunReport};

/// The name of PMC-IP 4+6+6 (the initial image takes 4 spp).
pub const PMC_IP_4: &str = "pmc_ip[initial=4]";

/// Definition.
pub static DEF: ExperimentDef =
    ExperimentDef { toml: include_str!("pmc_ip.toml"), claims: Some(claims), post: Some(pmc_ip_post::post) };

/// The image side the stored `checker-image` references are made for.
pub const RESOLUTION: f64 = 48.0;

/// The row of an estimator at a budget on a variant.
pub fn row<'a>(r: &'a RunReport, variant: &str, estimator: &str, budget: u64) -> Option<&'a SummaryRow> {
    r.query().variant(variant).estimator(estimator).at(budget).first()
}

/// "PMC-IP is unbiased" (paper 003 §4.2): held when the per-pixel Holm-Welch test against the
/// stored reference passes at the largest budget. The note sets it beside the pooled z-test and
/// beside both tests of `uniform_image`, which is unbiased by construction: on this test bed the
/// pixel samples of the sharp glossy squares are heavy-tailed, and a test that flags the uniform
/// sampler too says more about the repetitions than about the estimator.
fn unbiased_claim(r: &RunReport, variant: &str, estimator: &str) -> Claim {
    let test = |e: &str, name: &str| {
        Query::new(&r.tests).variant(variant).estimator(e).iter().find(|t| t.test == name).map(|t| t.p_value)
    };
    let p = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2e}"));
    let decisive = mcbench::analysis::claims::decisive_test(&r.tests, variant, estimator, "");
    let ours = decisive.map(|t| t.p_value);
    Claim {
        testbed: format!("checker-image/{variant}"),
        claim: format!("paper 003 §4.2: PMC-IP ({estimator}) is unbiased (against the stored reference)"),
        paper_value: None,
        our_value: ours,
        held: decisive.and_then(|t| mcbench::analysis::claims::unbiased_verdict(t).0),
        verdict: decisive.map(|t| mcbench::analysis::claims::unbiased_verdict(t).1),
        reason: decisive.map_or(String::new(), |t| t.reason.clone()),
        note: format!(
            "{} (Holm-Welch per pixel and the pooled t-test over repetitions, Bonferroni); smallest Holm-adjusted p {} (pooled t {}); uniform_image on the same bed: Holm-Welch {}, pooled t {}; {} repetitions (see docs/src/paper-003.md: heavy-tailed pixel samples)",
            decisive.map_or("-".to_string(), |t| format!("{}: {}", t.verdict, t.reason)),
            p(test(estimator, "holm_welch")),
            p(test(estimator, "pooled_t")),
            p(test("uniform_image", "holm_welch")),
            p(test("uniform_image", "pooled_t")),
            r.meta.reps
        ),
        ..Default::default()
    }
}

/// The claims that need the unbiasedness tests (the ratio claims are data, in `pmc_ip.toml`).
fn claims(r: &RunReport) -> Vec<Claim> {
    ["occluded", "default"].iter().map(|v| unbiased_claim(r, v, "pmc_ip")).collect()
}

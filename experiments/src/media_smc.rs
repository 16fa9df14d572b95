//! `media-smc` (paper 000 Fig. 3, Table 1, §5; SPEC §7): the gradient-box test bed at albedo
//! 1 / 0.8 / 0.5, the six cache ids (`is0_cv0` = independent path tracer, the papers' "MCMC") and
//! the biased ray-marching control `rm_is1_cv2`, spp = 4^k. The structure report of Table 1
//! (criterion, depth, nodes, leaves, cells, bytes) comes from the estimators' diagnostics and is
//! written to `structure.csv` and the `paper` block by the post hook.

use crate::ExperimentDef;
use mcbench::claims;
use mcbench::output::{Claim, RunReport};

/// Every id the experiment runs.
pub const IDS: &[&str] = &["is0_cv0", "is0_cv1", "is0_cv2", "is1_cv0", "is1_cv1", "is1_cv2", "rm_is1_cv2"];

/// The albedo variants (paper 000 Fig. 3, left to right).
pub const VARIANTS: &[&str] = &["albedo-1", "albedo-0.8", "albedo-0.5"];

/// Definition.
pub static DEF: ExperimentDef = ExperimentDef {
    toml: include_str!("media_smc.toml"),
    claims: Some(claims),
    post: Some(crate::media_smc_post::post),
};

fn claims(r: &RunReport) -> Vec<Claim> {
    let mut out = Vec::new();
    for v in VARIANTS {
        let tb = ("gradient-box", *v);
        out.push(claims::slope_matches(
            r,
            tb,
            "is0_cv0",
            -0.5,
            "paper 000 §5: independent MC (is0_cv0) converges with slope -0.5",
        ));
        out.push(claims::slope_steeper(
            r,
            tb,
            "is1_cv2",
            -0.625,
            "paper 000 §5: SMC (is1_cv2) converges faster than -0.5",
        ));
        out.push(claims::slope_matches(r, tb, "is1_cv2", -0.625, "paper 000 §5: SMC slopes between 0.62 and 0.63"));
    }
    out.extend(claims::speedup_claims(
        r,
        ("gradient-box", "albedo-0.8"),
        ("is1_cv2", Some("is0_cv0")),
        15.3,
        "paper 000 §5: at albedo 0.8 is1_cv2 is 15.3x faster than independent MC (24x fewer samples, 1.57x overhead)",
    ));
    out.push(claims::control_flagged(r, "rm_is1_cv2"));
    out
}

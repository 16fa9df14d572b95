//! `envmap-smc` (paper 004 Fig. 2-5, §7; book: experiments.md): the `envmap-sequence` test bed, N = 16
//! particles per pixel and frame.
//!
//! (a) Fig. 2-3: RMSE of `L_ns` (variant `mixed-lns`) against P for a single distribution with P MH
//!     moves (`smc[moves=P]`) and P intermediate distributions with the ratio (`smc_bridge`) or
//!     path sampling (`smc_path`);
//! (b) Fig. 4-5: RMSE of `L_r` per frame for `specular` and `mixed`, SMC (`smc_path[bridges=5]`,
//!     as in the paper) against `bidirectional_is` at equal time (its M sweep interpolated in
//!     log-log at SMC's time per estimate);
//! (c) §7: the share of pixels resampled per frame (paper: 36% with one distribution and 5 moves,
//!     18% with 5 bridges).
//!
//! Plus `smc_adaptive` (beyond the paper) and the biased control `bidirectional_is_sn` at 5
//! candidates, whose flagging is claimed by the dedicated unbiasedness check
//! ([`crate::envmap_unbiasedness`]). The per-frame analysis, plots and the claims that need cells
//! are in [`crate::envmap_smc_post`].

use crate::{envmap_smc_post, ExperimentDef};
use mcbench::config::Mode;
use mcbench::output::{Claim, RunReport};

/// Particles per pixel and frame (the paper's N).
pub const N: u64 = 16;

/// Definition.
pub static DEF: ExperimentDef =
    ExperimentDef { toml: include_str!("envmap_smc.toml"), claims: Some(claims), post: Some(envmap_smc_post::post) };

/// The P values of the moves / bridges sweep (a) for a mode.
pub fn p_values(mode: Mode) -> &'static [u32] {
    match mode {
        Mode::Quick => &[1, 2, 5, 10],
        Mode::Full => &[1, 2, 3, 5, 7, 10, 15, 20],
    }
}

/// The candidate counts M of `bidirectional_is` (the equal-time curve of (b)).
pub fn m_values(mode: Mode) -> &'static [u32] {
    match mode {
        Mode::Quick => &[32, 64, 128, 256, 512],
        Mode::Full => &[32, 64, 128, 200, 256, 512, 800, 1024],
    }
}

fn verdict(r: &RunReport, variant: &str, estimator: &str, claim: &str, expect_pass: Option<bool>) -> Claim {
    let t = mcbench::analysis::claims::decisive_test(&r.tests, variant, estimator, "");
    match t {
        None => Claim { testbed: format!("envmap-sequence/{variant}"), claim: claim.into(), paper_value: None, our_value: None, held: None, note: format!("{estimator} did not run") , ..Default::default() },
        Some(t) => Claim {
            testbed: format!("envmap-sequence/{variant}"),
            claim: claim.into(),
            paper_value: None,
            our_value: Some(t.p_value),
            // An inconclusive verdict decides neither way.
            held: match (expect_pass, t.verdict.as_str()) {
                (Some(true), "biased") => Some(false),
                (Some(true), "pass") => Some(true),
                (Some(false), v) => Some(v == "biased"),
                _ => None,
            },
            note: format!(
                "main sweep, reported only: {} p = {:.3e} over {} reps ({}), detectable relative bias {:.2e}; a dozen repetitions make t-tests anti-conservative for skewed HDR estimates, the dedicated check below decides",
                t.test, t.p_value, r.meta.reps, t.verdict, t.detectable_rel_bias
            ),
            ..Default::default()
        },
    }
}

fn claims(r: &RunReport) -> Vec<Claim> {
    let mut out = Vec::new();
    for v in ["mixed-lns", "specular", "mixed"] {
        out.push(verdict(
            r,
            v,
            "bidirectional_is[candidates=128]",
            "bidirectional IS (SIR with proper weights) is unbiased",
            None,
        ));
        out.push(verdict(r, v, "smc[moves=5]", "paper 004 §3: the SMC estimate (Eq. 9-10) is unbiased", None));
        out.push(verdict(
            r,
            v,
            "smc_bridge[bridges=5]",
            "paper 004 §4: intermediate distributions with the standard ratio stay unbiased",
            None,
        ));
        out.push(verdict(
            r,
            v,
            "smc_path[bridges=5]",
            "path sampling (Eq. 15-16): theory says exp(estimated log) is only consistent (verdict reported, not required)",
            None,
        ));
    }
    // The control's claim is the dedicated check's (thousands of repetitions on L_r, where the
    // self-normalised estimate is biased: flagged in 100 of 100 calibration seeds); at this sweep's
    // repetitions its bias on a 10x10 image is not resolved, and on L_ns it is unbiased.
    out
}

//! `pmc-hi` (paper 003 Table 2): `checker-direct` (and its `occluded` variant, standing in for the
//! paper's soft-shadowed Plant scene) at equal sample counts, MIS vs PMC-HI (and PMC-HI with
//! feedback), with the perceptual error `Err` and `P-Eff` (book: outputs.md) beside our plain efficiency.
//! Its claims are data, in `pmc_hi.toml`.

use crate::ExperimentDef;

/// Every id the experiment runs.
pub const IDS: &[&str] = &["mis", "pmc_hi", "pmc_hi_feedback", "clamped_is0_cv0"];

/// Definition.
pub static DEF: ExperimentDef =
    ExperimentDef { toml: include_str!("pmc_hi.toml"), claims: None, post: Some(crate::pmc_hi_post::post) };

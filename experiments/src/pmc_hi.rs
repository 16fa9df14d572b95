//! `pmc-hi` (paper 003 Table 2): `checker-direct` (and its `occluded` variant, standing in for the
//! paper's soft-shadowed Plant scene) at equal sample counts, MIS vs PMC-HI (and PMC-HI with
//! feedback), with the perceptual error `Err` and `P-Eff` (book: outputs.md) beside our plain efficiency.
//! Its claims are data, in `pmc_hi.toml`.

use crate::ExperimentDef;

/// Definition.
pub static DEF: ExperimentDef =
    ExperimentDef { toml: include_str!("pmc_hi.toml"), claims: None, post: Some(crate::pmc_hi_post::post) };

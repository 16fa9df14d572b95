//! `media-smc` (paper 000 Fig. 3, Table 1, §5; book: experiments.md): the gradient-box test bed at albedo
//! 1 / 0.8 / 0.5, the six cache ids (`is0_cv0` = independent path tracer, the papers' "MCMC") and
//! the biased ray-marching control `rm_is1_cv2`, spp = 4^k. The structure report of Table 1
//! (criterion, depth, nodes, leaves, cells, bytes) comes from the estimators' diagnostics and is
//! written to `structure.csv` and the `paper` block by the post hook; the other claims are data in
//! `media_smc.toml`.

use crate::ExperimentDef;

/// Definition.
pub static DEF: ExperimentDef =
    ExperimentDef { toml: include_str!("media_smc.toml"), claims: None, post: Some(crate::media_smc_post::post) };

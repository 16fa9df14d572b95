//! `surface-smc` (paper 001 Fig. 4, §5): the gradient-plane test bed, the surface cache ids and
//! the independent-MC baselines, spp = 4^k. Its claims are data, in `surface_smc.toml`.

use crate::ExperimentDef;

/// Definition.
pub static DEF: ExperimentDef = ExperimentDef { toml: include_str!("surface_smc.toml"), claims: None, post: None };

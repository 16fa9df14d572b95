//! `surface-smc` (paper 001 Fig. 4, §5): the gradient-plane test bed, the surface cache ids and
//! the independent-MC baselines, spp = 4^k. Its claims are data, in `surface_smc.toml`.

use crate::ExperimentDef;

/// Every id the experiment runs (those not registered yet are reported as unavailable).
pub const IDS: &[&str] = &[
    "is0_cv0",
    "is0_cv1",
    "is0_cv2",
    "is1_cv0",
    "is1_cv1",
    "is1_cv2",
    "brdf_is0_cv0",
    "brdf_is1_cv2",
    "clamped_is0_cv0",
];

/// Definition.
pub static DEF: ExperimentDef = ExperimentDef { toml: include_str!("surface_smc.toml"), claims: None, post: None };

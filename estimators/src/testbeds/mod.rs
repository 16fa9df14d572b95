//! The test beds (book: testbeds.md), each with its exact or stored reference: `gradient-plane`,
//! `gradient-box`, `envmap-sequence`, `checker-direct`, `checker-image`, `eq21-medium` and
//! `perlin-medium` ([`medium`]), `canonical-1d`; and two generic integrands with closed forms,
//! `product-peak` and `cosine-power` ([`mcbench_core::integrand_bed`]).

pub mod canonical_1d;
pub mod canonical_profiles;
pub mod checker;
pub mod checker_image;
pub mod checker_image_reference;
pub mod checker_reference;
pub mod cosine_power;
pub mod envmap_ess;
pub mod envmap_reference;
pub mod envmap_sequence;
pub mod gradient_box;
pub mod gradient_box_independent;
pub mod gradient_plane;
pub mod medium;
pub mod moving_sky;
pub mod phong_lobe;
pub mod pinhole;
pub mod product_peak;
pub mod sky;

//! The built-in test beds written as other renderers' scenes (`mcbench export`, book:
//! exported-beds.md): `gradient-plane` (`diffuse`) and `gradient-box` (every variant) as Mitsuba 3
//! scenes ([`mitsuba`]), each with a `bed.md` describing the scene for any renderer ([`notes`]).

pub mod mitsuba;
pub mod notes;
pub mod sky;

use mcbench_core::export::SceneExport;

/// `gradient-plane` as a Mitsuba 3 scene.
pub static GRADIENT_PLANE_MITSUBA: SceneExport = SceneExport {
    testbed: "gradient-plane",
    format: "mitsuba",
    variants: &["diffuse"],
    not_exported: "Mitsuba 3 has no modified-Phong BSDF (kd / pi + ks (n + 2) / (2 pi) cos^n of the angle to the \
                   mirror direction); its glossy BSDFs are microfacet models with other integrals",
    write: mitsuba::gradient_plane,
};

/// `gradient-box` as a Mitsuba 3 scene.
pub static GRADIENT_BOX_MITSUBA: SceneExport = SceneExport {
    testbed: "gradient-box",
    format: "mitsuba",
    variants: &["albedo-0.8", "albedo-1", "albedo-0.5", "hg-0.1", "furnace", "albedo-0", "thick"],
    not_exported: "",
    write: mitsuba::gradient_box,
};

/// Every exported scene, for the catalog.
pub static EXPORTS: &[&SceneExport] = &[&GRADIENT_PLANE_MITSUBA, &GRADIENT_BOX_MITSUBA];

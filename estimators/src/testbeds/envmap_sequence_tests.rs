//! Tests of [`super`]: the scene and its exact per-texel reference against brute-force
//! quadrature, parameters, stored references.

use super::*;
use crate::testbeds::envmap_reference::WALL_QUADRATURE_REL_ERROR;
use mcbench_core::quadrature::gauss_legendre;
use std::f64::consts::{PI, TAU};

fn small(variant: &str, extra: Params) -> EnvmapSequence {
    let mut p = extra.with("resolution", 3.0).with("frames", 2.0);
    for (k, v) in [("env_width", 64.0), ("env_height", 32.0)] {
        if !p.0.contains_key(k) {
            p = p.with(k, v);
        }
    }
    EnvmapSequence::new(variant, &p).unwrap()
}

/// Brute force: every texel split into `sub x sub` panels of 8x8 Gauss-Legendre in (theta, phi)
/// with max(0, cos), which converges slowly only on horizon texels; compared at 1e-7
/// relative (the brute force's own accuracy), the reference's claim of 1e-10 is checked by
/// the refinement test below.
fn brute(bed: &EnvmapSequence, i: usize, sub: usize) -> (Rgb, Rgb) {
    let (p, f) = (bed.points[i / bed.frames], i % bed.frames);
    let env = bed.environment(f);
    let g = env.map.grid();
    let (x, w) = gauss_legendre(8);
    let (dt, dp) = (PI / g.height as f64 / sub as f64, TAU / g.width as f64 / sub as f64);
    let (mut lns, mut lr) = (Rgb::ZERO, Rgb::ZERO);
    for a in 0..g.height * sub {
        for b in 0..g.width * sub {
            for (xi, wi) in x.iter().zip(&w) {
                let th = (a as f64 + 0.5 + 0.5 * xi) * dt;
                for (xj, wj) in x.iter().zip(&w) {
                    let ph = (b as f64 + 0.5 + 0.5 * xj) * dp + env.rotation;
                    let d = mcbench_core::samplers::spherical_direction(th.cos(), ph);
                    let cos = d.dot(p.normal);
                    if cos <= 0.0 {
                        continue;
                    }
                    let v =
                        env.radiance(d) * p.brdf.eval(d, p.wo, p.normal) * (cos * th.sin() * wi * wj * 0.25 * dt * dp);
                    lns += v;
                    if bed.visible(i / bed.frames, d) {
                        lr += v;
                    }
                }
            }
        }
    }
    (lns, lr)
}

/// The wall's silhouette is a kink the brute force resolves only to first order (it agrees to
/// about 3e-6 at 8 and at 16 sub-panels per texel side), so `L_r` is checked at the reference's
/// stated 1e-5, while `L_ns` (no wall) matches at 1e-7 as on the other variants.
#[test]
fn wall_reference_matches_refined_brute_force() {
    let bed = small("moving-wall", Params::new());
    let refs = bed.pixel_references();
    for i in [0, 5, 8, 17] {
        for sub in [8, 16] {
            let (lns, lr) = brute(&bed, i, sub);
            for c in 0..3 {
                let scale = refs[i].lns[c].abs().max(1e-3);
                assert!((lns[c] - refs[i].lns[c]).abs() <= 1e-7 * scale, "integral {i} ch {c}: L_ns {}", lns[c]);
                let err = (lr[c] - refs[i].lr[c]).abs() / scale;
                assert!(err <= WALL_QUADRATURE_REL_ERROR, "integral {i} ch {c}, {sub} sub-panels: L_r error {err:.2e}");
            }
        }
    }
    // The wall hides sky that the ground alone leaves visible: L_r below the open scene's.
    let open = small("moving", Params::new()).pixel_references();
    for (w, o) in refs.iter().zip(&open) {
        assert!(w.lr.0.iter().zip(o.lr.0).all(|(a, b)| *a < b), "{w:?} against {o:?}");
        assert_eq!(w.lns, o.lns);
    }
}

/// `moving-specular-wall`: the `specular` BRDF under the `moving` map behind the same wall. Its
/// references match the refined brute force (at 1e-5 for `L_r`, as the wall's kink allows; 1e-7
/// for `L_ns`); its `L_ns` is the `specular` BRDF's under the moving map (the wall hides nothing
/// from `L_ns`), and the wall darkens every pixel against the open scene with the same BRDF.
#[test]
fn specular_wall_variant_has_the_specular_brdf_and_exact_references() {
    let bed = small("moving-specular-wall", Params::new());
    let (specular, wall) = (small("specular", Params::new()), small("moving-wall", Params::new()));
    assert_eq!(bed.points[4].brdf, specular.points[4].brdf);
    assert_ne!(bed.points[4].brdf, wall.points[4].brdf);
    assert_eq!(bed.maps[0].texels(), wall.maps[0].texels());
    assert_eq!(bed.walls, wall.walls);
    assert_eq!(bed.quantity, EnvQuantity::Reflected);
    let refs = bed.pixel_references();
    for i in [0, 8, 17] {
        let (lns, lr) = brute(&bed, i, 8);
        for c in 0..3 {
            let scale = refs[i].lns[c].abs().max(1e-3);
            assert!((lns[c] - refs[i].lns[c]).abs() <= 1e-7 * scale, "integral {i} ch {c}: L_ns {}", lns[c]);
            let err = (lr[c] - refs[i].lr[c]).abs() / scale;
            assert!(err <= WALL_QUADRATURE_REL_ERROR, "integral {i} ch {c}: L_r error {err:.2e}");
        }
    }
    for (v, r) in bed.reference.value.iter().zip(&refs) {
        assert_eq!(*v, r.lr);
    }
    // Open: the moving map with the specular BRDF and no wall (the `moving` scene's geometry).
    let open = small("moving", Params::new());
    let mut open_specular = small("moving", Params::new());
    open_specular.points.iter_mut().for_each(|p| p.brdf = bed.points[0].brdf);
    open_specular.setup = format!("{}|specular-open", open.setup);
    let open_refs = open_specular.pixel_references();
    for (w, o) in refs.iter().zip(&open_refs) {
        assert_eq!(w.lns, o.lns);
        // Within the quadrature's bound: pixels whose lobe points at the ground see about 1e-16.
        assert!(w.lr.0.iter().zip(o.lr.0).all(|(a, b)| *a <= b + w.bound + o.bound), "{w:?} against {o:?}");
    }
    assert!(refs.iter().zip(&open_refs).any(|(w, o)| w.lr.0[1] < 0.9 * o.lr.0[1]), "the wall hides a lobe somewhere");
}

#[test]
fn reference_matches_brute_force_quadrature() {
    // The moving map's bright texels make the brute force's horizon texels converge more slowly:
    // 8x8 sub-panels there (at 4x4 it is off by 3e-7 on integral 5, at 16x16 within 1e-10).
    for (variant, sub) in [("mixed", 4), ("specular", 4), ("moving", 8)] {
        let bed = small(variant, Params::new());
        let refs = bed.pixel_references();
        for i in [0, 5, 8, 17] {
            let (lns, lr) = brute(&bed, i, sub);
            for c in 0..3 {
                for (a, b) in [(lns[c], refs[i].lns[c]), (lr[c], refs[i].lr[c])] {
                    assert!(
                        (a - b).abs() <= 1e-7 * b.abs().max(1e-3),
                        "{variant} integral {i} ch {c}: brute {a} vs reference {b}"
                    );
                }
            }
            assert!(
                refs[i].bound <= 1.01e-7 * refs[i].lns.0.iter().fold(0.0f64, |m, &v| m.max(v)),
                "bound {}",
                refs[i].bound
            );
        }
    }
}

/// The dawn-to-dusk option (book: testbeds.md): frame n shows the sky at time (n + 1/2) / F, the sky
/// scaled by 0.2 + 0.8 sin(pi t) and the sun by sin(pi t)^2; the exact references follow it.
#[test]
fn dawn_to_dusk_scales_the_sky_per_frame_and_references_follow() {
    let p = Params::new()
        .with("resolution", 3.0)
        .with("frames", 3.0)
        .with("env_width", 64.0)
        .with("env_height", 32.0)
        .with("dawn_dusk", 1.0);
    let bed = EnvmapSequence::new("mixed", &p).unwrap();
    // Straight down sees the ground only (no lobe, the sun is above the horizon), which the
    // rotation about z leaves alone: frame 1 (noon, scale 1) over frame 0 (t = 1/6, scale 0.6).
    let down = Vec3::new(0.0, 0.0, -1.0);
    let (dusk, noon) = (bed.environment(0).radiance(down), bed.environment(1).radiance(down));
    for c in 0..3 {
        assert!((noon[c] / dusk[c] - 1.0 / 0.6).abs() < 1e-9, "channel {c}: {} / {}", noon[c], dusk[c]);
    }
    let refs = bed.pixel_references();
    for i in [0, 1, 2, 13] {
        let (lns, lr) = brute(&bed, i, 4);
        for c in 0..3 {
            assert!((lns[c] - refs[i].lns[c]).abs() <= 1e-7 * refs[i].lns[c].abs().max(1e-3), "integral {i}");
            assert!((lr[c] - refs[i].lr[c]).abs() <= 1e-7 * refs[i].lr[c].abs().max(1e-3), "integral {i}");
        }
    }
    // Noon is brighter than the first frame at every pixel (sky 1.67x, sun 4x).
    for px in 0..9 {
        assert!(refs[px * 3 + 1].lns.0[1] > refs[px * 3].lns.0[1], "pixel {px}");
    }
}

/// The sky spans the dynamic range the test bed and the stability cases ask for (1e4, and 1e6 with
/// a brighter sun); references are positive.
#[test]
fn sky_has_the_required_dynamic_range_and_references_are_positive() {
    let bed = small("mixed", Params::new().with("env_width", 256.0).with("env_height", 128.0));
    assert!(bed.maps[0].dynamic_range() >= 1e4, "{}", bed.maps[0].dynamic_range());
    let stiff = small("mixed", Params::new().with("sun", 1e5).with("env_width", 256.0).with("env_height", 128.0));
    assert!(stiff.maps[0].dynamic_range() >= 1e6);
    assert!(bed.reference.value.iter().all(|v| v.0.iter().all(|&c| c > 0.0 && c.is_finite())));
    assert_eq!(bed.integrals(), 9 * 2);
}

/// The `moving` variants: the `mixed` BRDF under their own map, with a dynamic range of at least
/// 1e4, its lobes resolved by the default grid (the key lobe spans a few texels), and the
/// `L_ns` variant's references the `L_ns` of the `L_r` one.
#[test]
fn moving_variants_keep_the_mixed_brdf_under_their_own_map() {
    let full = || Params::new().with("env_width", 256.0).with("env_height", 128.0);
    let (moving, mixed) = (small("moving", full()), small("mixed", full()));
    assert_eq!(moving.points[4].brdf, mixed.points[4].brdf);
    assert_ne!(moving.maps[0].texels(), mixed.maps[0].texels());
    let range = moving.maps[0].dynamic_range();
    assert!((1e4..1e6).contains(&range), "{range}");
    let bright = moving.maps[0].texels().iter().filter(|t| t.mean() > 100.0).count();
    assert!((4..200).contains(&bright), "{bright} texels above 100");
    let lns = small("moving-lns", full());
    assert_eq!(lns.quantity, EnvQuantity::Unoccluded);
    for (a, b) in lns.reference.value.iter().zip(moving.pixel_references()) {
        assert_eq!(*a, b.lns);
    }
    assert!(moving.reference.value.iter().all(|v| v.0.iter().all(|&c| c > 0.0 && c.is_finite())));
}

#[test]
fn bad_parameters_are_refused_naming_the_field() {
    let e = EnvmapSequence::new("shiny", &Params::new()).err().unwrap().to_string();
    assert!(e.contains("envmap-sequence/shiny"), "{e}");
    let e = EnvmapSequence::new("mixed", &Params::new().with("env_height", 31.0)).err().unwrap().to_string();
    assert!(e.contains("env_height"), "{e}");
}

/// A stored reference of the bed's key made by the current method is read instead of computed;
/// one of another method is ignored.
#[test]
fn a_stored_reference_is_read_when_made_by_the_same_method() {
    use mcbench_core::references::{InMemory, StoredReference};
    let bed = small("mixed", Params::new());
    let key = bed.reference_key().expect("a key");
    let mut stored = StoredReference {
        testbed: key.testbed.clone(),
        variant: key.variant.clone(),
        params: key.params.clone(),
        command: key.command(),
        resolution: bed.resolution(),
        reference: bed.reference().clone(),
    };
    stored.reference.value.iter_mut().for_each(|v| *v = *v * 2.0);
    let p = Params::new().with("resolution", 3.0).with("frames", 2.0).with("env_width", 64.0).with("env_height", 32.0);
    let read = EnvmapSequence::with_references("mixed", &p, &InMemory(vec![stored.clone()])).unwrap();
    assert_eq!(read.reference().value, stored.reference.value);
    stored.reference.kind = ReferenceKind::Exact { method: "an older quadrature".into(), bound: 0.0 };
    let fresh = EnvmapSequence::with_references("mixed", &p, &InMemory(vec![stored])).unwrap();
    assert_eq!(fresh.reference(), bed.reference());
    let other = EnvmapSequence::with_references("specular", &p, &InMemory(Vec::new())).unwrap();
    assert_ne!(other.reference_key(), Some(key), "the key names the variant");
}

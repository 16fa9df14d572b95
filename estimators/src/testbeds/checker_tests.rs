//! Tests of the checker scene and its quadrature reference.

use super::*;
use crate::testbeds::checker::CheckerDirect;
use mcbench_core::params::Params;
use mcbench_core::testbed::{HemisphereScene, TestBed};

/// Independent brute force: a uniform grid of `nx x ny` cells per light, 10-point Gauss-Legendre
/// per cell and axis, visibility by the scene's own ray cast at every node.
fn brute(geo: &CheckerGeometry, p: &ShadingPoint, nx: usize, ny: usize) -> f64 {
    let (x, w) = gauss_legendre(10);
    let mut total = 0.0;
    for light in &geo.lights {
        let f = AreaIntegrand { p, light };
        let (hx, hy) = ((light.max[0] - light.min[0]) / nx as f64, (light.max[1] - light.min[1]) / ny as f64);
        for i in 0..nx {
            for j in 0..ny {
                let mut s = 0.0;
                for (xi, wi) in x.iter().zip(&w) {
                    for (xj, wj) in x.iter().zip(&w) {
                        let u = light.min[0] + hx * (i as f64 + 0.5 + 0.5 * xi);
                        let v = light.min[1] + hy * (j as f64 + 0.5 + 0.5 * xj);
                        let dir = (Vec3::new(u, v, light.z) - p.position).normalize();
                        if geo.incident(p.position, dir)[0] > 0.0 {
                            s += wi * wj * f.eval(u, v);
                        }
                    }
                }
                total += s * 0.25 * hx * hy;
            }
        }
    }
    total
}

/// Pixels of a 24 x 24 image: a diffuse one, glossy ones of low and high exponent, the
/// reflections of both lights.
fn probe_pixels(bed: &CheckerDirect) -> Vec<usize> {
    let mut picks = Vec::new();
    let mut best = [(0.0, 0usize); 3];
    for i in 0..bed.integrals() {
        let p = bed.shading(i);
        let v = bed.reference().value[i][0];
        let slot = if p.brdf.ks[0] == 0.0 {
            0
        } else if p.brdf.n < 100.0 {
            1
        } else {
            2
        };
        if v > best[slot].0 {
            best[slot] = (v, i);
        }
    }
    picks.extend(best.iter().map(|b| b.1));
    picks
}

#[test]
fn unoccluded_reference_is_within_its_bound_and_1e_9_relative() {
    let bed = CheckerDirect::new("default", &Params::new().with("resolution", 24.0)).unwrap();
    let geo = bed.geometry();
    let mcbench_core::testbed::ReferenceKind::Exact { bound, .. } = bed.reference().kind.clone() else { panic!() };
    for i in probe_pixels(&bed) {
        let p = bed.shading(i);
        let r = bed.reference().value[i][0];
        let (v, e, evals) = direct_lighting(geo, &p, REL_TOL);
        let b = brute(geo, &p, 256, 128);
        eprintln!(
            "pixel {i} n {} value {r:.12e} brute {b:.12e} |diff| {:.2e} bound {e:.2e} ({evals} evaluations)",
            p.brdf.n,
            (r - b).abs()
        );
        assert_eq!(v, r);
        assert!((r - b).abs() <= e.max(1e-13 * r), "pixel {i}: error {:e} above the bound {e:e}", (r - b).abs());
        assert!(e <= 1e-9 * r && e <= bound, "pixel {i}: bound {e:e} vs value {r:e}");
    }
}

#[test]
fn occluded_reference_splits_exactly_at_shadow_edges() {
    let bed = CheckerDirect::new("occluded", &Params::new().with("resolution", 24.0)).unwrap();
    let free = CheckerDirect::new("default", &Params::new().with("resolution", 24.0)).unwrap();
    let geo = bed.geometry();
    // Pixels in the penumbra: occluded value strictly between 0 and the unoccluded value.
    let mut penumbra: Vec<usize> = (0..bed.integrals())
        .filter(|&i| {
            let (a, b) = (bed.reference().value[i][0], free.reference().value[i][0]);
            a > 0.05 * b && a < 0.95 * b
        })
        .collect();
    assert!(penumbra.len() >= 5, "the occluder casts partial shadows ({} pixels)", penumbra.len());
    penumbra.truncate(4);
    for i in penumbra {
        let p = bed.shading(i);
        let r = bed.reference().value[i][0];
        // The ray-cast brute force converges only at O(h) at the shadow edges.
        let b = brute(geo, &p, 512, 256);
        eprintln!("penumbra pixel {i}: quadrature {r:.9e}, ray-cast brute force {b:.9e}");
        assert!((r - b).abs() <= 2e-3 * r, "pixel {i}: {r} vs {b}");
    }
}

#[test]
fn small_light_never_hides_the_large_one_and_every_pixel_sees_the_floor() {
    let geo = CheckerGeometry::new("default").unwrap();
    let (big, small) = (geo.lights[0], geo.lights[1]);
    for a in 0..=20 {
        for b in 0..=20 {
            let x = Vec3::new(-2.0 + 0.2 * a as f64, -2.0 + 0.2 * b as f64, 0.0);
            for u in 0..=4 {
                for v in 0..=4 {
                    let y = Vec3::new(big.min[0] + 0.5 * u as f64, big.min[1] + 0.25 * v as f64, big.z);
                    assert!(small.hit(x, (y - x).normalize()).is_none());
                }
            }
        }
    }
    let bed = CheckerDirect::new("default", &Params::new().with("resolution", 16.0)).unwrap();
    assert_eq!(bed.integrals(), 256);
    // Some pixels see past the board (zero integrand), most see it.
    let zeros = bed.reference().value.iter().filter(|v| v[0] == 0.0).count();
    assert!(zeros > 0 && zeros < 128, "{zeros}");
}

/// `soft-shadow` (the Plant-like variant): most pixels that see the board see the light partly
/// hidden, and the quadrature behind several leaves agrees with the ray-cast brute force.
#[test]
fn soft_shadow_puts_most_of_the_board_in_penumbra_and_its_reference_splits_exactly() {
    let bed = CheckerDirect::new("soft-shadow", &Params::new().with("resolution", 24.0)).unwrap();
    let geo = bed.geometry();
    assert_eq!(geo.lights.len(), 1);
    let free = CheckerGeometry { occluders: Vec::new(), ..geo.clone() };
    let mut board = 0;
    let mut penumbra = Vec::new();
    let mut behind_several = Vec::new();
    for i in 0..bed.integrals() {
        let p = bed.shading(i);
        assert_eq!(p.brdf.ks[0], 0.0, "every square is diffuse");
        let unoccluded = direct_lighting(&free, &p, REL_TOL).0;
        if unoccluded == 0.0 {
            continue;
        }
        board += 1;
        let ratio = bed.reference().value[i][0] / unoccluded;
        if ratio > 0.02 && ratio < 0.98 {
            penumbra.push(i);
            if shadows(&geo.lights[0], full(&geo.lights[0]), p.position, geo).len() >= 2 {
                behind_several.push(i);
            }
        }
    }
    let share = penumbra.len() as f64 / board as f64;
    eprintln!(
        "soft-shadow: {} of {board} board pixels in penumbra ({share:.2}), {} behind several leaves",
        penumbra.len(),
        behind_several.len()
    );
    assert!(share > 0.6, "penumbra share {share}");
    assert!(behind_several.len() >= 4, "{behind_several:?}");
    for &i in behind_several.iter().step_by(behind_several.len() / 4).take(4) {
        let p = bed.shading(i);
        let r = bed.reference().value[i][0];
        // The ray-cast brute force converges only at O(h) at the shadow edges, so it is held to
        // a share of the unoccluded value (deep in the penumbra the lit area is small).
        let b = brute(geo, &p, 384, 384);
        let unoccluded = direct_lighting(&free, &p, REL_TOL).0;
        eprintln!(
            "soft-shadow pixel {i}: quadrature {r:.9e}, ray-cast brute force {b:.9e}, unoccluded {unoccluded:.6e}"
        );
        assert!((r - b).abs() <= 1e-3 * unoccluded, "pixel {i}: {r} vs {b}");
    }
}

fn full(light: &RectLight) -> Rect {
    Rect { x0: light.min[0], x1: light.max[0], y0: light.min[1], y1: light.max[1] }
}

/// The rectangles [`uncovered`] returns tile the part of the light no shadow covers: a point off
/// every edge lies in exactly one of them when no shadow holds it, in none otherwise.
#[test]
fn uncovered_rectangles_tile_the_lit_part_of_the_light() {
    let light = Rect { x0: -1.0, x1: 1.0, y0: -0.5, y1: 1.5 };
    let shadows = [
        Rect { x0: -1.0, x1: -0.2, y0: 0.1, y1: 0.9 },
        Rect { x0: -0.5, x1: 0.4, y0: 0.6, y1: 1.5 },
        Rect { x0: 0.3, x1: 0.8, y0: -0.3, y1: 0.2 },
        Rect { x0: 0.35, x1: 0.6, y0: 0.0, y1: 0.1 },
    ];
    let parts = uncovered(light, &shadows);
    let inside = |r: &Rect, u: f64, v: f64| r.x0 < u && u < r.x1 && r.y0 < v && v < r.y1;
    let mut rng = mcbench_core::rng::stream(3, "uncovered");
    for _ in 0..20_000 {
        use rand::Rng;
        let (u, v) = (rng.gen_range(-1.0..1.0), rng.gen_range(-0.5..1.5));
        let lit = !shadows.iter().any(|s| inside(s, u, v));
        let holders = parts.iter().filter(|r| inside(r, u, v)).count();
        assert_eq!(holders, usize::from(lit), "({u}, {v}): lit {lit}, in {holders} parts");
    }
    let area: f64 = parts.iter().map(|r| (r.x1 - r.x0) * (r.y1 - r.y0)).sum();
    assert!(area > 0.0 && area < 4.0 && parts.len() < 20, "{} parts, area {area}", parts.len());
}

/// `lattice`: every point that sees the board sees exactly one rectangle of the light through
/// the bars, most uniform light samples are blocked, and the quadrature agrees with the
/// ray-cast brute force.
#[test]
fn lattice_shows_one_window_blocks_most_light_samples_and_its_reference_splits_exactly() {
    use rand::Rng;
    let start = std::time::Instant::now();
    let bed = CheckerDirect::new("lattice", &Params::new().with("resolution", 24.0)).unwrap();
    let built = start.elapsed().as_secs_f64();
    let geo = bed.geometry();
    assert_eq!(geo.lights.len(), 1);
    let light = geo.lights[0];
    let free = CheckerGeometry { occluders: Vec::new(), ..geo.clone() };
    let mut rng = mcbench_core::rng::stream(5, "lattice");
    let (mut board, mut blocked_share, mut area_share) = (Vec::new(), 0.0, 0.0);
    let (samples, mut smallest, mut largest) = (2000, 1.0f64, 0.0f64);
    for i in 0..bed.integrals() {
        let p = bed.shading(i);
        assert_eq!(p.brdf.ks[0], 0.0, "every square is diffuse");
        if p.brdf.kd[0] == 0.0 {
            continue;
        }
        let parts = visible_parts(&light, p.position, geo);
        assert_eq!(parts.len(), 1, "pixel {i} sees one window: {parts:?}");
        let lit = parts.iter().map(|r| (r.x1 - r.x0) * (r.y1 - r.y0)).sum::<f64>() / (1.2 * 1.2);
        (smallest, largest) = (smallest.min(lit), largest.max(lit));
        area_share += 1.0 - lit;
        // Uniform points on the light, as MIS's light sampler draws them, cast against the bars.
        let mut blocked = 0;
        for _ in 0..samples {
            let (u, v) = (rng.gen_range(light.min[0]..light.max[0]), rng.gen_range(light.min[1]..light.max[1]));
            let w = (Vec3::new(u, v, light.z) - p.position).normalize();
            blocked += usize::from(geo.incident(p.position, w)[0] == 0.0);
        }
        blocked_share += blocked as f64 / samples as f64;
        board.push(i);
    }
    let (blocked_share, area_share) = (blocked_share / board.len() as f64, area_share / board.len() as f64);
    eprintln!(
        "lattice: built with its reference in {built:.3} s, {} board pixels, mean blocked share of light samples {blocked_share:.3} (area {area_share:.3}), \
         visible share of the light from {smallest:.3} to {largest:.3}",
        board.len()
    );
    assert!(board.len() > 300, "{}", board.len());
    assert!(blocked_share > 0.8 && (blocked_share - area_share).abs() < 0.01, "{blocked_share} vs {area_share}");
    assert!(largest <= 0.25 + 1e-12 && smallest < 0.05, "{smallest}..{largest}");
    for &i in board.iter().step_by(board.len() / 4).take(4) {
        let p = bed.shading(i);
        let r = bed.reference().value[i][0];
        let b = brute(geo, &p, 384, 384);
        let unoccluded = direct_lighting(&free, &p, REL_TOL).0;
        eprintln!("lattice pixel {i}: quadrature {r:.9e}, ray-cast brute force {b:.9e}, unoccluded {unoccluded:.6e}");
        assert!(r > 0.0 && (r - b).abs() <= 1e-3 * unoccluded, "pixel {i}: {r} vs {b}");
    }
}

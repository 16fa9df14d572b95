//! The registry of samplers and their chi-square goodness-of-fit checks (book: conformance.md):
//! one entry per sampler module (the direction and distance samplers of this folder, the Phong
//! BRDF mixture and the phase functions), each check drawing with a fixed seed and binning against
//! the sampler's reported density with the helpers of [`super::testing`].
//!
//! The checks are the samplers' chi-square tests: `tests::every_registered_sampler_fits` runs
//! them beside the code, and the conformance suite (`mcbench::conformance`) runs the checks of
//! the samplers each estimator names. A check is deterministic, so running it twice is the same
//! test: the Sidak family of [`super::testing::SAMPLER_TESTS`] counts each statistic once.

use super::testing::{interval_chi_square, sampler_chi_square, SphereGrid};
use super::{cone, cosine_hemisphere, equiangular::Equiangular, free_flight, mixture, phong_lobe, rayleigh};
use super::{rect_light, uniform_hemisphere};
use crate::brdf::Phong;
use crate::lighting::RectLight;
use crate::math::{Frame, Rgb, Vec3};
use crate::phase::Phase;
use crate::quadrature::gauss_legendre;
use crate::rng::stream;
use crate::stats::{chi_square_gof, ChiSquare};
use free_flight::{Interp, SamplingDensity};
use rand::Rng;

/// One registered sampler.
pub struct SamplerEntry {
    /// Stable id (the module name).
    pub id: &'static str,
    /// What it samples.
    pub summary: &'static str,
    /// Its chi-square tests: (name, outcome) per configuration.
    pub check: fn() -> Vec<(String, ChiSquare)>,
}

/// Every registered sampler.
pub static SAMPLERS: &[SamplerEntry] = &[
    SamplerEntry { id: "uniform_hemisphere", summary: "uniform directions on the hemisphere", check: uniform },
    SamplerEntry { id: "cosine_hemisphere", summary: "cosine-weighted hemisphere", check: cosine },
    SamplerEntry { id: "cone", summary: "uniform in a cone (wide and 0.01 rad)", check: cone_check },
    SamplerEntry { id: "phong_lobe", summary: "Phong lobe cos^n (n = 20 and the stiff 10000)", check: lobe },
    SamplerEntry { id: "rayleigh", summary: "Rayleigh phase directions", check: rayleigh_check },
    SamplerEntry { id: "rect_light", summary: "solid-angle sampling of rectangular lights", check: rect },
    SamplerEntry { id: "equiangular", summary: "equiangular distances towards a point light", check: equiangular },
    SamplerEntry {
        id: "free_flight",
        summary: "free-flight distances (constant, piecewise, truncated)",
        check: flights,
    },
    SamplerEntry { id: "mixture", summary: "deterministic mixture sampling (DMS) of three lobes", check: dms },
    SamplerEntry { id: "brdf", summary: "the Phong BRDF's diffuse + lobe mixture", check: brdf_mixture },
    SamplerEntry { id: "phase", summary: "isotropic, Henyey-Greenstein and Rayleigh phase sampling", check: phases },
];

/// Looks a sampler up by id.
pub fn sampler(id: &str) -> Option<&'static SamplerEntry> {
    SAMPLERS.iter().find(|s| s.id == id)
}

fn one(name: &str, c: ChiSquare) -> Vec<(String, ChiSquare)> {
    vec![(name.to_string(), c)]
}

fn uniform() -> Vec<(String, ChiSquare)> {
    let grid = SphereGrid::upper(16, 16);
    one(
        "uniform hemisphere",
        sampler_chi_square(&grid, 200_000, 1, uniform_hemisphere::sample_local, |d| uniform_hemisphere::pdf(d.z)),
    )
}

fn cosine() -> Vec<(String, ChiSquare)> {
    let grid = SphereGrid::upper(16, 16);
    one(
        "cosine hemisphere",
        sampler_chi_square(&grid, 200_000, 2, cosine_hemisphere::sample_local, |d| cosine_hemisphere::pdf(d.z)),
    )
}

fn cone_check() -> Vec<(String, ChiSquare)> {
    [(0.3f64, 16usize, 31u64, "cone 0.3 rad"), (0.01, 8, 32, "cone 0.01 rad")]
        .into_iter()
        .map(|(angle, phi, seed, name)| {
            let cos_max = angle.cos();
            let edges = (0..=16).map(|k| cos_max + (1.0 - cos_max) * k as f64 / 16.0).collect();
            let grid = SphereGrid::with_cos_edges(edges, phi);
            let c = sampler_chi_square(
                &grid,
                100_000,
                seed,
                |r| cone::sample_local(cos_max, r),
                |d| cone::pdf(d.z, cos_max),
            );
            (name.to_string(), c)
        })
        .collect()
}

fn lobe() -> Vec<(String, ChiSquare)> {
    let wide = SphereGrid::upper(24, 12);
    // Cells in cos(alpha) concentrated near the axis, where the mass of a stiff lobe sits.
    let stiff = SphereGrid::with_cos_edges((0..=24).map(|k| 1.0 - 2e-3 * (k as f64 / 24.0)).rev().collect(), 12);
    vec![
        (
            "phong lobe n=20".into(),
            sampler_chi_square(
                &wide,
                200_000,
                3,
                |r| phong_lobe::sample_local(20.0, r),
                |d| phong_lobe::pdf(d.z, 20.0),
            ),
        ),
        (
            "phong lobe n=10000".into(),
            sampler_chi_square(&stiff, 200_000, 4, |r| phong_lobe::sample_local(1e4, r), |d| phong_lobe::pdf(d.z, 1e4)),
        ),
    ]
}

fn rayleigh_check() -> Vec<(String, ChiSquare)> {
    let grid = SphereGrid::full(16, 8);
    one("rayleigh", sampler_chi_square(&grid, 200_000, 3, |r| rayleigh::sample(Vec3::Z, r), |d| rayleigh::pdf(d.z)))
}

/// Chi-square in the light's own plane: directions are binned by where they cross it (an
/// `nx x ny` grid aligned with the rectangle) and each cell's probability is the integral of the
/// reported solid-angle pdf over the cell, `int pdf(w(y)) cos(theta_y) / d^2 dA` (12 x 12
/// Gauss-Legendre). A wrong distance or cosine factor shows up as a gradient; a pdf that does not
/// integrate to one over the light fails outright (p = 0).
fn rect_one(light: &RectLight, p: Vec3, seed: u64) -> ChiSquare {
    let (nx, ny) = (16usize, 12usize);
    let (dx, dy) = ((light.max[0] - light.min[0]) / nx as f64, (light.max[1] - light.min[1]) / ny as f64);
    let (x, w) = gauss_legendre(12);
    let mut probs = Vec::with_capacity(nx * ny + 1);
    for iy in 0..ny {
        for ix in 0..nx {
            let mut acc = 0.0;
            for (xi, wi) in x.iter().zip(&w) {
                for (xj, wj) in x.iter().zip(&w) {
                    let px = light.min[0] + dx * (ix as f64 + 0.5 + 0.5 * xi);
                    let py = light.min[1] + dy * (iy as f64 + 0.5 + 0.5 * xj);
                    let d = Vec3::new(px, py, light.z) - p;
                    let dir = d.normalize();
                    acc += wi * wj * rect_light::pdf(light, p, dir) * dir.z / d.dot(d);
                }
            }
            probs.push(acc * 0.25 * dx * dy);
        }
    }
    let inside: f64 = probs.iter().sum();
    probs.push(0.0);
    let mut rng = stream(seed, "rect light chi-square");
    let mut counts = vec![0u64; nx * ny + 1];
    for _ in 0..100_000 {
        let s = rect_light::sample(light, p, &mut rng);
        let cell = light.hit(p, s.w).map(|t| {
            let h = p + s.w * t;
            let ix = (((h.x - light.min[0]) / dx) as usize).min(nx - 1);
            let iy = (((h.y - light.min[1]) / dy) as usize).min(ny - 1);
            iy * nx + ix
        });
        counts[cell.unwrap_or(nx * ny)] += 1;
    }
    let c = chi_square_gof(&counts, &probs).unwrap_or_else(|e| panic!("chi-square could not run: {e}"));
    if (inside - 1.0).abs() < 1e-9 {
        c
    } else {
        ChiSquare { p_value: 0.0, ..c }
    }
}

fn rect() -> Vec<(String, ChiSquare)> {
    // The checker scene's large dim light seen obliquely, and the small bright one nearby.
    let large = RectLight::centred(-1.0, 2.5, 2.0, 2.0, 1.0, Rgb::splat(3.0));
    let small = RectLight::centred(1.0, 1.8, 1.2, 0.15, 0.15, Rgb::splat(400.0));
    vec![
        ("rect light, large".into(), rect_one(&large, Vec3::new(0.3, -0.5, 0.0), 21)),
        ("rect light, small".into(), rect_one(&small, Vec3::new(0.9, 1.7, 0.0), 22)),
    ]
}

fn equiangular() -> Vec<(String, ChiSquare)> {
    let Some(e) = Equiangular::new(6.0, 0.3, (1.0, 17.0)) else {
        panic!("the equiangular test geometry has a density");
    };
    // Cells graded towards the peak.
    let mut edges: Vec<f64> = (0..=40).map(|k| 1.0 + 16.0 * k as f64 / 40.0).collect();
    edges.extend((-10..=10).map(|k| 6.0 + 0.06 * k as f64));
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    one("equiangular", interval_chi_square(&edges, 200_000, 21, |r| e.sample(r.gen()), |t| e.pdf(t)))
}

/// Chi-square of sampled distances against the exact distribution
/// `P(a <= s < b) = exp(-Lambda(a)) - exp(-Lambda(b))`, with a tail cell; a distance not beyond
/// the start fails outright (p = 0).
fn flight(d: &SamplingDensity, start: f64, edges_end: f64, name: &str) -> (String, ChiSquare) {
    let mut rng = stream(11, name);
    let cells = 40;
    let edges: Vec<f64> = (0..=cells).map(|k| start + edges_end * k as f64 / cells as f64).collect();
    let mut counts = vec![0u64; cells + 1];
    let mut backwards = false;
    for _ in 0..200_000 {
        let s = d.sample(start, rng.gen::<f64>());
        backwards |= !(s > start || s.is_infinite());
        let c = edges.partition_point(|&e| e <= s).clamp(1, cells + 1) - 1;
        counts[if s >= edges[cells] { cells } else { c }] += 1;
    }
    let surv = |x: f64| (-d.integral(start, x)).exp();
    let mut probs: Vec<f64> = edges.windows(2).map(|w| surv(w[0]) - surv(w[1])).collect();
    probs.push(surv(edges[cells]));
    let c = chi_square_gof(&counts, &probs).unwrap_or_else(|e| panic!("chi-square could not run: {e}"));
    (name.to_string(), if backwards { ChiSquare { p_value: 0.0, ..c } } else { c })
}

fn flights() -> Vec<(String, ChiSquare)> {
    let pwc = SamplingDensity::new(vec![0.0, 1.0, 2.5, 4.0], vec![0.2, 1.5, 0.0, 0.6], Interp::Constant);
    let pwl = SamplingDensity::new(vec![0.0, 1.0, 2.5, 4.0, 6.0], vec![0.1, 1.2, 0.0, 0.9, 0.3], Interp::Linear);
    let trunc = SamplingDensity::new(vec![1.0, 3.0, 6.0, 9.0], vec![0.05, 0.9, 0.02, 0.4], Interp::Linear);
    let edges: Vec<f64> = (0..=48).map(|k| 1.0 + 10.0 * k as f64 / 48.0).collect();
    vec![
        flight(&SamplingDensity::constant(0.7), 0.0, 6.0, "ff-constant"),
        flight(&pwc, 0.3, 8.0, "ff-pwc"),
        flight(&pwl, 0.5, 9.0, "ff-pwl"),
        (
            "truncated free flight".into(),
            interval_chi_square(
                &edges,
                200_000,
                23,
                |r| trunc.sample_truncated((1.0, 11.0), r.gen()),
                |t| trunc.pdf_truncated((1.0, 11.0), t),
            ),
        ),
    ]
}

/// Pooled DMS draws from a cosine + Phong lobe + cone mixture follow the full-mixture pdf.
fn dms() -> Vec<(String, ChiSquare)> {
    let alphas = [0.3, 0.45, 0.25];
    let lobe_axis = Vec3::new(0.3, -0.2, 0.9).normalize();
    // The cone about +z so its edge is a cell edge (the pdf is discontinuous there).
    let cone_axis = Vec3::Z;
    let cos_max = 0.25f64.cos();
    let (lobe, cf) = (Frame::around(lobe_axis), Frame::around(cone_axis));
    let pdf = move |d: Vec3| {
        alphas[0] * cosine_hemisphere::pdf(d.z)
            + alphas[1] * phong_lobe::pdf(lobe_axis.dot(d), 30.0)
            + alphas[2] * cone::pdf(cone_axis.dot(d), cos_max)
    };
    let mut queue: Vec<Vec3> = Vec::new();
    let mut edges: Vec<f64> = (0..=24).map(|k| -1.0 + 2.0 * k as f64 / 24.0).collect();
    edges.push(cos_max);
    edges.sort_by(f64::total_cmp);
    let grid = SphereGrid::with_cos_edges(edges, 24);
    let sample = |r: &mut crate::rng::StreamRng| {
        if queue.is_empty() {
            let c = mixture::dms_counts(&alphas, 7, r);
            for _ in 0..c[0] {
                queue.push(cosine_hemisphere::sample_local(r));
            }
            for _ in 0..c[1] {
                queue.push(lobe.to_world(phong_lobe::sample_local(30.0, r)));
            }
            for _ in 0..c[2] {
                queue.push(cf.to_world(cone::sample_local(cos_max, r)));
            }
        }
        queue.pop().unwrap_or(Vec3::Z)
    };
    one("DMS mixture", sampler_chi_square(&grid, 160_000, 41, sample, pdf))
}

fn brdf_mixture() -> Vec<(String, ChiSquare)> {
    let brdf = Phong { kd: Rgb::splat(0.5), ks: Rgb::splat(0.3), n: 20.0 };
    let wo = Vec3::new(0.0, -0.8, 0.6).normalize();
    let grid = SphereGrid::full(24, 16);
    one(
        "phong mixture",
        sampler_chi_square(&grid, 400_000, 11, |rng| brdf.sample(wo, Vec3::Z, rng).w, |d| brdf.pdf(d, wo, Vec3::Z)),
    )
}

/// Each phase function on a 16 x 8 grid over the whole sphere, around a tilted propagation
/// direction so the frame construction is exercised too.
fn phases() -> Vec<(String, ChiSquare)> {
    let dir = Vec3::new(0.3, -0.5, 0.8).normalize();
    let grid = SphereGrid::full(16, 8);
    [Phase::Isotropic, Phase::HenyeyGreenstein(0.1), Phase::HenyeyGreenstein(0.8), Phase::Rayleigh]
        .into_iter()
        .enumerate()
        .map(|(k, phase)| {
            let c = sampler_chi_square(
                &grid,
                100_000,
                40 + k as u64,
                |rng| phase.sample(dir, rng).0,
                |w| phase.eval(w.dot(dir)),
            );
            (phase.name(), c)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samplers::testing::assert_fits;

    #[test]
    fn every_registered_sampler_fits() {
        for s in SAMPLERS {
            for (name, c) in (s.check)() {
                assert_fits(&format!("{}: {name}", s.id), &c);
            }
        }
    }

    #[test]
    fn every_sampler_module_is_registered() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/samplers");
        let mut missing = Vec::new();
        for f in std::fs::read_dir(&dir).expect("samplers folder").flatten() {
            let name = f.file_name().to_string_lossy().trim_end_matches(".rs").to_string();
            if !["mod", "testing", "registry"].contains(&name.as_str()) && sampler(&name).is_none() {
                missing.push(name);
            }
        }
        assert!(missing.is_empty(), "sampler modules without a registry entry: {missing:?}");
        let mut ids: Vec<_> = SAMPLERS.iter().map(|s| s.id).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), SAMPLERS.len());
    }
}

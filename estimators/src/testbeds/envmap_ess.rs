//! The expected effective sample size of the SMC reweighting of `envmap-sequence` (paper 004
//! Eq. 3-4 and §3's ESS), computed exactly from the map and the BRDF: how much resampling the
//! scene itself asks for, the ceiling its map and BRDF set on the share resampled.
//!
//! Algorithm 1 of paper 004 reweights particles drawn from `p_{n-1}` by the incremental weights
//! `w = p~_n / p~_{n-1}` (Eq. 3) and resamples when the effective sample size
//! `(sum_j W_j^2)^-1` (§3, Liu and Chen 1998) falls below `N / 2`. For N particles drawn exactly from `p_{n-1}`, `ESS / N` tends to
//! `E[w]^2 / E[w^2]` (Kong, Liu and Wong 1994). With `p~ = L f cos` (grey BRDF: `f` the same in
//! every channel, as in every variant) and a piecewise-constant map rotated about +z, both frames
//! are constant on the panels where one texel of frame n-1 meets one texel of frame n (the grids
//! share their rows; a rotation splits each texel of frame n-1 in `phi` at most once), so with
//! `G` the geometric factor `integral of f cos` of a panel
//! ([`super::envmap_reference::TexelTable::panel_factor`]), `a` and `b` its channel-mean
//! radiance in frames n-1 and n, and sums over the panels where `a > 0`:
//!
//! `Z = sum a G`, `E[w] = sum b G / Z`, `E[w^2] = sum (b^2 / a) G / Z`,
//! `ESS / N = (sum b G)^2 / (Z sum (b^2 / a) G)`.
//!
//! The share of pixels whose expected `ESS / N` falls below the threshold is what the scene asks
//! of the reweighting, the many-particle limit of the `resampled` diagnostic of a frame that starts
//! from equal weights. It is no bound on a measurement with few particles either way: weights a
//! pixel did not resample carry into the next frame and lower its ESS further
//! ([`share_below_carried`] follows them), while with N = 16 the rare particles that carry large
//! weights are mostly missing, so a measured ESS sits above its expectation where the target
//! moves far.

use super::envmap_reference::TexelTable;
use super::envmap_sequence::EnvmapSequence;
use mcbench_core::error::ConfigError;
use mcbench_core::params::Params;
use mcbench_core::testbed::{EnvSequenceScene, TestBed};
use rayon::prelude::*;
use std::f64::consts::TAU;

/// The resampling threshold of paper 004 Algorithm 1: resample when `ESS < N / 2` (the default
/// `threshold` of the SMC estimators).
pub const RESAMPLING_THRESHOLD: f64 = 0.5;

/// Expected `ESS / N` of the reweighting from frame `frame - 1` to `frame` (1 or more) at `pixel`.
/// 1 when nothing changes; 0 when no particle of frame `frame - 1` keeps any weight.
pub fn expected_ess(bed: &EnvmapSequence, table: &TexelTable, pixel: usize, frame: usize) -> f64 {
    let (prev, next) = (bed.environment(frame - 1), bed.environment(frame));
    let g = prev.map.grid();
    let point = bed.shading(pixel);
    // Frame n-1's map coordinates: the shading point rotated by -rotation (as the reference does).
    let rot = |v: mcbench_core::math::Vec3| {
        let (s, c) = (-prev.rotation).sin_cos();
        mcbench_core::math::Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
    };
    let (n, wo) = (rot(point.normal), rot(point.wo));
    let r = wo.reflect(n);
    // Frame n's map sits rotated by `shift` columns in these coordinates.
    let shift = (next.rotation - prev.rotation) / (TAU / g.width as f64);
    let whole = shift.floor();
    let cut = shift - whole;
    let (mut z, mut first, mut second) = (0.0, 0.0, 0.0);
    for t in 0..table.texels() {
        let a = prev.map.texel(t).mean() * prev.scale;
        if a <= 0.0 {
            continue;
        }
        let (row, col) = (t / g.width, t % g.width);
        let (pa, pb) = table.phi_edges(t);
        let split = pa + cut * (pb - pa);
        let column = |back: i64| (col as i64 - whole as i64 - back).rem_euclid(g.width as i64) as usize;
        for (range, back) in [((pa, split), 1), ((split, pb), 0)] {
            let Some(geometric) = table.panel_factor(t, range, n, r, &point.brdf) else { continue };
            let b = next.map.texel(row * g.width + column(back)).mean() * next.scale;
            z += a * geometric;
            first += b * geometric;
            second += b * b / a * geometric;
        }
    }
    if first <= 0.0 || z <= 0.0 {
        return 0.0;
    }
    (first * first / (z * second)).min(1.0)
}

/// Expected `ESS / N` of every propagated frame (1 to F - 1) and pixel, frame-major:
/// `[frame - 1][pixel]` (parallel over pixels).
pub fn expected_ess_by_frame(bed: &EnvmapSequence) -> Vec<Vec<f64>> {
    let g = bed.environment(0).map.grid();
    let table = TexelTable::new(g.width, g.height);
    let (w, h) = bed.resolution();
    (1..bed.frames()).map(|f| (0..w * h).into_par_iter().map(|p| expected_ess(bed, &table, p, f)).collect()).collect()
}

/// The share of pixels whose expected `ESS / N` falls below `threshold`, averaged over the
/// propagated frames (0 when there are none).
pub fn share_below(ess: &[Vec<f64>], threshold: f64) -> f64 {
    let shares: Vec<f64> =
        ess.iter().map(|f| f.iter().filter(|&&e| e < threshold).count() as f64 / f.len().max(1) as f64).collect();
    if shares.is_empty() {
        0.0
    } else {
        shares.iter().sum::<f64>() / shares.len() as f64
    }
}

/// As [`share_below`], but with the weights a pixel did not resample carried into the next frame,
/// as Algorithm 1 carries them: its expected `ESS / N` is the product of the per-frame values since
/// it last resampled (exact when the MH moves mix perfectly, so each frame's particles are fresh
/// draws from `p_{n-1}` whatever their weights), and it resamples, starting the product again,
/// when that falls below `threshold`.
pub fn share_below_carried(ess: &[Vec<f64>], threshold: f64) -> f64 {
    let (frames, pixels) = (ess.len(), ess.first().map_or(0, Vec::len));
    if frames == 0 || pixels == 0 {
        return 0.0;
    }
    let mut resampled = 0usize;
    for p in 0..pixels {
        let mut carried = 1.0;
        for frame in ess {
            carried *= frame[p];
            if carried < threshold {
                resampled += 1;
                carried = 1.0;
            }
        }
    }
    resampled as f64 / (frames * pixels) as f64
}

/// The expected share of pixels resampled per propagated frame by SMC on `envmap-sequence`
/// `variant` with `params` (paper 004 §7 reports 36% with one distribution and 5 MH moves): the
/// share of pixels whose expected `ESS / N` falls below [`RESAMPLING_THRESHOLD`], averaged over
/// frames 1 to F - 1. The `resampled` diagnostic is a mean over all F frames, of which the first
/// resamples nothing: compare it with this share times `(F - 1) / F`.
pub fn expected_resampled_share(params: &Params, variant: &str) -> Result<f64, ConfigError> {
    let bed = EnvmapSequence::without_reference(variant, params)?;
    Ok(share_below(&expected_ess_by_frame(&bed), RESAMPLING_THRESHOLD))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::math::Vec3;

    fn params(rotation: f64) -> Params {
        Params::new()
            .with("resolution", 3.0)
            .with("frames", 3.0)
            .with("env_width", 64.0)
            .with("env_height", 32.0)
            .with("rotation", rotation)
    }

    /// By hand: without rotation `w = 1` everywhere, so `ESS / N = 1` and nothing resamples.
    #[test]
    fn no_rotation_gives_ess_one_and_share_zero() {
        for variant in ["mixed", "specular-lns"] {
            let bed = EnvmapSequence::without_reference(variant, &params(0.0)).unwrap();
            for frame in expected_ess_by_frame(&bed) {
                assert!(frame.iter().all(|e| (e - 1.0).abs() < 1e-12), "{variant}: {frame:?}");
            }
            assert_eq!(expected_resampled_share(&params(0.0), variant).unwrap(), 0.0);
        }
    }

    /// A whole turn a frame is no change either.
    #[test]
    fn a_whole_turn_is_no_change() {
        let bed = EnvmapSequence::without_reference("mixed", &params(360.0)).unwrap();
        assert!(expected_ess_by_frame(&bed).iter().flatten().all(|e| (e - 1.0).abs() < 1e-9));
    }

    /// By hand on a two-texel-wide change: at a rotation of exactly one column, frame n shows
    /// column j - 1 where frame n-1 showed column j, so `E[w]` and `E[w^2]` are sums over whole
    /// texels; checked against Monte Carlo over `p_{n-1}` sampled by the map and weighted by the
    /// BRDF (importance sampling of both moments).
    #[test]
    fn one_column_of_rotation_matches_monte_carlo_moments() {
        let deg = 360.0 / 64.0;
        let bed = EnvmapSequence::without_reference("mixed", &params(deg)).unwrap();
        let g = bed.environment(0).map.grid();
        let table = TexelTable::new(g.width, g.height);
        let exact = expected_ess(&bed, &table, 4, 1);
        let (prev, next, point) = (bed.environment(0), bed.environment(1), bed.shading(4));
        let mut rng = mcbench_core::rng::stream(3, "ess");
        let (mut z, mut m1, mut m2) = (0.0, 0.0, 0.0);
        let target = |env: &mcbench_core::envmap::EnvFrame<'_>, w: Vec3| {
            let cos = w.dot(point.normal);
            if cos <= 0.0 {
                0.0
            } else {
                env.radiance(w).mean() * point.brdf.eval(w, point.wo, point.normal).mean() * cos
            }
        };
        for _ in 0..400_000 {
            let s = prev.sample(&mut rng);
            let (a, b) = (target(&prev, s.w), target(&next, s.w));
            if a > 0.0 {
                z += a / s.pdf;
                m1 += b / s.pdf;
                m2 += b * b / a / s.pdf;
            }
        }
        let mc = m1 * m1 / (z * m2);
        assert!((mc - exact).abs() < 0.02 * exact, "Monte Carlo {mc} vs exact {exact}");
        assert!(exact < 1.0 - 1e-3, "the rotation changes the target: {exact}");
    }

    /// The table of expected shares against rotation at the `envmap-smc` quick size (10x10
    /// pixels, 6 frames); seconds in a release build:
    /// `cargo test --release -p mcbench-papers expected_share_table -- --ignored --nocapture`.
    #[test]
    #[ignore = "prints a table for the docs; about 2 min in a release build"]
    fn expected_share_table() {
        for variant in ["mixed", "moving"] {
            for rotation in [0.5, 1.5, 5.0, 15.0] {
                let p = Params::new().with("resolution", 10.0).with("frames", 6.0).with("rotation", rotation);
                let bed = EnvmapSequence::without_reference(variant, &p).unwrap();
                let ess = expected_ess_by_frame(&bed);
                let all: Vec<f64> = ess.iter().flatten().copied().collect();
                let mean = all.iter().sum::<f64>() / all.len() as f64;
                let min = all.iter().copied().fold(1.0, f64::min);
                let share = share_below(&ess, RESAMPLING_THRESHOLD);
                let carried = share_below_carried(&ess, RESAMPLING_THRESHOLD);
                println!(
                    "{variant} rotation {rotation}: share {share:.4}, carried {carried:.4}, mean ESS/N {mean:.4}, min {min:.4}"
                );
            }
        }
    }

    /// Faster rotation moves the sun further between frames: the expected ESS falls.
    #[test]
    fn expected_ess_falls_with_rotation() {
        let mean = |deg: f64| {
            let bed = EnvmapSequence::without_reference("specular", &params(deg)).unwrap();
            let e = expected_ess_by_frame(&bed);
            e.iter().flatten().sum::<f64>() / e.iter().flatten().count() as f64
        };
        let (slow, fast) = (mean(1.5), mean(15.0));
        assert!(fast < slow && slow < 1.0, "1.5 degrees {slow}, 15 degrees {fast}");
        assert_eq!(share_below(&[vec![0.4, 0.6], vec![0.1, 0.2]], 0.5), 0.75);
        assert_eq!(share_below(&[], 0.5), 0.0);
        // Carried: 0.8 then 0.55 multiply to 0.44 (resampled in the second frame), 0.4 at once.
        assert_eq!(share_below_carried(&[vec![0.8, 0.4], vec![0.55, 0.9]], 0.5), 0.5);
    }
}

//! Which reading of paper 002 Eq. 21 fits what the paper prints (book: paper-002.md, "Eq. 21's
//! exponent"): the extracted text has a "5" on a line of its own above the first factor, so the
//! medium is either `((cos(1.5 (x + y + z)) + 1) / 2) (sin(z / 2) + 2) / 3` (k = 1) or the same with
//! the first factor to the fifth power (k = 5). Both have maximum 1. This prints, for both
//! readings, every number the paper gives that does not depend on its unknown lighting:
//!
//! - Fig. 6 (particle tracing, `eq21-medium/multiple`, 16x16 over the square the sphere fills;
//!   pixels that miss it fetch nothing): fetches per path of the adaptive model at sigma_samp 1
//!   (the paper's 1053 fetches per pixel at 100 paths), at each sigma_samp over those at 1, and
//!   of the terminating model over the adaptive one (where it is valid);
//! - Fig. 9 (`eq21-medium/transmittance`, 10 fetches per pixel on average over the image): rays
//!   per pixel of Woodcock (delta) tracking and of residual ratio tracking, and the error ratio
//!   Woodcock / new method at those ray counts;
//! - Fig. 12 (`eq21-medium/single-scatter`, 300 fetches per pixel): primary rays per pixel (the
//!   residual-tracking methods' explorer evaluations are not counted, as in `single-scatter`);
//! - Fig. 5 / 8: the largest |sigma_t - main part| on the central ray, which sets the paper's
//!   sigma_samp = 0.4 for that ray, for piecewise-linear main parts through explorer points.
//!
//! Run: `cargo run --release -p experiments --example eq21_signatures` (about a minute on two
//! cores; seed fixed, the same output at any thread count).

use mcbench_core::budget::Budget;
use mcbench_core::math::Vec3;
use mcbench_core::params::Params;
use mcbench_core::references::NoReferences;
use mcbench_core::rng::StreamKey;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use mcbench_papers::builtins as registry;
use mcbench_papers::testbeds::medium::{density, Field, MediumBed};
use rayon::prelude::*;

/// The two readings of Eq. 21.
const READINGS: [i32; 2] = [1, 5];
/// Paths per pixel for the Fig. 6 fetch counts (one path per estimate).
const PATHS: u64 = 200;
/// Repetitions per pixel for the Fig. 9 error ratio.
const REPS: u64 = 256;

/// Mean fetches per sample of `estimator` over every pixel of `bed` (a pixel whose ray misses the
/// medium fetches nothing), `rays` samples per estimate and `estimates` estimates per pixel, and
/// the standard error of that mean (estimates are independent).
fn fetches_per_sample(bed: &dyn TestBed, estimator: &str, params: &Params, rays: u64, estimates: u64) -> (f64, f64) {
    let entry = registry::estimator(estimator).unwrap();
    let est = (entry.build)(params).unwrap();
    est.validate(bed).unwrap();
    let per_pixel: Vec<(f64, f64)> = (0..bed.integrals())
        .into_par_iter()
        .map(|i| {
            let mut rng =
                StreamKey { seed: 7, testbed: "sig", estimator, budget: rays, rep: 0, integral: i as u64 }.rng();
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..estimates {
                let task = Task::new(bed, i, Budget::samples(rays).unwrap());
                est.estimate(&task, &mut rng).unwrap();
                let f = task.costs().fetches as f64 / task.costs().samples as f64;
                s += f;
                s2 += f * f;
            }
            let n = estimates as f64;
            (s / n, (s2 / n - (s / n).powi(2)).max(0.0) / n)
        })
        .collect();
    let m = per_pixel.len() as f64;
    let mean = per_pixel.iter().map(|x| x.0).sum::<f64>() / m;
    let se = per_pixel.iter().map(|x| x.1).sum::<f64>().sqrt() / m;
    (mean, se)
}

/// Rays per pixel that spend `budget` fetches per pixel on average over the image (the paper sets
/// one ray count per method so that every method makes the same number of fetches).
fn rays_at(bed: &dyn TestBed, estimator: &str, budget: f64) -> f64 {
    budget / fetches_per_sample(bed, estimator, &Params::new(), 16, 16).0
}

fn bed(variant: &str, k: i32, extra: &[(&str, f64)]) -> MediumBed {
    let mut p = Params::new().with("exponent", k as f64);
    for (name, v) in extra {
        p = p.with(name, *v);
    }
    MediumBed::new(Field::Eq21, variant, &p, &NoReferences)
        .unwrap_or_else(|_| MediumBed::without_reference(Field::Eq21, variant, &p).unwrap())
}

fn sigma(s: f64) -> Params {
    Params::new().with("sigma_samp", s)
}

/// Fig. 6: fetches per path (adaptive at each sigma_samp; terminating where it is valid).
fn fig6(k: i32) -> Vec<(String, f64, f64)> {
    let b = bed("multiple", k, &[]);
    let adaptive: Vec<(f64, (f64, f64))> = [0.6, 0.7, 0.8, 0.9, 1.0, 2.0]
        .into_iter()
        .map(|s| (s, fetches_per_sample(&b, "spm_adaptive", &sigma(s), 1, PATHS)))
        .collect();
    let at1 = adaptive.iter().find(|x| x.0 == 1.0).unwrap().1 .0;
    let mut out = vec![("adaptive fetches per path at sigma_samp 1".to_string(), at1, 10.53)];
    let paper_adaptive = [621.0, 737.0, 832.0, 931.0, 1053.0, 2096.0];
    for ((s, c), p) in adaptive.iter().zip(paper_adaptive) {
        if *s != 1.0 {
            out.push((format!("adaptive fetches at {s} / at 1"), c.0 / at1, p / 1053.0));
        }
    }
    let paper_term = [(0.9, 689.0, 931.0), (1.0, 753.0, 1053.0), (2.0, 1433.0, 2096.0)];
    for (s, pt, pa) in paper_term {
        let t = fetches_per_sample(&b, "spm_terminating", &sigma(s), 1, PATHS).0;
        let a = adaptive.iter().find(|x| x.0 == s).unwrap().1 .0;
        out.push((format!("terminating / adaptive fetches at {s}"), t / a, pt / pa));
    }
    out
}

/// Fig. 9: rays per pixel at 10 fetches and the error ratio Woodcock / residual ratio tracking at
/// those ray counts (one count per method for every pixel, as the paper sets them).
fn fig9(k: i32) -> Vec<(String, f64, f64)> {
    let b = bed("transmittance", k, &[("resolution", 16.0)]);
    let mut out = Vec::new();
    let mut rmse = Vec::new();
    for (id, paper) in [("delta_tracking", 3.0), ("residual_ratio_tracking", 2.0)] {
        let rays = rays_at(&b, id, 10.0);
        out.push((format!("{id}: rays per pixel at 10 fetches"), rays, paper));
        rmse.push(error_at(&b, id, rays.round().max(1.0) as u64));
    }
    out.push(("Err ratio Woodcock / new method at 10 fetches".into(), rmse[0] / rmse[1], 367.0 / 54.0));
    out
}

/// RMS error over the image of `id` with `rays` rays per pixel ([`REPS`] estimates per pixel).
fn error_at(bed: &MediumBed, id: &str, rays: u64) -> f64 {
    let est = (registry::estimator(id).unwrap().build)(&Params::new()).unwrap();
    let sq: Vec<f64> = (0..bed.integrals())
        .into_par_iter()
        .map(|i| {
            let truth = bed.reference().value[i][0];
            let mut rng =
                StreamKey { seed: 8, testbed: "sig", estimator: id, budget: rays, rep: 0, integral: i as u64 }.rng();
            let mut s = 0.0;
            for _ in 0..REPS {
                let task = Task::new(bed, i, Budget::samples(rays).unwrap());
                let v = est.estimate(&task, &mut rng).unwrap();
                s += (v[0] - truth).powi(2);
            }
            s / REPS as f64
        })
        .collect();
    (sq.iter().sum::<f64>() / sq.len() as f64).sqrt()
}

/// Fig. 12: primary rays per pixel at 300 fetches (the scene of `single-scatter`, 16x16).
fn fig12(k: i32) -> Vec<(String, f64, f64)> {
    let b = bed("single-scatter", k, &[("resolution", 16.0)]);
    [
        ("delta_tracking", 45.0),
        ("attenuation_driven", 10.0),
        ("attenuation_driven_sir", 30.0),
        ("source_driven", 6.0),
        ("scattering_driven", 6.0),
    ]
    .into_iter()
    .map(|(id, paper)| (format!("{id}: primary rays per pixel at 300 fetches"), rays_at(&b, id, 300.0), paper))
    .collect()
}

/// Fig. 5 / 8: the largest |sigma_t - piecewise-linear fit through explorer points `spacing` apart|
/// on the central ray (x = y = 0, z in [0, 20]); the paper samples that ray with sigma_samp 0.4.
fn fig5(k: i32) -> Vec<(String, f64, f64)> {
    let f = |z: f64| density::eq21(Vec3::new(0.0, 0.0, z), k);
    [0.5, 1.0, 2.0]
        .into_iter()
        .map(|h: f64| {
            let n = (20.0 / h).round() as usize;
            let worst = (0..=20_000)
                .map(|j| {
                    let z = 20.0 * j as f64 / 20_000.0;
                    let cell = ((z / h) as usize).min(n - 1);
                    let (z0, z1) = (cell as f64 * h, (cell + 1) as f64 * h);
                    let fit = f(z0) + (f(z1) - f(z0)) * (z - z0) / h;
                    (f(z) - fit).abs()
                })
                .fold(0.0, f64::max);
            (format!("central ray: max abs(sigma_diff), explorers {h} apart"), worst, 0.4)
        })
        .collect()
}

fn main() {
    let mut rows: Vec<(String, Vec<f64>, f64)> = Vec::new();
    for (i, k) in READINGS.into_iter().enumerate() {
        let all = [fig6(k), fig9(k), fig12(k), fig5(k)].concat();
        for (j, (what, ours, paper)) in all.into_iter().enumerate() {
            if i == 0 {
                rows.push((what, vec![ours], paper));
            } else {
                rows[j].1.push(ours);
            }
        }
    }
    println!("| signature | k = 1 | k = 5 | paper |");
    println!("|---|---|---|---|");
    for (what, ours, paper) in rows {
        println!("| {what} | {:.3} | {:.3} | {paper:.3} |", ours[0], ours[1]);
    }
}

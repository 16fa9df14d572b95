//! How far paper 000's Eq. 7 can go against its 15.3x speed-up on `gradient-box/albedo-0.8` at
//! every extinction the sensitivity experiment tries (book: paper-000.md, "How far Eq. 7 can go"):
//! the family's bound (no cache and no direction sampling beats it) and the exact-cache limit
//! (Eq. 7 with the true radiance field as cache), both as the work ratio (variance x rays per
//! estimate) over the independent path tracer, which the sensitivity part compares the paper's
//! number with.
//!
//! For each `sigma_t` it solves the box's radiance field ([`Field::solve`]), checks it against the
//! stored reference of the same box (an integrator that shares no code with it: the field's pixel
//! values and the reference's, the largest difference in the reference's standard errors), then
//! measures both estimators on the 16x16 image and prints the work ratios with their parts. The
//! last lines are the sensitivity part's `bound.values` and `limit.values`. A second solve at a finer field
//! (`--check-resolution`) shows what the discretisation moves.
//!
//! Run: `cargo run --release -p experiments --example exact_cache_bound` (seed fixed, the same
//! output at any thread count).

use mcbench_core::lighting::Gradient;
use mcbench_core::math::Vec3;
use mcbench_core::params::Params;
use mcbench_papers::builtins as registry;
use mcbench_papers::media_smc::exact_cache::field::{BoxScene, Field, Resolution};
use mcbench_papers::media_smc::exact_cache::{camera_ray, Limits};

/// The extinctions of the sensitivity part `000-speedup-sigma_t`.
const SIGMA_T: [f64; 6] = [0.125, 0.25, 0.5, 1.0, 2.0, 4.0];
/// The field's discretisation.
const FIELD: Resolution = Resolution { n: 13, m: 20, k: 40 };
/// The finer field of the check.
const FINE: Resolution = Resolution { n: 19, m: 28, k: 56 };
/// Image side, as the part's test bed.
const SIDE: usize = 16;
/// Paths per pixel for each estimator.
const PATHS: usize = 4000;
const SEED: u64 = 2026;

/// The largest |field - reference| over pixels and channels in the reference's standard errors,
/// and the largest relative difference.
fn against_reference(field: &Field, sigma_t: f64) -> (f64, f64) {
    let entry = registry::testbed("gradient-box").expect("gradient-box");
    let params = Params::new().with("sigma_t", sigma_t);
    let bed = (entry.build)("albedo-0.8", &params, &mcbench_papers::built_in_references::BUILT_IN)
        .expect("a stored reference for this sigma_t");
    let reference = bed.reference();
    let (mut z, mut rel) = (0.0f64, 0.0f64);
    for i in 0..SIDE * SIDE {
        let (o, d) = camera_ray(SIDE, i % SIDE, i / SIDE);
        let v = field.radiance(o, d);
        for c in 0..3 {
            let (r, se) = (reference.value[i][c], reference.std_err[i][c]);
            z = z.max((v[c] - r).abs() / se.max(f64::MIN_POSITIVE));
            rel = rel.max((v[c] - r).abs() / r.abs().max(1e-12));
        }
    }
    (z, rel)
}

fn main() {
    let check = std::env::args().any(|a| a == "--check-resolution");
    let background = Gradient { clamp: true, ..Gradient::papers() };
    let (mut bounds, mut limits) = (Vec::new(), Vec::new());
    println!("sigma_t  sweeps  max|field-ref|/se  max rel  var_indep  rays_indep  var_exact  rays_exact  exact_cache  family_bound");
    for sigma_t in SIGMA_T {
        let scene = BoxScene { sigma_t, albedo: 0.8, background };
        let field = Field::solve(scene, FIELD);
        let (z, rel) = against_reference(&field, sigma_t);
        let c = Limits::measure(&field, SIDE, PATHS, SEED);
        let (limit, bound) = (c.work_ratio(), c.family_bound(&field, SIDE));
        println!(
            "{sigma_t:<8} {:<7} {z:<18.2} {rel:<8.4} {:<10.5} {:<11.4} {:<10.5} {:<11.4} {:<12.3} {:.3}",
            field.sweeps,
            c.independent.mean_variance,
            c.independent.rays,
            c.exact.mean_variance,
            c.exact.rays,
            limit,
            bound
        );
        if check {
            let fine = Field::solve(scene, FINE);
            let f = Limits::measure(&fine, SIDE, PATHS, SEED);
            let centre = |x: &Field| x.in_scattered(Vec3::new(0.0, 0.0, 0.0)).mean();
            println!(
                "  finer field ({}^3 nodes, {}^2 cells, {} segments): work ratio {:.3}, L_i(centre) {:.5} against {:.5}",
                FINE.n,
                FINE.m,
                FINE.k,
                f.work_ratio(),
                centre(&fine),
                centre(&field)
            );
        }
        limits.push(format!("{limit:.3}"));
        bounds.push(format!("{bound:.3}"));
    }
    println!("bound.values = [{}]", bounds.join(", "));
    println!("limit.values = [{}]", limits.join(", "));
}

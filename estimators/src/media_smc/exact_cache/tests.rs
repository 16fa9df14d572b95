use super::field::{BoxScene, Field, Resolution};
use super::*;
use mcbench_core::lighting::Gradient;

fn scene(sigma_t: f64, albedo: f64, background: Gradient) -> BoxScene {
    BoxScene { sigma_t, albedo, background }
}

const COARSE: Resolution = Resolution { n: 5, m: 6, k: 8 };

/// The furnace (albedo 1, a constant background `c0`): the radiance is `c0` everywhere, which the
/// discretised equation keeps exactly (the segment weights telescope; the solve stops within
/// about 1e-8 of it), and Eq. 7 with the exact
/// cache returns `c0` from every path: zero variance.
#[test]
fn the_furnace_solves_to_its_constant_and_the_exact_cache_has_no_variance() {
    let c0 = Rgb([1.0, 0.8, 0.6]);
    let bg = Gradient { c0, c1: Rgb::ZERO, c2: Rgb::ZERO, clamp: true };
    let field = Field::solve(scene(1.0, 1.0, bg), COARSE);
    for i in 0..5 * 5 * 5 {
        let l = field.in_scattered(field.node(i));
        assert!((0..3).all(|c| (l[c] - c0[c]).abs() < 1e-7), "node {i}: {l:?}");
    }
    let cache = ExactCache::new(&field);
    let mut rng = <Pcg64 as rand::SeedableRng>::seed_from_u64(7);
    for _ in 0..200 {
        let (o, d) = camera_ray(4, 1, 2);
        let (v, flights) = cache.path(o, d, &mut rng);
        assert!(flights >= 1 && (0..3).all(|c| (v[c] - c0[c]).abs() < 1e-7), "{v:?}");
    }
}

/// Without scattering (albedo 0) the in-scattered radiance is the background's attenuated mean,
/// and at the centre of a nearly transparent box it is the background's mean over the sphere:
/// `c0` for an unclamped gradient (the linear terms average to zero).
#[test]
fn a_transparent_box_sees_the_mean_of_the_background() {
    let bg = Gradient { clamp: false, ..Gradient::papers() };
    let field = Field::solve(scene(1e-9, 0.0, bg), Resolution { n: 3, m: 16, k: 4 });
    let l = field.in_scattered(Vec3::new(0.0, 0.0, 0.0));
    assert!((0..3).all(|c| (l[c] - bg.c0[c]).abs() < 1e-6), "{l:?} against {:?}", bg.c0);
    // Attenuation: the box's centre at sigma_t = 1 sees at most exp(-0.5) of a constant sky and
    // at least exp(-sqrt(3) / 2) of it.
    let flat = Gradient { c1: Rgb::ZERO, c2: Rgb::ZERO, ..bg };
    let field = Field::solve(scene(1.0, 0.0, flat), Resolution { n: 3, m: 16, k: 4 });
    let l = field.in_scattered(Vec3::new(0.0, 0.0, 0.0))[0];
    assert!(l < (-0.5f64).exp() && l > (-(3f64.sqrt()) / 2.0).exp(), "{l}");
}

/// On the papers' box (albedo 0.8, a coarse field) the exact cache's estimate agrees with the
/// independent path tracer's within the field's discretisation and has several times less
/// variance at about the same rays (2.5x at this coarse field): the ceiling is above 1.
#[test]
fn the_exact_cache_removes_most_of_the_independent_tracers_variance() {
    let bg = Gradient { clamp: true, ..Gradient::papers() };
    let field = Field::solve(scene(1.0, 0.8, bg), COARSE);
    let c = Limits::measure(&field, 2, 4000, 11);
    for (a, b) in c.independent.mean.iter().zip(&c.exact.mean) {
        assert!((0..3).all(|k| (a[k] - b[k]).abs() < 0.03 * a[k].max(0.1)), "{a:?} against {b:?}");
    }
    assert!(c.work_ratio() > 1.5, "work ratio {}", c.work_ratio());
    assert!((c.independent.rays / c.exact.rays - 1.0).abs() < 0.5, "{} / {}", c.independent.rays, c.exact.rays);
}

/// Without scattering the first flight either passes (`L_b` with probability `exp(-sigma_t)`
/// across the unit box) or collides (value 0): the floor is the Bernoulli variance
/// `L_b^2 q (1 - q)`, whatever the field.
#[test]
fn the_first_flight_floor_is_the_pass_or_collide_variance_without_scattering() {
    let bg = Gradient { clamp: true, ..Gradient::papers() };
    let field = Field::solve(scene(0.7, 0.0, bg), Resolution { n: 2, m: 2, k: 2 });
    let q = (-0.7f64).exp();
    let lb = bg.eval(Vec3::new(0.0, 1.0, 0.0));
    let expected = (lb * lb).mean() * q * (1.0 - q);
    let floor = first_flight_variance(&field, 3, 64);
    assert!((floor - expected).abs() < 1e-12, "{floor} against {expected}");
}

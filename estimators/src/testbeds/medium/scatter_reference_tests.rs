//! The single-scatter reference against an independent brute force (the error bound
//! is shown, not assumed).

use super::*;
use mcbench_core::params::Params;
use mcbench_core::quadrature::gauss_legendre;

/// Composite 20-point Gauss-Legendre of `f` over the panels of `breaks`.
fn composite(f: impl Fn(f64) -> f64, breaks: &[f64]) -> f64 {
    let (x, w) = gauss_legendre(20);
    breaks
        .windows(2)
        .map(|p| {
            let (c, h) = (0.5 * (p[0] + p[1]), 0.5 * (p[1] - p[0]));
            x.iter().zip(&w).map(|(xi, wi)| wi * f(c + h * xi)).sum::<f64>() * h
        })
        .sum()
}

/// Uniform panels of at most `h` over `[a, b]`.
fn uniform(a: f64, b: f64, h: f64) -> Vec<f64> {
    let n = ((b - a) / h).ceil().max(1.0) as usize;
    (0..=n).map(|k| a + (b - a) * k as f64 / n as f64).collect()
}

/// The brute force: plain `t` (no change of variables), panels graded geometrically towards the
/// light's closest point (`t_l +- D 2^k`) and 0.25 wide elsewhere; both optical depths integrated
/// from scratch at every node with 0.5-wide panels.
fn brute(bed: &MediumBed, ray: &MediumRay, light: &PointLight) -> f64 {
    let Some((t0, t1)) = clip_sphere(ray.origin, ray.dir) else { return 0.0 };
    let t1 = t1.min(ray.length);
    let (t_l, d) = light.closest_approach(ray.origin, ray.dir);
    let mut breaks = uniform(t0, t1, 0.25);
    for k in 0..60 {
        let step = d * 2f64.powi(k);
        breaks.extend([t_l - step, t_l + step].into_iter().filter(|t| (t0..=t1).contains(t)));
    }
    breaks.push(t_l.clamp(t0, t1));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let depth = |o: Vec3, w: Vec3, a: f64, b: f64| composite(|s| bed.extinction(o + w * s), &uniform(a, b, 0.5));
    composite(
        |t| {
            let p = ray.origin + ray.dir * t;
            let to = light.position - p;
            let r = to.length();
            let tau_l = clip_sphere(p, to / r).map_or(0.0, |(a, b)| depth(p, to / r, a, b.min(r)));
            let tau_c = depth(ray.origin, ray.dir, t0, t);
            let cos = (p - light.position).normalize().dot(-ray.dir);
            (-tau_c - tau_l).exp()
                * bed.albedo()
                * bed.extinction(p)
                * mcbench_core::phase::Phase::Rayleigh.eval(cos)
                * light.intensity
                / (r * r)
        },
        &breaks,
    )
}

fn ray_of(bed: &MediumBed, i: usize) -> (MediumRay, PointLight) {
    let ray = bed.ray(i);
    let MediumQuantity::SingleScatter { light } = ray.quantity else { panic!("not a single-scatter ray") };
    (ray, light)
}

/// Eq. 21: the nested quadrature agrees with the brute force within its bound, and the bound is
/// below 1e-9 relative, for the default light near and far from the pixel ray, the light at the
/// sphere's boundary, in the densest region (sigma_t = 1 at z = pi, x + y + z = 4 pi / 3), and at
/// distance 1e-4 from a pixel ray (the peak 1/(D^2 + (t - t_l)^2) is then 1e8 high).
#[test]
fn eq21_reference_is_within_its_bound_of_a_brute_force() {
    let pi = std::f64::consts::PI;
    let cases: [(Params, usize); 5] = [
        (Params::new().with("resolution", 32.0), 16 * 32 + 16),
        (Params::new().with("resolution", 32.0), 10 * 32 + 3),
        (Params::new().with("resolution", 32.0).with("light_z", 20.0), 16),
        (Params::new().with("resolution", 8.0).with("light_x", 4.0 * pi / 3.0 - pi).with("light_z", pi), 6 * 8 + 4),
        // Pixel 5 of a 4x4 image looks along x = -2.5, z = 12.5.
        (Params::new().with("resolution", 4.0).with("light_x", -2.5 + 1e-4).with("light_z", 12.5), 5),
    ];
    for (params, i) in cases {
        let bed = MediumBed::without_reference(Field::Eq21, "single-scatter", &params).unwrap();
        let (ray, light) = ray_of(&bed, i);
        let q = single_scatter(&bed, &ray, &light, &Settings::of(Field::Eq21));
        let b = brute(&bed, &ray, &light);
        assert!(q.value > 0.0, "{params:?}: {q:?}");
        assert!((q.value - b).abs() <= q.bound + 1e-13 * b, "{params:?} pixel {i}: {q:?} vs brute force {b}");
        assert!(q.bound <= 1e-9 * q.value, "{params:?} pixel {i}: bound {:e} of {}", q.bound, q.value);
    }
}

/// Perlin's settings on a short piece of ray near the light: within their bound of a computation
/// with 4x finer initial panels and 100x tighter tolerances, and the bound is below 1e-3 relative.
#[test]
fn perlin_settings_are_within_their_bound_on_a_short_segment() {
    let bed =
        MediumBed::without_reference(Field::Perlin, "single-scatter", &Params::new().with("resolution", 2.0)).unwrap();
    // A dense spot of the Perlin medium (sigma_t about 0.7 at (-5, 0.15, 6)).
    let light = PointLight { position: Vec3::new(-4.8, 0.3, 6.1), intensity: 100.0 };
    let ray = MediumRay {
        origin: Vec3::new(-5.0, 0.0, 6.0),
        dir: Vec3::new(0.0, 1.0, 0.0),
        length: 0.15,
        quantity: MediumQuantity::SingleScatter { light },
    };
    let coarse = single_scatter(&bed, &ray, &light, &Settings::of(Field::Perlin));
    let fine = single_scatter(&bed, &ray, &light, &Settings { per_unit: 64.0, tau_tol: 1e-6, rel_tol: 1e-6 });
    assert!(coarse.value > 0.0);
    assert!((coarse.value - fine.value).abs() <= coarse.bound + fine.bound, "{coarse:?} vs {fine:?}");
    assert!(coarse.bound <= 1e-3 * coarse.value, "{coarse:?}");
}

/// The default Perlin image loads its stored reference (computing it takes minutes) made with
/// the current settings, and its bound is below 1e-3 of the brightest pixel.
#[test]
fn perlin_default_reference_is_stored_with_the_current_settings() {
    let bed = MediumBed::without_reference(Field::Perlin, "single-scatter", &Params::new()).unwrap();
    let r = load_stored(&bed, &crate::built_in_references::BUILT_IN)
        .unwrap()
        .expect("estimators/references/perlin-medium_single-scatter.json");
    let ReferenceKind::Exact { bound, .. } = r.kind else { panic!("not exact") };
    let brightest = r.value.iter().map(|v| v[0]).fold(0.0f64, f64::max);
    assert!(brightest > 0.0 && bound <= 1e-3 * brightest, "bound {bound:e}, brightest {brightest}");
    assert!(r.value.iter().all(|v| v.is_finite()));
}

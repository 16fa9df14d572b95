//! Uniform points on a rectangular area light converted to a density per unit solid angle at the
//! shading point (paper 003's light component `h_light`, Eq. 7): a point `y` with area density
//! `1 / A` seen from `x` at distance `d` under `cos(theta_y)` has solid-angle density
//! `d^2 / (A cos(theta_y))`.

use crate::brdf::DirectionSample;
use crate::lighting::RectLight;
use crate::math::Vec3;
use rand::Rng;

/// A direction from `p` towards a uniform point on `light`, with its solid-angle density.
/// `p` must lie below the light's plane (every point of the floor scenes does).
pub fn sample<R: Rng + ?Sized>(light: &RectLight, p: Vec3, rng: &mut R) -> DirectionSample {
    let (u, v): (f64, f64) = (rng.gen(), rng.gen());
    let y = Vec3::new(
        light.min[0] + u * (light.max[0] - light.min[0]),
        light.min[1] + v * (light.max[1] - light.min[1]),
        light.z,
    );
    let d = y - p;
    let w = d.normalize();
    DirectionSample { w, pdf: pdf(light, p, w) }
}

/// The solid-angle density of [`sample`] at the unit direction `w` (zero off the light).
pub fn pdf(light: &RectLight, p: Vec3, w: Vec3) -> f64 {
    match light.hit(p, w) {
        // The light faces -z, so cos(theta_y) = w.z > 0 wherever the ray hits it.
        Some(t) => t * t / (light.area() * w.z),
        None => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rgb;
    use crate::quadrature::gauss_legendre;
    use crate::rng::stream;
    use crate::samplers::testing::sampler_alpha;
    use crate::stats::chi_square_gof;

    /// Chi-square in the light's own plane: directions are binned by where they cross it (an
    /// `nx x ny` grid aligned with the rectangle) and each cell's probability is the integral of
    /// the reported solid-angle pdf over the cell, `int pdf(w(y)) cos(theta_y) / d^2 dA`
    /// (12 x 12 Gauss-Legendre). A wrong distance or cosine factor shows up as a gradient.
    fn check(light: &RectLight, p: Vec3, seed: u64) {
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
                        acc += wi * wj * pdf(light, p, dir) * dir.z / d.dot(d);
                    }
                }
                probs.push(acc * 0.25 * dx * dy);
            }
        }
        let inside: f64 = probs.iter().sum();
        assert!((inside - 1.0).abs() < 1e-9, "pdf integrates to {inside} over the light");
        probs.push(0.0);
        let mut rng = stream(seed, "rect light chi-square");
        let mut counts = vec![0u64; nx * ny + 1];
        for _ in 0..100_000 {
            let s = sample(light, p, &mut rng);
            let cell = light.hit(p, s.w).map(|t| {
                let h = p + s.w * t;
                let ix = (((h.x - light.min[0]) / dx) as usize).min(nx - 1);
                let iy = (((h.y - light.min[1]) / dy) as usize).min(ny - 1);
                iy * nx + ix
            });
            counts[cell.unwrap_or(nx * ny)] += 1;
        }
        let c = chi_square_gof(&counts, &probs).unwrap();
        assert!(
            c.p_value > sampler_alpha(),
            "rect light: chi-square {} on {} dof, p = {:e}",
            c.statistic,
            c.dof,
            c.p_value
        );
    }

    #[test]
    fn chi_square_rect_lights_solid_angle() {
        // The checker scene's large dim light seen obliquely, and the small bright one nearby.
        check(&RectLight::centred(-1.0, 2.5, 2.0, 2.0, 1.0, Rgb::splat(3.0)), Vec3::new(0.3, -0.5, 0.0), 21);
        check(&RectLight::centred(1.0, 1.8, 1.2, 0.15, 0.15, Rgb::splat(400.0)), Vec3::new(0.9, 1.7, 0.0), 22);
    }
}

//! The PMC-HI mixture kernel (paper 003 Eq. 7): one BRDF component, one component per light and
//! the cone component,
//! `K(w) = alpha_BRDF h_BRDF(w) + sum_l alpha_l h_l(w) + alpha_cone h_cone(w | d, beta)`.
//! Component order: 0 = BRDF, 1..=L = lights, L + 1 = cone.

use mcbench_core::lighting::RectLight;
use mcbench_core::math::{Frame, Vec3};
use mcbench_core::samplers::{cone, rect_light};
use mcbench_core::testbed::ShadingPoint;
use rand::Rng;

/// Parameters of the cone component: unit axis `d` and `cos(beta)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Axis.
    pub axis: Vec3,
    /// Cosine of the half-angle.
    pub cos_max: f64,
}

/// The kernel at one shading point.
pub struct Kernel<'a> {
    point: &'a ShadingPoint,
    lights: &'a [RectLight],
    /// Mixture weights, one per component (sum 1).
    pub alpha: Vec<f64>,
    /// The cone's parameters (its weight is zero without them).
    pub cone: Option<Cone>,
}

impl<'a> Kernel<'a> {
    /// A kernel with the given weights (length `lights.len() + 2`).
    pub fn new(point: &'a ShadingPoint, lights: &'a [RectLight], alpha: Vec<f64>, cone: Option<Cone>) -> Self {
        Kernel { point, lights, alpha, cone }
    }
    /// Number of components `m = L + 2`.
    pub fn components(&self) -> usize {
        self.lights.len() + 2
    }
    /// Index of the cone component.
    pub fn cone_index(&self) -> usize {
        self.lights.len() + 1
    }
    /// A direction from component `k`.
    pub fn sample<R: Rng + ?Sized>(&self, k: usize, rng: &mut R) -> Vec3 {
        let p = self.point;
        if k == 0 {
            p.brdf.sample(p.wo, p.normal, rng).w
        } else if k <= self.lights.len() {
            rect_light::sample(&self.lights[k - 1], p.position, rng).w
        } else {
            let c = self.cone.expect("the cone is sampled only when it has parameters");
            Frame::around(c.axis).to_world(cone::sample_local(c.cos_max, rng))
        }
    }
    /// The density of component `k` at `w` (per unit solid angle).
    pub fn component_pdf(&self, k: usize, w: Vec3) -> f64 {
        let p = self.point;
        if k == 0 {
            p.brdf.pdf(w, p.wo, p.normal)
        } else if k <= self.lights.len() {
            rect_light::pdf(&self.lights[k - 1], p.position, w)
        } else {
            self.cone.map_or(0.0, |c| cone::pdf(c.axis.dot(w), c.cos_max))
        }
    }
    /// The full mixture density `K(w)` (paper 003 Eq. 8's denominator).
    pub fn pdf(&self, w: Vec3) -> f64 {
        (0..self.components()).filter(|&k| self.alpha[k] > 0.0).map(|k| self.alpha[k] * self.component_pdf(k, w)).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::brdf::Phong;
    use mcbench_core::math::Rgb;
    use mcbench_core::samplers::mixture::dms_counts;
    use mcbench_core::samplers::testing::{assert_sampler_fits, SphereGrid};

    fn scene() -> (ShadingPoint, [RectLight; 2]) {
        let point = ShadingPoint {
            position: Vec3::new(0.2, -0.3, 0.0),
            normal: Vec3::Z,
            wo: Vec3::new(0.0, -0.6, 0.8),
            brdf: Phong { kd: Rgb::splat(0.05), ks: Rgb::splat(0.8), n: 40.0 },
        };
        let lights = [
            RectLight::centred(-1.0, 1.8, 2.0, 2.0, 1.0, Rgb::splat(3.0)),
            RectLight::centred(1.0, 0.9, 1.2, 0.15, 0.15, Rgb::splat(400.0)),
        ];
        (point, lights)
    }

    /// DMS draws from the BRDF + cone part of the kernel follow `K` (the light components have
    /// their own chi-square in the light plane, `samplers::rect_light`).
    #[test]
    fn chi_square_pmc_hi_kernel_brdf_and_cone() {
        let (point, lights) = scene();
        let cos_max = 0.4f64.cos();
        let k = Kernel::new(&point, &lights, vec![0.6, 0.0, 0.0, 0.4], Some(Cone { axis: Vec3::Z, cos_max }));
        let mut edges: Vec<f64> = (0..=24).map(|i| -1.0 + 2.0 * i as f64 / 24.0).collect();
        edges.push(cos_max);
        edges.sort_by(f64::total_cmp);
        let grid = SphereGrid::with_cos_edges(edges, 24);
        let mut queue = Vec::new();
        assert_sampler_fits(
            "PMC-HI kernel (DMS)",
            &grid,
            100_000,
            51,
            |r| {
                if queue.is_empty() {
                    for (c, n) in dms_counts(&k.alpha, 8, r).into_iter().enumerate() {
                        for _ in 0..n {
                            queue.push(k.sample(c, r));
                        }
                    }
                }
                queue.pop().unwrap_or(Vec3::Z)
            },
            |d| k.pdf(d),
        );
    }

    /// With all components, `E_K[h_j / K] = 1` for every component `j` (each `h_j` integrates to 1
    /// where `K > 0`): a z-test per component on draws from the full kernel.
    #[test]
    fn every_component_density_integrates_to_one_under_the_full_kernel() {
        let (point, lights) = scene();
        let cone = Some(Cone { axis: Vec3::new(0.2, 0.3, 0.9).normalize(), cos_max: 0.3f64.cos() });
        let k = Kernel::new(&point, &lights, vec![0.3, 0.3, 0.2, 0.2], cone);
        let mut rng = mcbench_core::rng::stream(52, "kernel");
        let mut m = vec![mcbench_core::stats::Moments::default(); 4];
        for _ in 0..20_000 {
            for (c, n) in dms_counts(&k.alpha, 8, &mut rng).into_iter().enumerate() {
                for _ in 0..n {
                    let w = k.sample(c, &mut rng);
                    let kk = k.pdf(w);
                    assert!(kk > 0.0 && k.component_pdf(c, w) > 0.0);
                    for (j, mj) in m.iter_mut().enumerate() {
                        mj.push(k.component_pdf(j, w) / kk);
                    }
                }
            }
        }
        for (j, mj) in m.iter().enumerate() {
            let z = (mj.mean() - 1.0) / mj.std_err();
            assert!(z.abs() < 4.0, "component {j}: mean {} se {}", mj.mean(), mj.std_err());
        }
    }
}

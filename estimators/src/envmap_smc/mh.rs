//! The Metropolis-Hastings kernel of paper 004 §3 Step 2 (Eq. 6-8): a mixture of a local random
//! walk (a direction uniform in a cone of a few degrees about the current one: symmetric, so the
//! acceptance is `min(1, p~(w') / p~(w))`, Eq. 7) and an independent proposal from the environment
//! map (`min(1, p~(w') q(w) / (p~(w) q(w')))`, Eq. 8, written with the proposal density so it
//! holds for any map sampler). Each component leaves the target invariant, hence so does their
//! state-independent mixture. Targets are given in log space; a proposal with zero target is
//! rejected, and a reverse move of zero density makes the acceptance zero.

use mcbench_core::brdf::DirectionSample;
use mcbench_core::envmap::EnvFrame;
use mcbench_core::math::{Frame, Vec3};
use mcbench_core::samplers::spherical_direction;
use rand::Rng;
use std::f64::consts::TAU;

/// An independent proposal over directions with its density.
///
/// ```
/// use mcbench_core::brdf::DirectionSample;
/// use mcbench_core::math::Vec3;
/// use mcbench_papers::envmap_smc::mh::Proposal;
///
/// /// Directions uniform on the sphere.
/// struct Sphere;
/// impl Proposal for Sphere {
///     fn draw(&self, rng: &mut dyn rand::RngCore) -> DirectionSample {
///         use rand::Rng;
///         let (z, phi): (f64, f64) = (rng.gen_range(-1.0..1.0), rng.gen_range(0.0..std::f64::consts::TAU));
///         let r = (1.0 - z * z).sqrt();
///         DirectionSample { w: Vec3::new(r * phi.cos(), r * phi.sin(), z), pdf: self.density(Vec3::Z) }
///     }
///     fn density(&self, _w: Vec3) -> f64 {
///         1.0 / (4.0 * std::f64::consts::PI)
///     }
/// }
///
/// let mut rng = mcbench_core::rng::stream(3, "sphere");
/// let s = Sphere.draw(&mut rng);
/// assert!((s.w.dot(s.w) - 1.0).abs() < 1e-12 && s.pdf > 0.0);
/// ```
pub trait Proposal {
    /// Draws a direction.
    fn draw(&self, rng: &mut dyn rand::RngCore) -> DirectionSample;
    /// Its density per unit solid angle.
    fn density(&self, w: Vec3) -> f64;
}

impl Proposal for EnvFrame<'_> {
    fn draw(&self, rng: &mut dyn rand::RngCore) -> DirectionSample {
        self.sample(rng)
    }
    fn density(&self, w: Vec3) -> f64 {
        self.pdf(w)
    }
}

/// One chain state: the direction, `log p~` there, and whatever the caller keeps with it (the
/// per-channel products of two frames, for bridges).
#[derive(Clone, Debug, PartialEq)]
pub struct State<P> {
    /// Direction.
    pub w: Vec3,
    /// Log of the (unnormalised) target at `w`.
    pub log_target: f64,
    /// Caller data evaluated with the target.
    pub payload: P,
}

/// The mixture kernel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MhKernel {
    /// Cosine of the half-angle of the local cone.
    pub cos_cone: f64,
    /// Probability of an independent environment-map proposal (else a local move).
    pub p_independent: f64,
}

impl MhKernel {
    /// A kernel with a cone of `cone_degrees` and independent-move probability `p_independent`.
    pub fn new(cone_degrees: f64, p_independent: f64) -> Self {
        MhKernel { cos_cone: cone_degrees.to_radians().cos(), p_independent }
    }

    /// One MH transition of `x` for the target evaluated by `eval` (returns `(log p~, payload)`
    /// and counts one sample per call through the caller's probe). Returns whether it moved.
    pub fn step<P, R: Rng>(
        &self,
        x: &mut State<P>,
        proposal: &dyn Proposal,
        rng: &mut R,
        eval: &mut dyn FnMut(Vec3) -> (f64, P),
    ) -> bool {
        let independent = rng.gen::<f64>() < self.p_independent;
        let (w_new, log_q_ratio) = if independent {
            let s = proposal.draw(rng);
            let q_back = proposal.density(x.w);
            if q_back <= 0.0 && x.log_target > f64::NEG_INFINITY {
                return false; // the reverse move is impossible: acceptance 0
            }
            (s.w, q_back.ln() - s.pdf.ln())
        } else {
            let cos_a = 1.0 - rng.gen::<f64>() * (1.0 - self.cos_cone);
            let local = spherical_direction(cos_a, TAU * rng.gen::<f64>());
            (Frame::around(x.w).to_world(local).normalize(), 0.0)
        };
        let (lt, payload) = eval(w_new);
        if lt == f64::NEG_INFINITY || lt.is_nan() {
            return false;
        }
        let accept = x.log_target == f64::NEG_INFINITY || {
            let log_a = lt - x.log_target + log_q_ratio;
            log_a >= 0.0 || rng.gen::<f64>().ln() < log_a
        };
        if accept {
            *x = State { w: w_new, log_target: lt, payload };
        }
        accept
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testbeds::sky::Sky;
    use mcbench_core::brdf::Phong;
    use mcbench_core::envmap::EnvMap;
    use mcbench_core::math::Rgb;
    use mcbench_core::quadrature::gauss_legendre;
    use mcbench_core::stats::chi_square_gof;
    use std::f64::consts::PI;

    /// A coarse map (cells = texels), normal +z so the shading horizon is a texel edge, a glossy
    /// Phong: the product target and its exact per-texel probabilities (8x8 sub-panels of 6x6
    /// Gauss-Legendre in (theta, phi), a smooth integrand inside each texel).
    fn setup() -> (EnvMap, Phong, Vec3, Vec<f64>, f64) {
        let map = EnvMap::tabulate(16, 8, |w| Sky::default_with_sun(30.0).radiance(w)).unwrap();
        let brdf = Phong { kd: Rgb::splat(0.3), ks: Rgb::splat(0.6), n: 20.0 };
        let wo = Vec3::new(0.3, -0.5, 0.8).normalize();
        let g = map.grid();
        let (x, wts) = gauss_legendre(6);
        let mut probs = Vec::new();
        for t in 0..g.width * g.height {
            let (i, j) = (t / g.width, t % g.width);
            let (dt, dp) = (PI / g.height as f64 / 8.0, TAU / g.width as f64 / 8.0);
            let mut s = 0.0;
            for a in 0..8 {
                for b in 0..8 {
                    for (xi, wi) in x.iter().zip(&wts) {
                        let th = i as f64 * PI / g.height as f64 + (a as f64 + 0.5 + 0.5 * xi) * dt;
                        for (xj, wj) in x.iter().zip(&wts) {
                            let ph = j as f64 * TAU / g.width as f64 + (b as f64 + 0.5 + 0.5 * xj) * dp;
                            let d = spherical_direction(th.cos(), ph);
                            s += wi * wj * 0.25 * dt * dp * th.sin() * brdf.eval(d, wo, Vec3::Z).mean() * d.z.max(0.0);
                        }
                    }
                }
            }
            probs.push(s * map.texel(t).mean());
        }
        let total: f64 = probs.iter().sum();
        let fmax = brdf.kd.mean() / PI + brdf.ks.mean() * (brdf.n + 2.0) / TAU;
        (map, brdf, wo, probs.into_iter().map(|p| p / total).collect(), fmax)
    }

    /// Runs `chains` independent chains, each started exactly from the product distribution (by
    /// rejection from the environment map: accept with `f cos / max(f cos)`), applies `steps`
    /// transitions of `kernel`, bins the final states by texel and returns the chi-square p-value.
    /// If the kernel leaves the target invariant the final states follow it exactly.
    fn invariance_p(kernel: MhKernel, steps: usize, seed: u64, broken: bool) -> f64 {
        let (map, brdf, wo, probs, fmax) = setup();
        let frame = EnvFrame { map: &map, rotation: 0.0, scale: 1.0 };
        let fcos = |d: Vec3| brdf.eval(d, wo, Vec3::Z).mean() * d.z.max(0.0);
        let mut eval = |d: Vec3| {
            let v = map.radiance(d).mean() * fcos(d);
            ((if v > 0.0 { v.ln() } else { f64::NEG_INFINITY }), ())
        };
        let mut rng = mcbench_core::rng::stream(seed, "mh invariance");
        let mut counts = vec![0u64; probs.len()];
        for _ in 0..60_000 {
            let w = loop {
                let s = frame.sample(&mut rng);
                if rng.gen::<f64>() * fmax < fcos(s.w) {
                    break s.w;
                }
            };
            let mut x = State { w, log_target: eval(w).0, payload: () };
            for _ in 0..steps {
                if broken {
                    // Independent moves accepted with the target ratio alone (Eq. 7 misused for Eq. 8).
                    let s = frame.sample(&mut rng);
                    let (lt, _) = eval(s.w);
                    if lt > f64::NEG_INFINITY && rng.gen::<f64>().ln() < lt - x.log_target {
                        x = State { w: s.w, log_target: lt, payload: () };
                    }
                } else {
                    kernel.step(&mut x, &frame, &mut rng, &mut eval);
                }
            }
            counts[map.grid().texel_of(x.w, 0.0)] += 1;
        }
        chi_square_gof(&counts, &probs).unwrap().p_value
    }

    #[test]
    fn mh_local_cone_moves_leave_the_product_invariant() {
        let p = invariance_p(MhKernel::new(20.0, 0.0), 6, 51, false);
        assert!(p > mcbench_core::samplers::testing::sampler_alpha(), "p = {p}");
    }

    #[test]
    fn mh_mixture_leaves_the_product_invariant() {
        let p = invariance_p(MhKernel::new(5.0, 0.5), 4, 52, false);
        assert!(p > mcbench_core::samplers::testing::sampler_alpha(), "p = {p}");
    }

    /// Teeth: ignoring the proposal density in Eq. 8 breaks invariance, and the test sees it.
    #[test]
    fn the_invariance_test_flags_a_broken_kernel() {
        let p = invariance_p(MhKernel::new(5.0, 1.0), 4, 53, true);
        assert!(p < 1e-6, "p = {p}");
    }
}

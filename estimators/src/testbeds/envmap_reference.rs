//! Exact references of the `envmap-sequence` test bed (book: testbeds.md): for a piecewise-constant map,
//! `L = sum over texels t of T_t * integral over t of f cos (V) dw`, so each texel's geometric
//! factor is integrated exactly or by deterministic quadrature in `(theta, phi)` with the
//! `sin(theta)` solid-angle weight:
//!
//! - the diffuse factor `integral of (w . n) dw` of texels entirely above the shading horizon in
//!   closed form (`S2 (sin phi_b - sin phi_a), S2 (cos phi_a - cos phi_b), S1 dphi`);
//! - the Phong lobe `(r . w)^n (w . n)` by Gauss-Legendre per texel (5x5 near the lobe, 3x3 in its
//!   tail, the centre value far out), texels whose lobe bound is below `1e-18` of the pixel's scale
//!   skipped with that bound added to the error bound;
//! - texels crossed by the shading horizon (the kink of `max(0, cos)`) split in `phi` at the
//!   points where the horizon crosses the texel's `theta` edges, and integrated in `theta` only over
//!   the lit part, so every panel is smooth (6x6 Gauss-Legendre).
//!
//! Visibility (an infinite ground plane at z = -1, `V = 1` iff `w_z >= 0`) coincides with the
//! equator, a row edge of every map with an even number of rows. A wall beside the sphere (the
//! `-wall` variants) hides the directions on one side of a great circle through each shading
//! point; texels it crosses are split in `phi` where it crosses their `theta` edges and integrated
//! in `theta` over the visible part, as at the horizon (checked at 1e-5 relative, the brute
//! force's own accuracy at that kink).
//!
//! The rigorous part of the bound is the skipped mass; the quadrature's own error is stated as
//! 1e-7 relative, the level at which the tests check it against a brute-force quadrature with 16x
//! more panels per texel (the bound is 1e-9: the rules used should reach it on smooth
//! texels, but the brute force cannot show it, so it is not claimed).

use mcbench_core::brdf::Phong;
use mcbench_core::envmap::EnvFrame;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::quadrature::gauss_legendre;
use mcbench_core::testbed::ShadingPoint;
use std::f64::consts::{PI, TAU};

/// Relative quadrature accuracy promised beyond the skipped mass (the level the tests check).
pub const QUADRATURE_REL_ERROR: f64 = 1e-7;
/// The same with a wall: its panels are split like the horizon's, but the brute force the tests
/// compare with converges only to first order at the wall's kink (to about 3e-6), so this is the
/// level checked.
pub const WALL_QUADRATURE_REL_ERROR: f64 = 1e-5;

/// Per-texel precomputation shared by every pixel and frame of a map grid.
pub struct TexelTable {
    width: usize,
    height: usize,
    centre: Vec<Vec3>,
    radius: Vec<f64>,
    moment: Vec<Vec3>,
    rules: Vec<(Vec<f64>, Vec<f64>)>,
}

/// The reference of one pixel in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelReference {
    /// Unoccluded reflected radiance `L_ns`.
    pub lns: Rgb,
    /// Reflected radiance with visibility `L_r`.
    pub lr: Rgb,
    /// Absolute error bound (largest over channels, both quantities).
    pub bound: f64,
}

impl TexelTable {
    /// Precomputes texel centres, angular radii and first moments for a map grid.
    pub fn new(width: usize, height: usize) -> Self {
        let (dt, dp) = (PI / height as f64, TAU / width as f64);
        let (mut centre, mut radius, mut moment) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..height {
            let (ta, tb) = (i as f64 * dt, (i + 1) as f64 * dt);
            let s2 = (tb - ta) / 2.0 - ((2.0 * tb).sin() - (2.0 * ta).sin()) / 4.0;
            let s1 = (tb.sin().powi(2) - ta.sin().powi(2)) / 2.0;
            let smax = if ta <= PI / 2.0 && tb >= PI / 2.0 { 1.0 } else { ta.sin().max(tb.sin()) };
            for j in 0..width {
                let (pa, pb) = (j as f64 * dp, (j + 1) as f64 * dp);
                let (tm, pm) = (0.5 * (ta + tb), 0.5 * (pa + pb));
                centre.push(Vec3::new(tm.sin() * pm.cos(), tm.sin() * pm.sin(), tm.cos()));
                radius.push(0.5 * (dt + dp * smax) * 1.01);
                moment.push(Vec3::new(s2 * (pb.sin() - pa.sin()), s2 * (pa.cos() - pb.cos()), s1 * dp));
            }
        }
        let rules = (0..=8).map(gauss_legendre).collect();
        TexelTable { width, height, centre, radius, moment, rules }
    }

    fn edges(&self, t: usize) -> (f64, f64, f64, f64) {
        let (i, j) = (t / self.width, t % self.width);
        let (dt, dp) = (PI / self.height as f64, TAU / self.width as f64);
        (i as f64 * dt, (i + 1) as f64 * dt, j as f64 * dp, (j + 1) as f64 * dp)
    }

    /// `(diffuse, lobe)` factors of one texel by `q x q` Gauss-Legendre on `[ta, tb] x [pa, pb]`,
    /// clipping `theta` to the lit side (`w . c >= 0`) of the great circle of each `c` in `clips`
    /// (the shading horizon of `n`, a wall's silhouette), with `phi` panels split where each
    /// circle crosses the `theta` edges, so every panel is smooth.
    #[allow(clippy::too_many_arguments)]
    fn quad(
        &self,
        (ta, tb, pa, pb): (f64, f64, f64, f64),
        n: Vec3,
        r: Vec3,
        e: f64,
        q: usize,
        clips: &[Vec3],
        lobe_only: bool,
    ) -> (f64, f64) {
        let mut cuts = vec![pa, pb];
        for c in clips {
            let rho = (c.x * c.x + c.y * c.y).sqrt();
            let pn = c.y.atan2(c.x);
            for th in [ta, tb] {
                let s = th.sin();
                if rho > 0.0 && s > 0.0 {
                    let arg = -c.z * th.cos() / (s * rho);
                    if arg.abs() <= 1.0 {
                        let a = arg.acos();
                        for phi in [pn + a, pn - a] {
                            for k in -1..=1 {
                                let p = phi + k as f64 * TAU;
                                if p > pa && p < pb {
                                    cuts.push(p);
                                }
                            }
                        }
                    }
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        let (x, w) = &self.rules[q];
        let (mut d, mut l) = (0.0, 0.0);
        for pair in cuts.windows(2) {
            let (p0, p1) = (pair[0], pair[1]);
            'node: for (xp, wp) in x.iter().zip(w) {
                let phi = 0.5 * (p0 + p1) + 0.5 * (p1 - p0) * xp;
                let (sp, cp) = phi.sin_cos();
                let (mut t0, mut t1) = (ta, tb);
                for c in clips {
                    // w . c = a sin(theta) + b cos(theta) has at most one root in a texel row.
                    let (a, b) = (c.x * cp + c.y * sp, c.z);
                    let g = |t: f64| a * t.sin() + b * t.cos();
                    let (g0, g1) = (g(ta), g(tb));
                    if g0 <= 0.0 && g1 <= 0.0 {
                        continue 'node;
                    }
                    if g0 < 0.0 || g1 < 0.0 {
                        let root = (-b).atan2(a).rem_euclid(PI).clamp(ta, tb);
                        if g0 < 0.0 {
                            t0 = t0.max(root);
                        } else {
                            t1 = t1.min(root);
                        }
                    }
                }
                if t1 <= t0 {
                    continue;
                }
                let jac = 0.25 * (p1 - p0) * (t1 - t0) * wp;
                for (xt, wt) in x.iter().zip(w) {
                    let th = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * xt;
                    let (st, ct) = th.sin_cos();
                    let dir = Vec3::new(st * cp, st * sp, ct);
                    let cos = dir.dot(n).max(0.0);
                    let rw = dir.dot(r);
                    let lobe = if rw > 0.0 { rw.powf(e) } else { 0.0 };
                    let m = jac * wt * st * cos;
                    if !lobe_only {
                        d += m;
                    }
                    l += m * lobe;
                }
            }
        }
        (d, l)
    }

    /// The texels of the grid, `width x height`.
    pub fn texels(&self) -> usize {
        self.width * self.height
    }

    /// The geometric factor `integral of f cos dw` of the grey Phong BRDF `brdf` (channel means
    /// of `kd` and `ks`) at normal `n` and mirror direction `r`, over the part of texel `t` with
    /// `phi` in `[pa, pb]` (inside the texel's own `phi` range): the diffuse factor in closed form
    /// above the shading horizon, the lobe by Gauss-Legendre at the orders [`TexelTable::reflect`]
    /// uses, texels crossed by the horizon split there. `None` when the texel lies below the
    /// horizon. Nothing is skipped: the expected effective sample size needs every texel.
    pub fn panel_factor(&self, t: usize, (pa, pb): (f64, f64), n: Vec3, r: Vec3, brdf: &Phong) -> Option<f64> {
        let (c, rad) = (self.centre[t], self.radius[t]);
        let dn = c.dot(n);
        if dn < -rad.sin() || pb <= pa {
            return None;
        }
        let (ta, tb, _, _) = self.edges(t);
        let e = brdf.n;
        let (kd, ks) = (brdf.kd.mean() / PI, brdf.ks.mean() * (e + 2.0) / TAU);
        let ca = c.dot(r).clamp(-1.0, 1.0);
        let (cr, sr) = (rad.cos(), rad.sin());
        let cos_min = if ca >= cr { 1.0 } else { ca * cr + (1.0 - ca * ca).sqrt() * sr };
        let lobe_bound = if ks > 0.0 && cos_min > 0.0 { cos_min.powf(e) } else { 0.0 };
        let q = if lobe_bound > 1e-3 {
            5
        } else if lobe_bound > 1e-9 {
            3
        } else {
            1
        };
        let (d, l) = if dn <= rad.sin() {
            self.quad((ta, tb, pa, pb), n, r, e, 6, &[n], kd == 0.0)
        } else {
            let s2 = (tb - ta) / 2.0 - ((2.0 * tb).sin() - (2.0 * ta).sin()) / 4.0;
            let s1 = (tb.sin().powi(2) - ta.sin().powi(2)) / 2.0;
            let moment = Vec3::new(s2 * (pb.sin() - pa.sin()), s2 * (pa.cos() - pb.cos()), s1 * (pb - pa));
            let l = if lobe_bound > 0.0 { self.quad((ta, tb, pa, pb), n, r, e, q, &[], true).1 } else { 0.0 };
            (moment.dot(n), l)
        };
        Some(kd * d + ks * l)
    }

    /// The `phi` edges of texel `t`.
    pub fn phi_edges(&self, t: usize) -> (f64, f64) {
        let (_, _, pa, pb) = self.edges(t);
        (pa, pb)
    }

    /// The references `L_ns` and `L_r` of shading point `p` under the frame's map (texels scaled by
    /// `env.scale` and rotated by `env.rotation` about +z; equivalently, the shading point rotated
    /// by `-rotation`). `L_r` sees the sky above the ground plane (`w_z >= 0`) and, with `wall`,
    /// only where `w . wall >= 0`: a wall's silhouette seen from `p` is a great circle
    /// ([`super::envmap_sequence::wall_normal`]), split at like the shading horizon.
    pub fn reflect(&self, env: EnvFrame<'_>, p: &ShadingPoint, wall: Option<Vec3>) -> PixelReference {
        let (map, rotation, scale, brdf) = (env.map, env.rotation, env.scale, &p.brdf);
        let rot = |v: Vec3| {
            let (s, c) = (-rotation).sin_cos();
            Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
        };
        let (n, wo) = (rot(p.normal), rot(p.wo));
        let wall = wall.map(rot);
        let r = wo.reflect(n);
        let e = brdf.n;
        let norm = (e + 2.0) / TAU;
        let has_diffuse = brdf.kd.0.iter().any(|&k| k != 0.0);
        let has_lobe = brdf.ks.0.iter().any(|&k| k != 0.0);
        // Scale of the answer for the skip threshold: the brightest texel times the lobe mass.
        let tmax = map.texels().iter().map(|t| t.mean()).fold(0.0, f64::max);
        let skip_below = 1e-18 * tmax.max(1e-300) * 4.0 * PI;
        let half = self.height / 2;
        let (mut lns_d, mut lns_s, mut lr_d, mut lr_s) = (Rgb::ZERO, Rgb::ZERO, Rgb::ZERO, Rgb::ZERO);
        let mut skipped = 0.0;
        for t in 0..self.width * self.height {
            let c = self.centre[t];
            let rad = self.radius[t];
            let dn = c.dot(n);
            if dn < -rad.sin() {
                continue;
            }
            let value = map.texel(t) * scale;
            let crossing = dn <= rad.sin();
            // cos of the smallest angle between the mirror direction and the texel.
            let ca = c.dot(r).clamp(-1.0, 1.0);
            let (cr, sr) = (rad.cos(), rad.sin());
            let cos_min = if ca >= cr { 1.0 } else { ca * cr + (1.0 - ca * ca).sqrt() * sr };
            let lobe_bound = if has_lobe && cos_min > 0.0 { cos_min.powf(e) } else { 0.0 };
            let area = rad * rad * 4.0;
            let (d, l) = if crossing {
                self.quad(self.edges(t), n, r, e, 6, &[n], !has_diffuse)
            } else {
                let d = if has_diffuse { self.moment[t].dot(n) } else { 0.0 };
                let l = if lobe_bound * norm * value.mean() * area < skip_below {
                    skipped += lobe_bound * norm * value.0.iter().fold(0.0f64, |a, &b| a.max(b)) * area;
                    0.0
                } else {
                    let q = if lobe_bound > 1e-3 {
                        5
                    } else if lobe_bound > 1e-9 {
                        3
                    } else {
                        1
                    };
                    self.quad(self.edges(t), n, r, e, q, &[], true).1
                };
                (d, l)
            };
            lns_d += value * d;
            lns_s += value * l;
            if t / self.width >= half {
                continue;
            }
            let (d, l) = match wall {
                Some(m) if c.dot(m) < -rad.sin() => continue,
                Some(m) if c.dot(m) <= rad.sin() => self.quad(self.edges(t), n, r, e, 6, &[n, m], !has_diffuse),
                _ => (d, l),
            };
            lr_d += value * d;
            lr_s += value * l;
        }
        let lns = brdf.kd * (1.0 / PI) * lns_d + brdf.ks * norm * lns_s;
        let lr = brdf.kd * (1.0 / PI) * lr_d + brdf.ks * norm * lr_s;
        let kmax = brdf.ks.0.iter().fold(0.0f64, |a, &b| a.max(b));
        let big = lns.0.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        let rel = if wall.is_some() { WALL_QUADRATURE_REL_ERROR } else { QUADRATURE_REL_ERROR };
        PixelReference { lns, lr, bound: kmax * skipped + rel * big }
    }
}

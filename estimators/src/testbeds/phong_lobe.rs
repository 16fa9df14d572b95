//! Reference moments of the horizon-clipped modified-Phong lobe (glossy part of `gradient-plane`).
//!
//! The lobe around the unit axis `r` is `L(w) = (n + 2) / (2 pi) max(0, r . w)^n`; the surface
//! normal is `+z` and only `w.z >= 0` is integrated. [`clipped_lobe_moments`] returns
//! `i0 = int L w.z`, `iz = int L w.z^2` and `ix = int L w.x w.z`, so that a background
//! `c0 + c1 w.z + c2 w.x` reflects `ks (c0 i0 + c1 iz + c2 ix)`.
//!
//! Method (deterministic): in the lobe frame `w = cos(a) r + sin(a) (cos(p) u + sin(p) v)` with
//! `u` in the plane of `r` and `+z` (so `v.z = 0`), the clip `w.z >= 0` is `|p| <= P(a)` with
//! `cos P = -r.z cos(a) / (|r_xy| sin(a))` once `a` exceeds the elevation `e` of `r` (the cone of
//! half-angle `a <= e` is entirely above the horizon). The `p`-integrals are closed form; the
//! remaining integral over `a in [0, pi/2]` of `(n + 2)/(2 pi) cos(a)^n sin(a) inner(a)` is done by
//! adaptive Gauss-Kronrod, split at `a = e`, with `a = e + tau^2` beyond the kink (which removes
//! the square-root behaviour of `P` there) and extra breakpoints at `2^k / sqrt(n + 2)` to resolve
//! the peak of width `~ 1 / sqrt(n)` for large exponents. `cos(a)^n` is evaluated as
//! `exp(n ln_1p(-2 sin^2(a / 2)))`, accurate to a few ulps even for `n = 10^4`.

use mcbench_core::math::Vec3;
use mcbench_core::quadrature::gauss_kronrod_multi;
use std::f64::consts::{FRAC_PI_2, PI};

/// Internal relative tolerance to use when callers need the glossy reference to `1e-9`.
pub const DEFAULT_REL_TOL: f64 = 1e-12;

/// Bisection depth limit handed to the quadrature.
const MAX_DEPTH: usize = 50;

/// Horizon-clipped moments of the normalised modified-Phong lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeMoments {
    /// `int_{w.z >= 0} L(w) w.z dw`.
    pub i0: f64,
    /// `int_{w.z >= 0} L(w) w.z^2 dw`.
    pub iz: f64,
    /// `int_{w.z >= 0} L(w) w.x w.z dw`.
    pub ix: f64,
    /// Bound on the largest absolute error of `i0`, `iz` and `ix` (the quadrature's conservative
    /// `|K15 - G7|` estimate plus a round-off allowance).
    pub error: f64,
}

/// The lobe axis and exponent with the frame quantities the integrand needs.
#[derive(Clone, Copy, Debug)]
struct Lobe {
    /// Axis components (normalised).
    rx: f64,
    rz: f64,
    /// `|r_xy| = cos(e)` and the elevation `e = atan2(r.z, |r_xy|)`.
    sr: f64,
    e: f64,
    /// `u.x` of the tangent `u = (z - r.z r) / |r_xy|` (`u.z = sr`).
    ux: f64,
    /// Exponent and normalisation `(n + 2) / (2 pi)`.
    n: f64,
    norm: f64,
}

impl Lobe {
    /// Builds the frame; `None` for a zero or non-finite axis or a negative or non-finite `n`.
    fn new(r: Vec3, n: f64) -> Option<Lobe> {
        let len = r.length();
        if !(len > 0.0 && len.is_finite() && n >= 0.0 && n.is_finite()) {
            return None;
        }
        let r = r / len;
        let sr = r.x.hypot(r.y);
        let ux = if sr > 0.0 { -r.z * r.x / sr } else { 1.0 };
        let norm = (n + 2.0) / (2.0 * PI);
        Some(Lobe { rx: r.x, rz: r.z, sr, e: r.z.atan2(sr), ux, n, norm })
    }

    /// `(n + 2)/(2 pi) cos(a)^n sin(a)` (zero from `a = pi/2` on).
    fn weight(&self, a: f64) -> f64 {
        let h = (0.5 * a).sin();
        let one_minus_cos = 2.0 * h * h;
        let pow = if one_minus_cos >= 1.0 {
            if self.n == 0.0 {
                1.0
            } else {
                0.0
            }
        } else {
            (self.n * (-one_minus_cos).ln_1p()).exp()
        };
        self.norm * pow * a.sin().max(0.0)
    }

    /// The three inner integrals given `s0 = int 1 dp`, `s1 = int cos p`, `s2 = int cos^2 p`.
    fn inner(&self, ca: f64, sa: f64, s: [f64; 3]) -> [f64; 3] {
        let (rx, rz, sr, ux) = (self.rx, self.rz, self.sr, self.ux);
        [
            ca * rz * s[0] + sa * sr * s[1],
            ca * ca * rz * rz * s[0] + 2.0 * ca * sa * rz * sr * s[1] + sa * sa * sr * sr * s[2],
            ca * ca * rx * rz * s[0] + ca * sa * (rx * sr + ux * rz) * s[1] + sa * sa * ux * sr * s[2],
        ]
    }

    /// Inner integrals where the whole circle of half-angle `a` is above the horizon.
    fn full(&self, a: f64) -> [f64; 3] {
        let (sa, ca) = a.sin_cos();
        self.inner(ca, sa, [2.0 * PI, 0.0, PI])
    }

    /// Inner integrals past the kink, `a = |e| + delta`: `p in [-P, P]` (`delta` avoids cancellation).
    fn clipped(&self, a: f64, delta: f64) -> [f64; 3] {
        let (sa, ca) = a.sin_cos();
        let d = self.sr * sa;
        if d <= 0.0 {
            return [0.0; 3];
        }
        // 1 + cos P = sin(a - e) / d and 1 - cos P = sin(a + e) / d.
        let (sm, sp) =
            if self.e >= 0.0 { (delta.sin(), (a + self.e).sin()) } else { ((a - self.e).sin(), delta.sin()) };
        let c = (-self.rz * ca / d).clamp(-1.0, 1.0);
        let sin_p = ((sm / d).max(0.0) * (sp / d).max(0.0)).sqrt().min(1.0);
        let p = sin_p.atan2(c);
        self.inner(ca, sa, [2.0 * p, 2.0 * sin_p, p + sin_p * c])
    }

    /// Integrand in the quadrature variable `t`: `a = t` on `[0, |e|]`, `a = |e| + (t - |e|)^2` beyond.
    fn integrand(&self, t: f64) -> [f64; 3] {
        let k = self.e.abs();
        if t <= k {
            if self.e < 0.0 {
                return [0.0; 3];
            }
            let w = self.weight(t);
            return self.full(t).map(|x| x * w);
        }
        let tau = t - k;
        let delta = tau * tau;
        let a = k + delta;
        let w = self.weight(a) * 2.0 * tau;
        self.clipped(a, delta).map(|x| x * w)
    }

    /// Breakpoints in `t`: the kink, the peak scales `2^j / sqrt(n + 2)` and the ends.
    fn breaks(&self) -> Vec<f64> {
        let k = self.e.abs();
        let to_t = |a: f64| if a <= k { a } else { k + (a - k).sqrt() };
        let mut pts = vec![0.0, to_t(k), to_t(FRAC_PI_2)];
        let mut a = 1.0 / (self.n + 2.0).sqrt();
        while a < FRAC_PI_2 {
            pts.push(to_t(a));
            a *= 2.0;
        }
        pts.sort_by(f64::total_cmp);
        pts.dedup();
        pts
    }
}

/// Horizon-clipped moments `i0`, `iz`, `ix` of the modified-Phong lobe around `r` with exponent `n`.
///
/// `r` is normalised here; it is meant to be a mirror direction (`r.z >= 0`), but any direction
/// works (a lobe partly or wholly below the horizon is clipped the same way). The quadrature runs to
/// `error <= rel_tol * max(|i0|, |iz|, |ix|) = rel_tol * i0` (use [`DEFAULT_REL_TOL`] for a `1e-9`
/// reference); if that cannot be reached (e.g. `rel_tol` below round-off), the returned `error` is
/// still an honest bound and exceeds `rel_tol * i0`. A zero or non-finite `r` or a negative or
/// non-finite `n` gives NaN moments with an infinite `error`.
pub fn clipped_lobe_moments(r: Vec3, n: f64, rel_tol: f64) -> LobeMoments {
    let Some(lobe) = Lobe::new(r, n) else {
        return LobeMoments { i0: f64::NAN, iz: f64::NAN, ix: f64::NAN, error: f64::INFINITY };
    };
    let q = gauss_kronrod_multi(|t| lobe.integrand(t), &lobe.breaks(), f64::MIN_POSITIVE, rel_tol, MAX_DEPTH);
    // Maximum that propagates NaN (`f64::max` alone would drop it).
    let error = q.error.iter().fold(0.0, |m: f64, &e| if m.is_nan() || e.is_nan() { f64::NAN } else { m.max(e) });
    LobeMoments { i0: q.value[0], iz: q.value[1], ix: q.value[2], error }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::quadrature::gauss_legendre;

    /// Brute force: tensor Gauss-Legendre panels in (theta, phi) around +z, panels farther than
    /// where `cos(a)^n < 1e-40` from the axis skipped.
    fn brute(r: Vec3, n: f64) -> [f64; 3] {
        let r = r.normalize();
        let h_target = (0.05f64).min(1.0 / (3.0 * (n + 2.0).sqrt()));
        let nt = (FRAC_PI_2 / h_target).ceil() as usize;
        let np = (2.0 * PI / h_target).ceil() as usize;
        let (ht, hp) = (FRAC_PI_2 / nt as f64, 2.0 * PI / np as f64);
        let (x, w) = gauss_legendre(10);
        let norm = (n + 2.0) / (2.0 * PI);
        let mut acc = [0.0f64; 3];
        for i in 0..nt {
            let tc = (i as f64 + 0.5) * ht;
            let mut row = [0.0f64; 3];
            for j in 0..np {
                let pc = -PI + (j as f64 + 0.5) * hp;
                let wc = Vec3::new(tc.sin() * pc.cos(), tc.sin() * pc.sin(), tc.cos());
                let amin = r.dot(wc).clamp(-1.0, 1.0).acos() - (ht + hp);
                if amin > 0.0 && (amin >= FRAC_PI_2 || n * amin.cos().ln() < -92.0) {
                    continue;
                }
                for (xa, wa) in x.iter().zip(&w) {
                    let th = tc + 0.5 * ht * xa;
                    let (st, ct) = th.sin_cos();
                    for (xb, wb) in x.iter().zip(&w) {
                        let ph = pc + 0.5 * hp * xb;
                        let d = Vec3::new(st * ph.cos(), st * ph.sin(), ct);
                        let l = norm * r.dot(d).max(0.0).powf(n) * d.z * st * wa * wb;
                        row[0] += l;
                        row[1] += l * d.z;
                        row[2] += l * d.x;
                    }
                }
            }
            for k in 0..3 {
                acc[k] += row[k] * 0.25 * ht * hp;
            }
        }
        acc
    }

    fn check_against_brute(r: Vec3, n: f64) -> LobeMoments {
        let m = clipped_lobe_moments(r, n, DEFAULT_REL_TOL);
        let b = brute(r, n);
        let got = [m.i0, m.iz, m.ix];
        let dev = (0..3).fold(0.0f64, |d, k| d.max((got[k] - b[k]).abs()));
        eprintln!("r {r:?} n {n}: {m:?}, max |quad - brute| / i0 = {:.2e}", dev / m.i0);
        for k in 0..3 {
            let dev = (got[k] - b[k]).abs() / m.i0;
            assert!(dev <= 1e-9, "r {r:?} n {n} moment {k}: {} vs brute {} (rel {dev:e})", got[k], b[k]);
        }
        assert!(m.i0.is_finite() && m.i0 > 0.0 && m.error <= 1e-9 * m.i0, "{m:?}");
        m
    }

    /// Mirror of the view direction from the gradient-plane camera (0, -3, 2) at the origin.
    fn camera_mirror() -> Vec3 {
        Vec3::new(0.0, -3.0, 2.0).normalize().reflect(Vec3::Z)
    }

    #[test]
    fn unclipped_axis_matches_closed_forms() {
        for n in [0.0, 1.0, 20.0, 200.0, 10000.0, 1e6] {
            let m = clipped_lobe_moments(Vec3::Z, n, DEFAULT_REL_TOL);
            let iz = (n + 2.0) / (n + 3.0);
            eprintln!("n {n}: {m:?}, |i0 - 1| {:.1e}, |iz - exact| {:.1e}", (m.i0 - 1.0).abs(), (m.iz - iz).abs());
            assert!((m.i0 - 1.0).abs() <= 1e-12, "n {n}: {m:?}");
            assert!((m.iz - iz).abs() <= 1e-12 * iz && m.ix.abs() <= 1e-12, "n {n}: {m:?}");
            assert!(m.error <= 1e-12 * m.i0, "n {n}: {m:?}");
            assert!((m.i0 - 1.0).abs() <= m.error && (m.iz - iz).abs() <= m.error, "n {n}: {m:?}");
        }
    }

    #[test]
    fn steep_lobe_far_from_horizon_matches_unclipped_second_moments() {
        // For n = 10^4 at 33.7 degrees elevation the clipped mass is < 1e-300: int L w w^T =
        // alpha r r^T + beta (I - r r^T), alpha = (n+2)/(n+3), beta = (n+2)/((n+1)(n+3)).
        for r in [camera_mirror(), Vec3::new(0.6, 0.9, 0.5).normalize()] {
            let n = 10000.0;
            let (alpha, beta) = ((n + 2.0) / (n + 3.0), (n + 2.0) / ((n + 1.0) * (n + 3.0)));
            let m = clipped_lobe_moments(r, n, DEFAULT_REL_TOL);
            let exact = [r.z, alpha * r.z * r.z + beta * (1.0 - r.z * r.z), (alpha - beta) * r.x * r.z];
            for (got, want) in [m.i0, m.iz, m.ix].into_iter().zip(exact) {
                assert!((got - want).abs() <= 1e-12 * m.i0 && (got - want).abs() <= m.error, "{m:?}");
            }
        }
    }

    #[test]
    fn oblique_camera_mirror_matches_brute_force() {
        for n in [20.0, 200.0, 10000.0] {
            let m = check_against_brute(camera_mirror(), n);
            assert!(m.ix.abs() <= 1e-12, "symmetric in x: {m:?}");
            check_against_brute(Vec3::new(0.6, 0.9, 0.5), n);
        }
        // The clip removes directions with w.z < 0, so it raises i0 above the unclipped r.z.
        let m = clipped_lobe_moments(camera_mirror(), 20.0, DEFAULT_REL_TOL);
        assert!(m.i0 > camera_mirror().z + 1e-6, "{m:?}");
    }

    #[test]
    fn grazing_and_below_horizon_axes_match_brute_force() {
        let el = 5f64.to_radians();
        let grazing = Vec3::new(el.cos() * 0.5, el.cos() * 0.75f64.sqrt(), el.sin());
        for n in [20.0, 200.0, 10000.0] {
            check_against_brute(grazing, n);
        }
        // Steep lobes cut by the horizon: elevation 0.5 degrees (~ one lobe width) and 0.
        let low = 0.5f64.to_radians();
        check_against_brute(Vec3::new(0.0, low.cos(), low.sin()), 10000.0);
        for n in [20.0, 10000.0] {
            check_against_brute(Vec3::new(1.0, 0.0, 0.0), n);
        }
        check_against_brute(Vec3::new(0.3, 0.2, -0.17), 20.0);
    }

    #[test]
    fn continuous_near_the_normal_and_rejects_bad_input() {
        let a = clipped_lobe_moments(Vec3::Z, 50.0, DEFAULT_REL_TOL);
        let b = clipped_lobe_moments(Vec3::new(1e-9, 0.0, 1.0), 50.0, DEFAULT_REL_TOL);
        assert!((a.i0 - b.i0).abs() < 1e-12 && (a.iz - b.iz).abs() < 1e-12 && b.ix.abs() < 1e-8);
        let bad = clipped_lobe_moments(Vec3::new(0.0, 0.0, 0.0), 20.0, DEFAULT_REL_TOL);
        assert!(bad.i0.is_nan() && bad.error.is_infinite());
        assert!(clipped_lobe_moments(Vec3::Z, f64::NAN, 1e-12).i0.is_nan());
        let below = clipped_lobe_moments(-Vec3::Z, 20.0, DEFAULT_REL_TOL);
        assert_eq!((below.i0, below.iz, below.ix), (0.0, 0.0, 0.0));
    }
}

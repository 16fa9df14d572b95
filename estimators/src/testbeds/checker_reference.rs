//! The quadrature reference of `checker-direct` (book: testbeds.md): for each pixel, the direct lighting
//! `sum_k int_{A_k visible} L_k f(w(y), w_o) cos(theta_x) cos(theta_y) / |y - x|^2 dA(y)` (paper
//! 003 Eq. 4-5 written over each light's area), by product Gauss-Legendre quadrature.
//!
//! - Visibility is handled exactly rather than by refinement: every occluder is an axis-aligned
//!   rectangle parallel to the lights, so the part of a light it hides from a floor point `x` is
//!   the axis-aligned rectangle `x + (O - x) z_light / z_occluder`; the visible part of the light
//!   is split into rectangles whose edges are exactly the shadow edges (at most four around one
//!   shadow; the lit cells of the grid of all shadow edges behind several), and each is
//!   integrated as a smooth function.
//! - Each rectangle is integrated adaptively: an order-8 product rule on a cell is compared with
//!   the sum over its four quadrants; a cell is accepted when they differ by less than its share of
//!   the tolerance, and a cell larger than a few Phong-lobe widths near the mirror direction's hit
//!   point is always split (so a narrow `n = 5000` peak cannot be missed by both rules).
//! - The bound is the sum over accepted cells of `|fine - coarse|` (the fine value is used, so this
//!   overestimates its error) plus a round-off allowance; a test shows the actual error against an
//!   independent brute-force quadrature is below it and below 1e-9 relative.

use super::checker::CheckerGeometry;
use mcbench_core::lighting::RectLight;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::quadrature::gauss_legendre;
use mcbench_core::testbed::{Reference, ReferenceKind, ShadingPoint};

/// Relative tolerance per pixel (the test bed promises 1e-9).
const REL_TOL: f64 = 1e-11;
/// Absolute floor of the tolerance (pixels whose value is zero or tiny).
const ABS_TOL: f64 = 1e-14;
/// Gauss-Legendre order per cell and axis.
const ORDER: usize = 8;
/// Subdivision depth limit.
const MAX_DEPTH: usize = 24;

/// An axis-aligned rectangle on a light's plane.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rect {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

/// The shadow of each occluder between `x` and `light` on the light's plane, clipped to the
/// light (empty shadows left out).
fn shadows(light: &RectLight, full: Rect, x: Vec3, geo: &CheckerGeometry) -> Vec<Rect> {
    geo.occluders
        .iter()
        .filter(|o| o.z > x.z && o.z < light.z)
        .filter_map(|o| {
            let s = (light.z - x.z) / (o.z - x.z);
            let sh = Rect {
                x0: (x.x + (o.min[0] - x.x) * s).max(full.x0),
                x1: (x.x + (o.max[0] - x.x) * s).min(full.x1),
                y0: (x.y + (o.min[1] - x.y) * s).max(full.y0),
                y1: (x.y + (o.max[1] - x.y) * s).min(full.y1),
            };
            (sh.x0 < sh.x1 && sh.y0 < sh.y1).then_some(sh)
        })
        .collect()
}

/// The visible parts of `light` from `x`: the whole light, the at most four rectangles around
/// one shadow, or, behind several occluders, [`uncovered`] rectangles.
fn visible_parts(light: &RectLight, x: Vec3, geo: &CheckerGeometry) -> Vec<Rect> {
    let full = Rect { x0: light.min[0], x1: light.max[0], y0: light.min[1], y1: light.max[1] };
    match shadows(light, full, x, geo).as_slice() {
        [] => vec![full],
        [sh] => {
            let parts = [
                Rect { x0: full.x0, x1: sh.x0, ..full },
                Rect { x0: sh.x1, x1: full.x1, ..full },
                Rect { x0: sh.x0, x1: sh.x1, y0: full.y0, y1: sh.y0 },
                Rect { x0: sh.x0, x1: sh.x1, y0: sh.y1, y1: full.y1 },
            ];
            parts.into_iter().filter(|r| r.x1 > r.x0 && r.y1 > r.y0).collect()
        }
        several => uncovered(full, several),
    }
}

/// The part of `full` no shadow covers, as disjoint rectangles whose edges are shadow edges: the
/// grid of every shadow edge splits `full` into cells each wholly lit or wholly hidden; the lit
/// cells of a row are joined into runs, and runs of equal extent in consecutive rows into one
/// rectangle.
fn uncovered(full: Rect, shadows: &[Rect]) -> Vec<Rect> {
    let edges = |lo: f64, hi: f64, of: &dyn Fn(&Rect) -> [f64; 2]| {
        let mut e: Vec<f64> = vec![lo, hi];
        e.extend(shadows.iter().flat_map(of));
        e.sort_by(f64::total_cmp);
        e.dedup();
        e
    };
    let xs = edges(full.x0, full.x1, &|r: &Rect| [r.x0, r.x1]);
    let ys = edges(full.y0, full.y1, &|r: &Rect| [r.y0, r.y1]);
    let (mut open, mut done): (Vec<Rect>, Vec<Rect>) = (Vec::new(), Vec::new());
    for band in ys.windows(2) {
        let (y0, y1) = (band[0], band[1]);
        let ym = 0.5 * (y0 + y1);
        let mut runs: Vec<(f64, f64)> = Vec::new();
        for cell in xs.windows(2) {
            let xm = 0.5 * (cell[0] + cell[1]);
            if shadows.iter().any(|s| s.x0 < xm && xm < s.x1 && s.y0 < ym && ym < s.y1) {
                continue;
            }
            match runs.last_mut() {
                Some(run) if run.1 == cell[0] => run.1 = cell[1],
                _ => runs.push((cell[0], cell[1])),
            }
        }
        let mut next = Vec::with_capacity(runs.len());
        for (x0, x1) in runs {
            match open.iter().position(|r| r.x0 == x0 && r.x1 == x1) {
                Some(k) => next.push(Rect { y1, ..open.swap_remove(k) }),
                None => next.push(Rect { x0, x1, y0, y1 }),
            }
        }
        done.append(&mut open);
        open = next;
    }
    done.append(&mut open);
    done
}

/// The area integrand at light point `(u, v)` (grey: one channel).
struct AreaIntegrand<'a> {
    p: &'a ShadingPoint,
    light: &'a RectLight,
}

impl AreaIntegrand<'_> {
    fn eval(&self, u: f64, v: f64) -> f64 {
        let d = Vec3::new(u, v, self.light.z) - self.p.position;
        let r2 = d.dot(d);
        let w = d / r2.sqrt();
        let cos_x = w.dot(self.p.normal);
        if cos_x <= 0.0 {
            return 0.0;
        }
        self.light.radiance[0] * self.p.brdf.eval(w, self.p.wo, self.p.normal)[0] * cos_x * w.z / r2
    }
}

struct Adaptive<'a> {
    f: AreaIntegrand<'a>,
    nodes: (Vec<f64>, Vec<f64>),
    /// Hit point of the mirror direction on the light's plane and the lobe width there.
    peak: Option<(f64, f64, f64)>,
    evals: usize,
}

impl Adaptive<'_> {
    fn rule(&mut self, r: &Rect) -> f64 {
        let (x, w) = (&self.nodes.0, &self.nodes.1);
        let (hx, hy) = (0.5 * (r.x1 - r.x0), 0.5 * (r.y1 - r.y0));
        let (cx, cy) = (0.5 * (r.x0 + r.x1), 0.5 * (r.y0 + r.y1));
        let mut s = 0.0;
        for (xi, wi) in x.iter().zip(w) {
            for (xj, wj) in x.iter().zip(w) {
                s += wi * wj * self.f.eval(cx + hx * xi, cy + hy * xj);
            }
        }
        self.evals += x.len() * x.len();
        s * hx * hy
    }

    fn must_split(&self, r: &Rect) -> bool {
        let Some((qx, qy, width)) = self.peak else { return false };
        let size = (r.x1 - r.x0).max(r.y1 - r.y0);
        let dx = (qx - qx.clamp(r.x0, r.x1)).abs();
        let dy = (qy - qy.clamp(r.y0, r.y1)).abs();
        size > 2.0 * width && dx.hypot(dy) < 12.0 * width
    }

    /// Returns (value, error bound) of the cell given its coarse value.
    fn integrate(&mut self, r: Rect, coarse: f64, tol: f64, depth: usize) -> (f64, f64) {
        let (mx, my) = (0.5 * (r.x0 + r.x1), 0.5 * (r.y0 + r.y1));
        let quads = [
            Rect { x1: mx, y1: my, ..r },
            Rect { x0: mx, y1: my, ..r },
            Rect { x1: mx, y0: my, ..r },
            Rect { x0: mx, y0: my, ..r },
        ];
        let vals: Vec<f64> = quads.iter().map(|q| self.rule(q)).collect();
        let fine: f64 = vals.iter().sum();
        let err = (fine - coarse).abs();
        if (err <= tol && !self.must_split(&r)) || depth >= MAX_DEPTH {
            return (fine, err);
        }
        let (mut v, mut e) = (0.0, 0.0);
        for (q, c) in quads.into_iter().zip(vals) {
            let (qv, qe) = self.integrate(q, c, 0.25 * tol, depth + 1);
            v += qv;
            e += qe;
        }
        (v, e)
    }
}

/// Direct lighting at one shading point with its error bound: `(value, bound, evaluations)`.
pub fn direct_lighting(geo: &CheckerGeometry, p: &ShadingPoint, rel_tol: f64) -> (f64, f64, usize) {
    if p.brdf.kd[0] == 0.0 && p.brdf.ks[0] == 0.0 {
        return (0.0, 0.0, 0);
    }
    // A first pass at a loose tolerance sets the scale of the absolute tolerance.
    let mut total: (f64, f64, usize) = (0.0, 0.0, 0);
    for pass in 0..2 {
        let scale = if pass == 0 { f64::INFINITY } else { rel_tol * total.0.abs() + ABS_TOL };
        total = (0.0, 0.0, total.2);
        for light in &geo.lights {
            let r = p.wo.reflect(p.normal);
            let peak = (p.brdf.ks[0] > 0.0 && r.z > 0.0).then(|| {
                let t = (light.z - p.position.z) / r.z;
                (p.position.x + t * r.x, p.position.y + t * r.y, t / (p.brdf.n + 2.0).sqrt())
            });
            let mut a = Adaptive { f: AreaIntegrand { p, light }, nodes: gauss_legendre(ORDER), peak, evals: 0 };
            let parts = visible_parts(light, p.position, geo);
            let area: f64 = parts.iter().map(|r| (r.x1 - r.x0) * (r.y1 - r.y0)).sum();
            for part in parts {
                let share = (part.x1 - part.x0) * (part.y1 - part.y0) / area;
                let tol = if pass == 0 { f64::INFINITY } else { scale * share / geo.lights.len() as f64 };
                let coarse = a.rule(&part);
                let (v, e) = a.integrate(part, coarse, tol, 0);
                total.0 += v;
                total.1 += e;
            }
            total.2 += a.evals;
        }
    }
    // Round-off allowance: a few ulps per evaluation of the summed value.
    let bound = total.1 + 1e-15 * total.0.abs() * (total.2 as f64).sqrt();
    (total.0, bound, total.2)
}

/// The reference of every pixel (grey: the three channels are equal).
pub fn reference(geo: &CheckerGeometry, points: &[ShadingPoint]) -> Reference {
    let mut bound = 0.0f64;
    let value = points
        .iter()
        .map(|p| {
            let (v, e, _) = direct_lighting(geo, p, REL_TOL);
            bound = bound.max(e);
            Rgb::splat(v)
        })
        .collect::<Vec<_>>();
    let method = "product Gauss-Legendre over each light's visible area (split exactly at shadow edges, adaptive in the glossy peaks)".to_string();
    Reference { kind: ReferenceKind::Exact { method, bound }, std_err: vec![Rgb::ZERO; value.len()], value }
}

#[cfg(test)]
#[path = "checker_tests.rs"]
mod tests;

//! Reconstruction of the control variate `g` from the cache and its integral `G` in closed form
//! (paper 001 §4.1; paper 000 §4.1 for the sphere).
//!
//! The cell coefficients are B-spline coefficients on the regular `(s, t)` grid, placed at the cell
//! centres. Because `d omega = |D| ds dt` with `|D|` the domain's solid angle, `G = |D| * integral
//! of g over the unit square`:
//! - `cv1` (order 0, piecewise constant): `g` is the coefficient of the containing cell and
//!   `G = |D| A`, `A` the average coefficient.
//! - `cv2` (order 1, bilinear): linear interpolation between cell centres, periodic in `s`; in `t`
//!   the first half-row interpolates towards the polar value `P0` (the average of the first row) at
//!   the pole `t = 0`, so `g` is continuous there. The last half-row interpolates towards the
//!   other polar value `P1` at `t = 1` on the sphere, and towards zero at the horizon on the
//!   hemisphere ("the bottom boundary is implied as zero due to the cosine term", §4.1). Integrating
//!   the piecewise-linear profile (the trapezoid rule is exact for it and periodic in `s`) gives
//!   `G = |D| A` on the sphere and, on the hemisphere, `G = |D| (A - P1 / (4 nt))`: "its simple
//!   weighted subtraction to a hemispherical average" with the second polar value.
//!
//! Both `A` and the polar values are maintained by the [`Grid`] on every write, so `g` and `G` are
//! `O(1)` reads.

use super::domain::St;
use super::grid::{floor_index, Grid};
use super::storage::Scalar;
use mcbench_core::math::Rgb;

/// The control variate of an estimator: `cv0`, `cv1` or `cv2` (paper 001 Fig. 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlVariate {
    /// `cv0`: no control variate, `g = 0`, `G = 0`.
    None,
    /// `cv1`: order-0 (piecewise constant) B-spline.
    Constant,
    /// `cv2`: order-1 (bilinear) B-spline with polar values.
    Bilinear,
}

impl ControlVariate {
    /// The id fragment (`cv0`, `cv1`, `cv2`).
    pub fn name(self) -> &'static str {
        match self {
            ControlVariate::None => "cv0",
            ControlVariate::Constant => "cv1",
            ControlVariate::Bilinear => "cv2",
        }
    }

    /// `g(st)` from the current coefficients, `O(1)`.
    pub fn g<S: Scalar>(self, grid: &Grid<S>, st: St) -> Rgb {
        match self {
            ControlVariate::None => Rgb::ZERO,
            ControlVariate::Constant => grid.radiance(grid.cell_at(st)),
            ControlVariate::Bilinear => bilinear(grid, st),
        }
    }

    /// `G`, the integral of `g` over the domain's solid angle, in closed form, `O(1)`.
    pub fn integral<S: Scalar>(self, grid: &Grid<S>) -> Rgb {
        let measure = grid.domain().measure();
        match self {
            ControlVariate::None => Rgb::ZERO,
            ControlVariate::Constant => grid.average() * measure,
            ControlVariate::Bilinear if grid.domain().has_bottom_pole() => grid.average() * measure,
            ControlVariate::Bilinear => {
                let nt = grid.resolution().1 as f64;
                (grid.average() - grid.last_polar() / (4.0 * nt)) * measure
            }
        }
    }
}

/// The order-1 B-spline reconstruction (see the module documentation).
fn bilinear<S: Scalar>(grid: &Grid<S>, st: St) -> Rgb {
    let (ns, nt) = grid.resolution();
    // Columns of the two centres around s, wrapping at the periodic seam (x >= -1/2, no modulo).
    let x = st.s * ns as f64 - 0.5;
    let (i0, fx) = if x < 0.0 {
        (ns - 1, x + 1.0)
    } else {
        let i = floor_index(x);
        (i.min(ns - 1), x - i as f64)
    };
    let i1 = if i0 + 1 == ns { 0 } else { i0 + 1 };
    let row = |j: usize| {
        let base = j * ns;
        grid.radiance(base + i0) * (1.0 - fx) + grid.radiance(base + i1) * fx
    };
    let y = st.t * nt as f64 - 0.5;
    if y < 0.0 {
        // Between the pole t = 0 (y = -1/2) and the first row of centres (y = 0).
        let w = 2.0 * (y + 0.5);
        grid.first_polar() * (1.0 - w) + row(0) * w
    } else if y >= (nt - 1) as f64 {
        // Between the last row of centres and t = 1: the bottom pole or the horizon (zero).
        let w = (2.0 * (y - (nt - 1) as f64)).min(1.0);
        let edge = if grid.domain().has_bottom_pole() { grid.last_polar() } else { Rgb::ZERO };
        row(nt - 1) * (1.0 - w) + edge * w
    } else {
        let j0 = floor_index(y);
        let fy = y - j0 as f64;
        row(j0) * (1.0 - fy) + row(j0 + 1) * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cache::domain::Domain;
    use mcbench_core::quadrature::gauss_legendre;
    use mcbench_core::rng::stream;
    use rand::Rng;

    /// The integral of `g` over the domain by Gauss-Legendre on sub-rectangles bounded by the cell
    /// edges and centres, where `g` is bilinear (cv2) or constant (cv1): exact up to rounding.
    fn integrate<S: Scalar>(cv: ControlVariate, grid: &Grid<S>) -> Rgb {
        let (ns, nt) = grid.resolution();
        let (x, w) = gauss_legendre(3);
        let mut sum = [mcbench_core::stats::NeumaierSum::new(), Default::default(), Default::default()];
        let (hs, ht) = (0.5 / ns as f64, 0.5 / nt as f64);
        for a in 0..2 * ns {
            for b in 0..2 * nt {
                for (xi, wi) in x.iter().zip(&w) {
                    for (xj, wj) in x.iter().zip(&w) {
                        let st = St { s: hs * (a as f64 + 0.5 + 0.5 * xi), t: ht * (b as f64 + 0.5 + 0.5 * xj) };
                        let v = cv.g(grid, st) * (wi * wj * 0.25 * hs * ht);
                        for ch in 0..3 {
                            sum[ch].add(v[ch]);
                        }
                    }
                }
            }
        }
        Rgb([sum[0].value(), sum[1].value(), sum[2].value()]) * grid.domain().measure()
    }

    fn random_grid<S: Scalar>(domain: Domain, ns: usize, nt: usize, seed: u64) -> Grid<S> {
        let mut rng = stream(seed, "reconstruction");
        let mut grid = Grid::<S>::with_resolution(domain, ns, nt);
        for c in 0..grid.cells() {
            grid.set_radiance(c, Rgb([rng.gen::<f64>() * 3.0, rng.gen::<f64>() - 0.5, 1e3 * rng.gen::<f64>()]));
        }
        grid
    }

    /// `G` in closed form equals the numerically integrated `g` to 1e-12, for cv1 and cv2, on
    /// both domains, at several resolutions and in both storage precisions.
    #[test]
    fn closed_form_integral_matches_quadrature_of_g() {
        let mut seed = 0;
        for domain in [Domain::Hemisphere, Domain::Sphere] {
            for (ns, nt) in [(1, 1), (2, 1), (2, 2), (4, 4), (16, 8), (32, 32)] {
                seed += 1;
                let g64 = random_grid::<f64>(domain, ns, nt, seed);
                let g32 = random_grid::<f32>(domain, ns, nt, seed);
                for cv in [ControlVariate::Constant, ControlVariate::Bilinear] {
                    for (closed, numeric) in
                        [(cv.integral(&g64), integrate(cv, &g64)), (cv.integral(&g32), integrate(cv, &g32))]
                    {
                        for ch in 0..3 {
                            let scale = numeric[ch].abs().max(1.0);
                            assert!(
                                (closed[ch] - numeric[ch]).abs() <= 1e-12 * scale,
                                "{domain:?} {ns}x{nt} {cv:?} ch {ch}: {} vs {}",
                                closed[ch],
                                numeric[ch]
                            );
                        }
                    }
                }
            }
        }
        let g = random_grid::<f64>(Domain::Hemisphere, 4, 4, 99);
        assert_eq!(ControlVariate::None.integral(&g), Rgb::ZERO);
        assert_eq!(ControlVariate::None.g(&g, St { s: 0.3, t: 0.3 }), Rgb::ZERO);
    }

    /// cv2 interpolates the coefficients at the cell centres, is continuous across the periodic
    /// seam `s = 0 = 1` and at the pole, and vanishes at the horizon of the hemisphere.
    #[test]
    fn bilinear_interpolates_is_periodic_and_handles_the_boundaries() {
        let grid = random_grid::<f64>(Domain::Hemisphere, 8, 4, 7);
        let cv = ControlVariate::Bilinear;
        for c in 0..grid.cells() {
            let (i, j) = grid.cell_ij(c);
            let centre = St { s: (i as f64 + 0.5) / 8.0, t: (j as f64 + 0.5) / 4.0 };
            assert!((cv.g(&grid, centre) - grid.radiance(c)).0.iter().all(|d| d.abs() < 1e-12));
        }
        let (a, b) = (cv.g(&grid, St { s: 1e-13, t: 0.4 }), cv.g(&grid, St { s: 1.0 - 1e-13, t: 0.4 }));
        assert!((a - b).0.iter().all(|d| d.abs() < 1e-9));
        let pole = grid.first_polar();
        for s in [0.0, 0.3, 0.77] {
            assert!((cv.g(&grid, St { s, t: 0.0 }) - pole).0.iter().all(|d| d.abs() < 1e-12));
            assert!(cv.g(&grid, St { s, t: 1.0 }).0.iter().all(|d| d.abs() < 1e-12));
        }
        let sphere = random_grid::<f64>(Domain::Sphere, 8, 4, 8);
        assert!((cv.g(&sphere, St { s: 0.6, t: 1.0 }) - sphere.last_polar()).0.iter().all(|d| d.abs() < 1e-12));
    }
}

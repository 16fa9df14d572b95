//! Small vector math: 3-vectors, RGB triples and orthonormal frames.
//!
//! Directions follow the papers' convention: `w_o` points from the surface towards the viewer,
//! `w_i` from the surface towards the light; the shading normal is `n`.

use std::ops::{Add, AddAssign, Div, Index, IndexMut, Mul, Neg, Sub};

/// A 3-vector of `f64` (points and directions).
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Vec3 {
    /// x component.
    pub x: f64,
    /// y component.
    pub y: f64,
    /// z component.
    pub z: f64,
}

impl Vec3 {
    /// The unit vector +z.
    pub const Z: Vec3 = Vec3 { x: 0.0, y: 0.0, z: 1.0 };
    /// Builds a vector from its components.
    #[inline]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Vec3 { x, y, z }
    }
    /// Dot product.
    #[inline]
    pub fn dot(self, o: Vec3) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// Cross product.
    #[inline]
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)
    }
    /// Euclidean length.
    #[inline]
    pub fn length(self) -> f64 {
        self.dot(self).sqrt()
    }
    /// The vector scaled to unit length.
    #[inline]
    pub fn normalize(self) -> Vec3 {
        self / self.length()
    }
    /// Mirror of `self` about the unit normal `n`: `2 (n . v) n - v`.
    #[inline]
    pub fn reflect(self, n: Vec3) -> Vec3 {
        n * (2.0 * n.dot(self)) - self
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline]
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl Sub for Vec3 {
    type Output = Vec3;
    #[inline]
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl Mul<f64> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, s: f64) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl Div<f64> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn div(self, s: f64) -> Vec3 {
        Vec3::new(self.x / s, self.y / s, self.z / s)
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    #[inline]
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

/// An orthonormal frame `(u, v, w)`; `w` is the frame's axis (a normal or a lobe direction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub u: Vec3,
    /// Second tangent.
    pub v: Vec3,
    /// Axis.
    pub w: Vec3,
}

impl Frame {
    /// A frame around the unit vector `w` (branchless construction of Duff et al. 2017).
    #[inline]
    pub fn around(w: Vec3) -> Frame {
        let sign = 1.0f64.copysign(w.z);
        let a = -1.0 / (sign + w.z);
        let b = w.x * w.y * a;
        let u = Vec3::new(1.0 + sign * w.x * w.x * a, sign * b, -sign * w.x);
        let v = Vec3::new(b, sign + w.y * w.y * a, -w.y);
        Frame { u, v, w }
    }
    /// Local coordinates `(x, y, z)` to world.
    #[inline]
    pub fn to_world(&self, l: Vec3) -> Vec3 {
        self.u * l.x + self.v * l.y + self.w * l.z
    }
    /// World to local coordinates.
    #[inline]
    pub fn to_local(&self, d: Vec3) -> Vec3 {
        Vec3::new(d.dot(self.u), d.dot(self.v), d.dot(self.w))
    }
}

/// An RGB radiance (or any per-channel quantity).
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Rgb(pub [f64; 3]);

impl Rgb {
    /// All channels zero.
    pub const ZERO: Rgb = Rgb([0.0; 3]);
    /// The same value in every channel.
    #[inline]
    pub const fn splat(v: f64) -> Rgb {
        Rgb([v, v, v])
    }
    /// Mean over channels.
    #[inline]
    pub fn mean(self) -> f64 {
        (self.0[0] + self.0[1] + self.0[2]) / 3.0
    }
    /// Applies `f` to every channel.
    #[inline]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Rgb {
        Rgb([f(self.0[0]), f(self.0[1]), f(self.0[2])])
    }
    /// True when every channel is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|c| c.is_finite())
    }
}

impl Add for Rgb {
    type Output = Rgb;
    #[inline]
    fn add(self, o: Rgb) -> Rgb {
        Rgb([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
}
impl AddAssign for Rgb {
    #[inline]
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}
impl Sub for Rgb {
    type Output = Rgb;
    #[inline]
    fn sub(self, o: Rgb) -> Rgb {
        Rgb([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
}
impl Mul<f64> for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, s: f64) -> Rgb {
        self.map(|c| c * s)
    }
}
impl Mul for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, o: Rgb) -> Rgb {
        Rgb([self.0[0] * o.0[0], self.0[1] * o.0[1], self.0[2] * o.0[2]])
    }
}
impl Div<f64> for Rgb {
    type Output = Rgb;
    #[inline]
    fn div(self, s: f64) -> Rgb {
        self.map(|c| c / s)
    }
}
impl Index<usize> for Rgb {
    type Output = f64;
    #[inline]
    fn index(&self, i: usize) -> &f64 {
        &self.0[i]
    }
}
impl IndexMut<usize> for Rgb {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        &mut self.0[i]
    }
}

/// The error function to about 1e-15 relative (statrs 0.17's `erf` is off by up to ~1e-11):
/// the positive-term series `erf(x) = 2/sqrt(pi) exp(-x^2) sum_n 2^n x^(2n+1) / (2n+1)!!`
/// (Abramowitz and Stegun 7.1.6), which has no cancellation; `erf(-x) = -erf(x)`, and `+-1`
/// beyond `|x| = 6` (where `1 - erf < 3e-17`).
pub fn erf(x: f64) -> f64 {
    let ax = x.abs();
    if ax > 6.0 {
        return x.signum();
    }
    let x2 = ax * ax;
    let (mut term, mut sum, mut n) = (ax, ax, 0.0);
    while term > 1e-17 * sum {
        n += 1.0;
        term *= 2.0 * x2 / (2.0 * n + 1.0);
        sum += term;
    }
    (2.0 / std::f64::consts::PI.sqrt() * (-x2).exp() * sum).min(1.0).copysign(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_for_any_axis() {
        for w in [Vec3::Z, -Vec3::Z, Vec3::new(1.0, 2.0, -0.3).normalize(), Vec3::new(0.0, 1.0, 0.0)] {
            let f = Frame::around(w);
            for (a, b) in [(f.u, f.v), (f.v, f.w), (f.u, f.w)] {
                assert!(a.dot(b).abs() < 1e-12);
            }
            for a in [f.u, f.v, f.w] {
                assert!((a.length() - 1.0).abs() < 1e-12);
            }
            let d = Vec3::new(0.3, -0.4, 0.2);
            let back = f.to_world(f.to_local(d));
            assert!((back - d).length() < 1e-12);
        }
    }

    /// Against correctly rounded values (Python's `math.erf`, which agrees with 50-digit mpmath).
    #[test]
    fn erf_is_accurate() {
        for (x, e) in [
            (1.0, 0.8427007929497149),
            (-0.5, -0.5204998778130465),
            (2.5, 0.999593047982555),
            (-1.7677669529663689, -0.9875806693484477),
            (1e-3, 0.0011283787909692363),
        ] {
            assert!((erf(x) - e).abs() <= 1e-15 * e.abs(), "erf({x}) = {} vs {e}", erf(x));
        }
        // 1 + erf(-3.5355...) = erfc(3.5355...) = 5.733031437583873e-07 to 1e-9 relative.
        assert!(((1.0 + erf(-3.5355339059327378)) / 5.733031437583873e-7 - 1.0).abs() < 1e-9);
        assert_eq!(erf(0.0), 0.0);
        assert_eq!(erf(7.0), 1.0);
        assert_eq!(erf(-7.0), -1.0);
    }

    #[test]
    fn reflect_mirrors_about_the_normal() {
        let wo = Vec3::new(0.0, -1.0, 1.0).normalize();
        let r = wo.reflect(Vec3::Z);
        assert!((r - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-12);
    }
}

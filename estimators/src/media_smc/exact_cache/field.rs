//! The converged radiance field of `gradient-box` (paper 000 Eq. 5-6 in a homogeneous cube with an
//! isotropic phase function): the in-scattered radiance `L_i(x)` on a grid of nodes, solved by
//! source iteration, and the incident radiance `L(x, w)` at any point and direction from it.
//!
//! With `L_e = 0` and the isotropic phase `1 / 4 pi`, Eq. 5 and 6 read
//! `L_i(x) = (1 / 4 pi) \int L(x, w) dw` and
//! `L(x, w) = exp(-sigma_t d) L_b(w) + a \int_0^d sigma_t exp(-sigma_t s) L_i(x + s w) ds`, `d` the
//! distance from `x` to the cube's boundary along `w` (the radiance arriving at `x` from
//! direction `w`, `L_b` the background seen along `w`). The solver discretises the sphere into
//! `m x m` cells of equal solid angle (`s = phi / 2 pi`, `t = (1 - cos theta) / 2`, paper 000 §4.1),
//! the ray integral into `k` segments whose weights `exp(-sigma_t s_j) - exp(-sigma_t s_{j+1})`
//! are exact for a constant `L_i` per segment (taken at the segment's midpoint), and `L_i` into
//! trilinear interpolation between `n^3` nodes spanning the cube (boundaries included). Starting
//! from `L_i = 0` each sweep adds one more order of scattering; it stops when no node changes by
//! more than [`TOLERANCE`] of the largest value.

use mcbench_core::lighting::Gradient;
use mcbench_core::math::{Rgb, Vec3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// A sweep that changes no node by more than this fraction of the largest value ends the solve.
pub const TOLERANCE: f64 = 1e-8;

/// The most sweeps (each one more order of scattering).
pub const MAX_SWEEPS: usize = 2000;

/// The scene the field solves: the cube `[-0.5, 0.5]^3` of homogeneous medium under `background`.
#[derive(Clone, Copy, Debug)]
pub struct BoxScene {
    /// Extinction.
    pub sigma_t: f64,
    /// Single-scattering albedo.
    pub albedo: f64,
    /// The background `L_b`.
    pub background: Gradient,
}

/// The discretisation: `n^3` nodes, `m x m` direction cells, `k` segments per ray.
#[derive(Clone, Copy, Debug)]
pub struct Resolution {
    /// Nodes per axis (at least 2).
    pub n: usize,
    /// Direction cells per spherical coordinate.
    pub m: usize,
    /// Segments per ray integral.
    pub k: usize,
}

/// The direction at the point `(s, t)` of the unit square (equal solid angle per area).
pub fn direction(s: f64, t: f64) -> Vec3 {
    let (phi, cos) = (2.0 * PI * s, 1.0 - 2.0 * t);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

/// The distance from `x` (inside the cube) to its boundary along `w`.
pub fn exit_distance(x: Vec3, w: Vec3) -> f64 {
    let axis = |p: f64, d: f64| {
        if d > 0.0 {
            (0.5 - p) / d
        } else if d < 0.0 {
            (-0.5 - p) / d
        } else {
            f64::INFINITY
        }
    };
    axis(x.x, w.x).min(axis(x.y, w.y)).min(axis(x.z, w.z)).max(0.0)
}

/// The solved field.
pub struct Field {
    scene: BoxScene,
    res: Resolution,
    /// `L_i` at the nodes, `x` fastest.
    li: Vec<Rgb>,
    /// Sweeps the solve took.
    pub sweeps: usize,
}

impl Field {
    /// Solves the field of `scene` at `res` by source iteration.
    pub fn solve(scene: BoxScene, res: Resolution) -> Field {
        assert!(res.n >= 2 && res.m >= 1 && res.k >= 1, "a field needs 2 nodes per axis, 1 cell, 1 segment");
        let nodes = res.n * res.n * res.n;
        let dirs: Vec<Vec3> = (0..res.m * res.m)
            .map(|c| direction(((c % res.m) as f64 + 0.5) / res.m as f64, ((c / res.m) as f64 + 0.5) / res.m as f64))
            .collect();
        let mut field = Field { scene, res, li: vec![Rgb::ZERO; nodes], sweeps: 0 };
        while field.sweeps < MAX_SWEEPS {
            let next: Vec<Rgb> = (0..nodes)
                .into_par_iter()
                .map(|i| {
                    let x = field.node(i);
                    let sum = dirs.iter().fold(Rgb::ZERO, |acc, w| acc + field.radiance(x, *w));
                    sum / dirs.len() as f64
                })
                .collect();
            let change =
                next.iter().zip(&field.li).map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max));
            let change = change.fold(0.0, f64::max);
            let largest = next.iter().map(|v| v.0.iter().copied().fold(0.0, f64::max)).fold(0.0, f64::max);
            field.li = next;
            field.sweeps += 1;
            if change <= TOLERANCE * largest.max(f64::MIN_POSITIVE) {
                break;
            }
        }
        field
    }

    /// The scene.
    pub fn scene(&self) -> BoxScene {
        self.scene
    }

    /// The resolution.
    pub fn resolution(&self) -> Resolution {
        self.res
    }

    /// The position of node `i`.
    pub fn node(&self, i: usize) -> Vec3 {
        let n = self.res.n;
        let h = 1.0 / (n - 1) as f64;
        Vec3::new(-0.5 + (i % n) as f64 * h, -0.5 + ((i / n) % n) as f64 * h, -0.5 + (i / (n * n)) as f64 * h)
    }

    /// The node nearest to `x`.
    pub fn nearest_node(&self, x: Vec3) -> usize {
        let n = self.res.n;
        let idx = |p: f64| (((p + 0.5) * (n - 1) as f64).round().max(0.0) as usize).min(n - 1);
        idx(x.x) + n * (idx(x.y) + n * idx(x.z))
    }

    /// `L_i(x)`, trilinear between the nodes (clamped to the cube).
    pub fn in_scattered(&self, x: Vec3) -> Rgb {
        let n = self.res.n;
        let scale = (n - 1) as f64;
        let split = |p: f64| {
            let u = ((p + 0.5) * scale).clamp(0.0, scale);
            let i = (u.floor() as usize).min(n - 2);
            (i, u - i as f64)
        };
        let ((ix, fx), (iy, fy), (iz, fz)) = (split(x.x), split(x.y), split(x.z));
        let at = |dx: usize, dy: usize, dz: usize| self.li[(ix + dx) + n * ((iy + dy) + n * (iz + dz))];
        let lerp = |a: Rgb, b: Rgb, f: f64| a * (1.0 - f) + b * f;
        let y0 = lerp(lerp(at(0, 0, 0), at(1, 0, 0), fx), lerp(at(0, 1, 0), at(1, 1, 0), fx), fy);
        let y1 = lerp(lerp(at(0, 0, 1), at(1, 0, 1), fx), lerp(at(0, 1, 1), at(1, 1, 1), fx), fy);
        lerp(y0, y1, fz)
    }

    /// `L(x, w)`: the radiance arriving at `x` from direction `w` (Eq. 6 over the field).
    pub fn radiance(&self, x: Vec3, w: Vec3) -> Rgb {
        let BoxScene { sigma_t, albedo, background } = self.scene;
        let d = exit_distance(x, w);
        let mut l = background.eval(w) * (-sigma_t * d).exp();
        if albedo > 0.0 && d > 0.0 {
            let step = d / self.res.k as f64;
            let mut before = 1.0;
            for j in 0..self.res.k {
                let after = (-sigma_t * step * (j + 1) as f64).exp();
                l += self.in_scattered(x + w * (step * (j as f64 + 0.5))) * (albedo * (before - after));
                before = after;
            }
        }
        l
    }
}

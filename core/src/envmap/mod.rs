//! Lat-long environment maps (paper 004; book: testbeds.md): a piecewise-constant table of texels
//! (tabulated from any radiance function, e.g. an analytic HDR sky, with [`EnvMap::tabulate`]), its
//! importance sampler ([`sampling::PiecewiseConstant2D`]), and one frame of a dynamic sequence
//! ([`EnvFrame`]: a map rotated about +z and scaled).
//!
//! Convention: row `i` of `H` covers `theta` in `[i pi / H, (i + 1) pi / H]` (row 0 at the zenith
//! +z), column `j` of `W` covers `phi` in `[2 pi j / W, 2 pi (j + 1) / W]`, with
//! `w = (sin theta cos phi, sin theta sin phi, cos theta)`.

pub mod sampling;

use crate::brdf::DirectionSample;
use crate::error::ConfigError;
use crate::math::{Rgb, Vec3};
use rand::Rng;
use sampling::PiecewiseConstant2D;
use std::f64::consts::{PI, TAU};

/// A piecewise-constant lat-long environment map with its sampler.
#[derive(Clone, Debug)]
pub struct EnvMap {
    width: usize,
    height: usize,
    texels: Vec<Rgb>,
    sampler: PiecewiseConstant2D,
}

impl EnvMap {
    /// A map of `width x height` texels (row-major from the zenith). Texels must be finite and
    /// non-negative and at least one must be bright (the sampler needs mass).
    pub fn new(width: usize, height: usize, texels: Vec<Rgb>) -> Result<Self, ConfigError> {
        if width < 2 || height < 2 || texels.len() != width * height {
            return Err(ConfigError::invalid(
                "envmap",
                format!("{width}x{height}"),
                "needs at least 2x2 texels, one value each",
            ));
        }
        if texels.iter().any(|t| !t.is_finite() || t.0.iter().any(|&c| c < 0.0)) {
            return Err(ConfigError::invalid("envmap", "texels", "radiance must be finite and >= 0"));
        }
        let scalar: Vec<f64> = texels.iter().map(|t| t.mean()).collect();
        let sampler = PiecewiseConstant2D::new(width, height, &scalar)?;
        Ok(EnvMap { width, height, texels, sampler })
    }
    /// Tabulates `radiance` at the texel centres (in `(cos theta, phi)`: the centre of solid angle).
    pub fn tabulate(width: usize, height: usize, radiance: impl Fn(Vec3) -> Rgb) -> Result<Self, ConfigError> {
        let g = LatLong { width, height };
        let mut texels = Vec::with_capacity(width * height);
        for i in 0..height {
            let c = 0.5 * (g.cos_edge(i) + g.cos_edge(i + 1));
            for j in 0..width {
                let phi = (j as f64 + 0.5) * TAU / width as f64;
                texels.push(radiance(crate::samplers::spherical_direction(c, phi)));
            }
        }
        Self::new(width, height, texels)
    }
    /// The grid.
    pub fn grid(&self) -> LatLong {
        LatLong { width: self.width, height: self.height }
    }
    /// Texel value by index.
    pub fn texel(&self, t: usize) -> Rgb {
        self.texels[t]
    }
    /// All texels, row-major.
    pub fn texels(&self) -> &[Rgb] {
        &self.texels
    }
    /// The sampler.
    pub fn sampler(&self) -> &PiecewiseConstant2D {
        &self.sampler
    }
    /// Radiance from direction `w` (unrotated).
    pub fn radiance(&self, w: Vec3) -> Rgb {
        self.texels[self.grid().texel_of(w, 0.0)]
    }
    /// Ratio of the brightest to the dimmest non-zero texel (channel means).
    pub fn dynamic_range(&self) -> f64 {
        let s = self.texels.iter().map(|t| t.mean()).filter(|&v| v > 0.0);
        let (lo, hi) = s.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
        hi / lo
    }
}

/// The lat-long texel grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LatLong {
    /// Columns (in `phi`).
    pub width: usize,
    /// Rows (in `theta`).
    pub height: usize,
}

impl LatLong {
    /// `cos(theta)` at the upper edge of row `i` (row `height` is the nadir edge).
    pub fn cos_edge(&self, i: usize) -> f64 {
        if 2 * i == self.height {
            return 0.0; // the equator exactly (the visibility boundary: the ground plane z = -1)
        }
        (i as f64 * PI / self.height as f64).cos()
    }
    /// Exact solid angle of one texel of row `i`: `(cos theta_i - cos theta_{i+1}) 2 pi / W`.
    pub fn solid_angle(&self, i: usize) -> f64 {
        (self.cos_edge(i) - self.cos_edge(i + 1)) * TAU / self.width as f64
    }
    /// The texel index of direction `w` in a map rotated by `rotation` radians about +z.
    pub fn texel_of(&self, w: Vec3, rotation: f64) -> usize {
        let theta = w.z.clamp(-1.0, 1.0).acos();
        let row = ((theta / PI * self.height as f64) as usize).min(self.height - 1);
        let phi = (w.y.atan2(w.x) - rotation).rem_euclid(TAU);
        let col = ((phi / TAU * self.width as f64) as usize).min(self.width - 1);
        row * self.width + col
    }
}

/// One frame of a dynamic environment: `L_n(w) = scale * map(R_z(-rotation) w)`.
#[derive(Clone, Copy, Debug)]
pub struct EnvFrame<'a> {
    /// The map.
    pub map: &'a EnvMap,
    /// Rotation about +z in radians.
    pub rotation: f64,
    /// Intensity scale (> 0).
    pub scale: f64,
}

impl EnvFrame<'_> {
    /// Radiance arriving from direction `w`.
    pub fn radiance(&self, w: Vec3) -> Rgb {
        self.map.texels[self.map.grid().texel_of(w, self.rotation)] * self.scale
    }
    /// A direction drawn proportionally to channel-mean radiance per solid angle, with its density.
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> DirectionSample {
        let (cos_theta, phi, pdf) = self.map.sampler.sample(rng);
        DirectionSample { w: crate::samplers::spherical_direction(cos_theta, phi + self.rotation), pdf }
    }
    /// The density of [`EnvFrame::sample`] per unit solid angle.
    pub fn pdf(&self, w: Vec3) -> f64 {
        self.map.sampler.pdf_of_texel(self.map.grid().texel_of(w, self.rotation))
    }
}

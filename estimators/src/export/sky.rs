//! The gradient sky `max(0, c0 + c1 w_z + c2 w_x)` as a latitude-longitude bitmap in Mitsuba 3's
//! `envmap` layout, written as PFM.
//!
//! Mitsuba's `envmap` reads its bitmap in a local frame with +y up: texel column `i` of `W` is at
//! longitude `u = (i + 1/2) / W`, row `j` of `H` at colatitude `v = j / (H - 1)` (the first and
//! last rows on the poles), the local direction of `(u, v)` being
//! `(sin(pi v) sin(2 pi u), cos(pi v), -sin(pi v) cos(2 pi u))`, and it interpolates bilinearly.
//! The scene's `to_world` maps local (x, y, z) to world (x, -z, y), so world
//! `(sin(pi v) sin(2 pi u), sin(pi v) cos(2 pi u), cos(pi v))`: +z up, as the test beds.

use mcbench_core::lighting::Gradient;
use mcbench_core::math::Vec3;

/// Width of the bitmap (its height is half): the interpolation's error against the exact sky
/// (book: exported-beds.md) is far below what the unbiasedness tests detect.
pub const WIDTH: usize = 512;

/// `to_world` of the envmap as a Mitsuba 4x4 matrix (row major).
pub const TO_WORLD: &str = "1 0 0 0 0 0 -1 0 0 1 0 0 0 0 0 1";

/// The world direction of texel `(i, j)` of a `w x h` bitmap.
pub fn texel_direction(i: usize, j: usize, w: usize, h: usize) -> Vec3 {
    let phi = std::f64::consts::TAU * (i as f64 + 0.5) / w as f64;
    let theta = std::f64::consts::PI * j as f64 / (h - 1) as f64;
    Vec3::new(theta.sin() * phi.sin(), theta.sin() * phi.cos(), theta.cos())
}

/// The sky clamped at zero over the whole sphere (the plane sees only the upper hemisphere, where
/// the gradient is positive), as the bytes of a little-endian PFM file (rows bottom to top).
pub fn pfm(sky: &Gradient, w: usize) -> Vec<u8> {
    let h = w / 2;
    let clamped = Gradient { clamp: true, ..*sky };
    let mut out = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    out.reserve(w * h * 12);
    for j in (0..h).rev() {
        for i in 0..w {
            for c in clamped.eval(texel_direction(i, j, w, h)).0 {
                out.extend((c as f32).to_le_bytes());
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_run_from_zenith_to_nadir_and_the_file_is_bottom_up() {
        assert!((texel_direction(3, 0, 8, 4).z - 1.0).abs() < 1e-12);
        assert!((texel_direction(3, 3, 8, 4).z + 1.0).abs() < 1e-12);
        let bytes = pfm(&Gradient::papers(), 8);
        let header = b"PF\n8 4\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        assert_eq!(bytes.len(), header.len() + 8 * 4 * 12);
        // The first value stored is the bottom row (the nadir): red max(0, 1 - 1) = 0.
        let first = f32::from_le_bytes(bytes[header.len()..header.len() + 4].try_into().unwrap());
        assert!(first.abs() < 1e-6);
        // The last row stored is the zenith: blue 0.6 + 1.5.
        let last = f32::from_le_bytes(bytes[bytes.len() - 4..].try_into().unwrap());
        assert!((last - 2.1).abs() < 1e-6);
    }
}

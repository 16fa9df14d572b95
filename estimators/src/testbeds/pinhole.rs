//! A pinhole camera through pixel centres (`gradient-plane`, `checker-direct`).

use mcbench_core::math::Vec3;

/// A pinhole camera with a square image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinhole {
    /// Eye position.
    pub eye: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    tan_half_fov: f64,
}

impl Pinhole {
    /// A camera at `eye` looking at `target` with world `up` and vertical field of view in degrees.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, vfov_degrees: f64) -> Self {
        let forward = (target - eye).normalize();
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        Pinhole { eye, forward, right, up, tan_half_fov: (vfov_degrees.to_radians() * 0.5).tan() }
    }
    /// Unit direction through the centre of pixel `(px, py)` of a `size x size` image (row 0 at
    /// the top).
    pub fn pixel_direction(&self, px: usize, py: usize, size: usize) -> Vec3 {
        self.image_direction(px as f64 + 0.5, py as f64 + 0.5, size)
    }
    /// Unit direction through image position `(sx, sy)` in `[0, size)^2` (pixel `(px, py)` covers
    /// `[px, px + 1) x [py, py + 1)`; row 0 at the top).
    pub fn image_direction(&self, sx: f64, sy: f64, size: usize) -> Vec3 {
        let x = (2.0 * sx / size as f64 - 1.0) * self.tan_half_fov;
        let y = (1.0 - 2.0 * sy / size as f64) * self.tan_half_fov;
        (self.forward + self.right * x + self.up * y).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_of_an_odd_image_looks_at_the_target() {
        let cam = Pinhole::look_at(Vec3::new(0.0, -3.0, 2.0), Vec3::default(), Vec3::Z, 40.0);
        let d = cam.pixel_direction(1, 1, 3);
        assert!((d - Vec3::new(0.0, 3.0, -2.0).normalize()).length() < 1e-12);
        // The top row looks further up than the bottom row.
        assert!(cam.pixel_direction(1, 0, 3).z > cam.pixel_direction(1, 2, 3).z);
    }
}

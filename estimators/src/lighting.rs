//! Analytic lighting shared by the test beds.

use crate::math::{Rgb, Vec3};
use serde::{Deserialize, Serialize};

/// The gradient background of papers 000/001: `L_b(w) = c0 + c1 w_z + c2 w_x` per channel
/// (SPEC §3.1), optionally clamped at zero per channel (SPEC §3.2, whole sphere).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gradient {
    /// Constant term per channel.
    pub c0: Rgb,
    /// Coefficient of `w_z` per channel.
    pub c1: Rgb,
    /// Coefficient of `w_x` per channel.
    pub c2: Rgb,
    /// Clamp negative radiance to zero (needed where `w_z < 0` is seen).
    pub clamp: bool,
}

impl Gradient {
    /// The SPEC §3.1 coefficients: R (1.0, 1.0, 0.5), G (0.8, 1.2, 0.0), B (0.6, 1.5, -0.4).
    pub const fn papers() -> Gradient {
        Gradient { c0: Rgb([1.0, 0.8, 0.6]), c1: Rgb([1.0, 1.2, 1.5]), c2: Rgb([0.5, 0.0, -0.4]), clamp: false }
    }
    /// Radiance arriving from direction `w` (unit vector leaving the scene).
    pub fn eval(&self, w: Vec3) -> Rgb {
        let l = self.c0 + self.c1 * w.z + self.c2 * w.x;
        if self.clamp {
            l.map(|c| c.max(0.0))
        } else {
            l
        }
    }
}

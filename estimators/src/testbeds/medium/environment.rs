//! The environment lighting of the media test beds (book: testbeds.md): the `gradient-plane`
//! gradient over the whole sphere (clamped at zero per channel, as `gradient-box` does for
//! directions below the horizon) plus a white HDR sun lobe `200 exp(100 (w . s - 1))`,
//! `s = normalize(1, 1, 2)`.

use mcbench_core::lighting::Gradient;
use mcbench_core::math::{Rgb, Vec3};

/// Sun lobe peak radiance.
pub const SUN_PEAK: f64 = 200.0;
/// Sun lobe sharpness.
pub const SUN_SHARPNESS: f64 = 100.0;

/// The environment radiance from direction `w` (unit, leaving the scene).
pub fn radiance(w: Vec3) -> Rgb {
    let g = Gradient { clamp: true, ..Gradient::papers() };
    let s = Vec3::new(1.0, 1.0, 2.0).normalize();
    g.eval(w) + Rgb::splat(SUN_PEAK * (SUN_SHARPNESS * (w.dot(s) - 1.0)).exp())
}

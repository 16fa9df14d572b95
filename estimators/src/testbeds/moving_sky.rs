//! The HDR map of the `moving` variants of `envmap-sequence`: bright features that move under a
//! rotation about +z, closer to the maps of paper 004 §7 than the default [`super::sky::Sky`].
//!
//! Paper 004 measures its resampled shares (§7: 36% of pixels per frame with one distribution and
//! 5 MH moves, 18% with 5 bridges) in the Grace Cathedral map rotated 1.5 degrees a frame, and
//! renders the sky probe gallery: natural HDR maps whose energy sits in a few small, very bright
//! sources (windows and lamps at several heights; the sun) over a dim, uneven background. Under a
//! rotation about the vertical the default sky's gradient stays put and only its sun moves the
//! target, so almost no pixel resamples. This map keeps the default's gradient colours, dimmed,
//! and adds:
//!
//! - a background brighter on one side, `1 + 0.6 (w . h)` with `h` horizontal at azimuth 30
//!   degrees (a nave lit from one side; the sky brighter towards the sun): not symmetric about
//!   the rotation axis, so it moves too;
//! - five narrow lobes `peak exp(k (w . d - 1))` off the axis at elevations 8 to 62 degrees (a
//!   rotation moves a feature at elevation `e` by `cos e` times the angle). Their widths
//!   `1 / sqrt(k)` of 1.0 to 1.6 degrees are about one texel of the default 256x128 map (1.4
//!   degrees), the narrowest it resolves: Grace Cathedral's lamps and the sun are smaller still.
//!   The key lobe's peak is the `sun` parameter (1e3 by default: with the ground at 0.02 the
//!   tabulated map spans a dynamic range of 4e4, above the test bed's 1e4 and below Grace
//!   Cathedral's of about 2e5); the other four have peaks of 100 to 300. A lobe's power is about `2 pi peak / k`:
//!   0.4 to 0.8 of the whole background's (about 1.2) for each of the four, 2.6 times it for the
//!   key lobe, so the lobes hold about 80% of the map's energy, as the windows and lamps do.

use super::sky::{direction, Lobe, SkyModel};
use mcbench_core::math::{Rgb, Vec3};

/// The map of the `moving` variants.
#[derive(Clone, Debug, PartialEq)]
pub struct MovingSky {
    /// Background radiance at the horizon (before the one-sided factor).
    pub horizon: Rgb,
    /// Background radiance at the zenith (before the one-sided factor).
    pub zenith: Rgb,
    /// Radiance of the ground (below the horizon).
    pub ground: Rgb,
    /// Horizontal direction the background brightens towards.
    pub bright_side: Vec3,
    /// Strength of the one-sided factor `1 + strength (w . bright_side)` (below 1).
    pub strength: f64,
    /// The key lobe (peak: the `sun` parameter).
    pub key: Lobe,
    /// The other bright features.
    pub lobes: [Lobe; 4],
    /// Multiplier of everything but the key lobe (dawn to dusk).
    pub sky_scale: f64,
    /// Multiplier of the key lobe (dawn to dusk).
    pub sun_scale: f64,
}

impl MovingSky {
    /// The map with a key lobe of peak radiance `sun_peak`.
    pub fn with_key(sun_peak: f64) -> MovingSky {
        let lobe = |elevation: f64, azimuth: f64, peak: f64, sharpness: f64, colour: [f64; 3]| Lobe {
            dir: direction(elevation, azimuth),
            peak,
            sharpness,
            colour: Rgb(colour),
        };
        MovingSky {
            horizon: Rgb([0.3, 0.27, 0.23]),
            zenith: Rgb([0.07, 0.12, 0.27]),
            ground: Rgb([0.024, 0.021, 0.018]),
            bright_side: direction(0.0, 30.0),
            strength: 0.6,
            key: lobe(25.0, 40.0, sun_peak, 2000.0, [1.0, 0.9, 0.7]),
            lobes: [
                lobe(8.0, 250.0, 200.0, 1300.0, [0.9, 0.9, 1.0]),
                lobe(42.0, 150.0, 300.0, 3000.0, [1.0, 0.8, 0.6]),
                lobe(62.0, 320.0, 100.0, 1300.0, [1.0, 0.95, 0.9]),
                lobe(18.0, 200.0, 150.0, 2000.0, [0.8, 0.85, 1.0]),
            ],
            sky_scale: 1.0,
            sun_scale: 1.0,
        }
    }
}

impl SkyModel for MovingSky {
    /// As [`super::sky::Sky::at_time`]: the background and the other lobes scale as
    /// `0.2 + 0.8 sin(pi t)`, the key lobe as `sin(pi t)^2`.
    fn at_time(&self, t: f64) -> Self {
        let s = (std::f64::consts::PI * t).sin().max(0.0);
        MovingSky { sky_scale: 0.2 + 0.8 * s, sun_scale: (s * s).max(1e-3), ..self.clone() }
    }
    fn radiance(&self, w: Vec3) -> Rgb {
        let base = if w.z >= 0.0 {
            let t = w.z.sqrt();
            (self.horizon * (1.0 - t) + self.zenith * t) * (1.0 + self.strength * w.dot(self.bright_side))
        } else {
            self.ground
        };
        let lobes = self.lobes.iter().fold(Rgb::ZERO, |sum, l| sum + l.eval(w));
        (base + lobes) * self.sky_scale + self.key.eval(w) * self.sun_scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lobe is off the rotation axis (so a rotation moves it) and the background differs
    /// between opposite azimuths at equal elevation (so it moves too).
    #[test]
    fn features_are_off_axis_and_the_background_is_one_sided() {
        let sky = MovingSky::with_key(1e3);
        for l in std::iter::once(&sky.key).chain(&sky.lobes) {
            assert!(l.dir.z.abs() < 0.9 && l.dir.z > 0.0, "{:?}", l.dir);
        }
        let (east, west) = (direction(30.0, 30.0), direction(30.0, 210.0));
        let off = Lobe { peak: 0.0, ..sky.key };
        let dim = |w: Vec3| MovingSky { key: off, lobes: [off; 4], ..sky.clone() }.radiance(w);
        assert!(dim(east).mean() > 3.0 * dim(west).mean(), "{:?} vs {:?}", dim(east), dim(west));
        // The key lobe's peak is the parameter (the tabulated map's dynamic range is 4e4 at 1e3).
        assert!((sky.radiance(sky.key.dir).mean() / 1e3 - 0.87).abs() < 0.02);
    }
}

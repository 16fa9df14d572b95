//! The analytic HDR sky of `envmap-sequence`: a gradient (horizon to zenith, dim ground) plus one strong
//! sun lobe and two dim lobes, `peak * colour * exp(k (w . d - 1))` each. With the default sun
//! peak of 1e3 the tabulated 256x128 map spans a dynamic range above 1e4; `sun = 1e5` gives 1e6.

use mcbench_core::math::{Rgb, Vec3};

/// One exponential lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobe {
    /// Unit direction of the lobe centre.
    pub dir: Vec3,
    /// Peak radiance multiplier.
    pub peak: f64,
    /// Sharpness `k` (angular width about `1 / sqrt(k)` radians).
    pub sharpness: f64,
    /// Colour.
    pub colour: Rgb,
}

impl Lobe {
    /// Radiance of the lobe towards `w`.
    pub fn eval(&self, w: Vec3) -> Rgb {
        self.colour * (self.peak * (self.sharpness * (w.dot(self.dir) - 1.0)).exp())
    }
}

/// The sky: `gradient(w) * sky_scale + sun * sun_scale + lobes * sky_scale`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sky {
    /// Radiance at the horizon.
    pub horizon: Rgb,
    /// Radiance at the zenith.
    pub zenith: Rgb,
    /// Radiance of the ground (below the horizon).
    pub ground: Rgb,
    /// The sun.
    pub sun: Lobe,
    /// Two dim lobes.
    pub lobes: [Lobe; 2],
    /// Multiplier of everything but the sun (dawn to dusk).
    pub sky_scale: f64,
    /// Multiplier of the sun (dawn to dusk).
    pub sun_scale: f64,
}

/// The unit direction at `elevation_deg` above the horizon and `azimuth_deg` from +x towards +y.
pub fn direction(elevation_deg: f64, azimuth_deg: f64) -> Vec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
}

/// An analytic HDR map the test bed tabulates, with its dawn-to-dusk course.
pub trait SkyModel: Sized {
    /// The map at time `t` in [0, 1] of a dawn-to-dusk day.
    fn at_time(&self, t: f64) -> Self;
    /// Radiance arriving from direction `w`.
    fn radiance(&self, w: Vec3) -> Rgb;
}

impl SkyModel for Sky {
    fn at_time(&self, t: f64) -> Self {
        Sky::at_time(self, t)
    }
    fn radiance(&self, w: Vec3) -> Rgb {
        Sky::radiance(self, w)
    }
}

impl Sky {
    /// The default sky with a sun of peak radiance `sun_peak`.
    pub fn default_with_sun(sun_peak: f64) -> Sky {
        Sky {
            horizon: Rgb([0.9, 0.8, 0.7]),
            zenith: Rgb([0.2, 0.35, 0.8]),
            ground: Rgb([0.08, 0.07, 0.06]),
            sun: Lobe { dir: direction(35.0, 40.0), peak: sun_peak, sharpness: 800.0, colour: Rgb([1.0, 0.9, 0.7]) },
            lobes: [
                Lobe { dir: direction(10.0, 200.0), peak: 8.0, sharpness: 30.0, colour: Rgb([0.6, 0.7, 1.0]) },
                Lobe { dir: direction(60.0, 290.0), peak: 4.0, sharpness: 60.0, colour: Rgb([1.0, 0.6, 0.5]) },
            ],
            sky_scale: 1.0,
            sun_scale: 1.0,
        }
    }
    /// The same sky at time `t` in [0, 1] of a dawn-to-dusk day: the sky brightens and dims as
    /// `0.2 + 0.8 sin(pi t)`, the sun as `sin(pi t)^2` (so the sun-to-sky ratio changes too).
    pub fn at_time(&self, t: f64) -> Sky {
        let s = (std::f64::consts::PI * t).sin().max(0.0);
        Sky { sky_scale: 0.2 + 0.8 * s, sun_scale: (s * s).max(1e-3), ..self.clone() }
    }
    /// Radiance arriving from direction `w`.
    pub fn radiance(&self, w: Vec3) -> Rgb {
        let base = if w.z >= 0.0 {
            let t = w.z.sqrt();
            self.horizon * (1.0 - t) + self.zenith * t
        } else {
            self.ground
        };
        (base + self.lobes[0].eval(w) + self.lobes[1].eval(w)) * self.sky_scale + self.sun.eval(w) * self.sun_scale
    }
}

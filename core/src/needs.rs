//! [`Needs`]: what a test bed provides and what an estimator needs, as a small bit set of scene
//! views (book: extending.md).

use std::fmt;

/// What a test bed provides and what an estimator needs (a small bit set).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Needs(u32);

impl Needs {
    /// Nothing.
    pub const NONE: Needs = Needs(0);
    /// Hemispherical surface integrals ([`HemisphereScene`](crate::testbed::HemisphereScene)).
    pub const SURFACE: Needs = Needs(1);
    /// A participating medium (fetches are counted).
    pub const MEDIUM: Needs = Needs(2);
    /// A point light.
    pub const POINT_LIGHT: Needs = Needs(4);
    /// A sequence of environment maps (frames).
    pub const ENV_SEQUENCE: Needs = Needs(8);
    /// Area lights that can be sampled.
    pub const AREA_LIGHTS: Needs = Needs(16);
    /// Pixel integrals over the image plane, sampled at chosen positions ([`ImagePlaneScene`](crate::testbed::ImagePlaneScene)).
    pub const IMAGE_PLANE: Needs = Needs(32);
    /// A generic integrand on a named domain ([`crate::integrand::Integrand`]).
    pub const INTEGRAND: Needs = Needs(64);
    const NAMES: [(Needs, &'static str); 7] = [
        (Needs::SURFACE, "surface"),
        (Needs::MEDIUM, "medium"),
        (Needs::POINT_LIGHT, "point light"),
        (Needs::ENV_SEQUENCE, "environment sequence"),
        (Needs::AREA_LIGHTS, "area lights"),
        (Needs::IMAGE_PLANE, "image plane"),
        (Needs::INTEGRAND, "integrand"),
    ];
    /// Union of two sets.
    pub const fn and(self, o: Needs) -> Needs {
        Needs(self.0 | o.0)
    }
    /// True when every member of `o` is in `self`.
    pub fn contains(self, o: Needs) -> bool {
        self.0 & o.0 == o.0
    }
    /// The members of `self` missing from `provided`, or `None` when all are there.
    pub fn missing_from(self, provided: Needs) -> Option<Needs> {
        let m = Needs(self.0 & !provided.0);
        (m.0 != 0).then_some(m)
    }
}

impl fmt::Display for Needs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = Needs::NAMES.iter().filter(|(n, _)| self.contains(*n)).map(|(_, s)| *s).collect();
        if names.is_empty() {
            write!(f, "nothing")
        } else {
            write!(f, "{}", names.join(" + "))
        }
    }
}

//! Cell storage precision of the radiance caches.
//!
//! Paper 001 §5 (Table 1) reports the cache memory "using double-precision" and §6 notes that it
//! "can be trivially halved by using a single-precision floating point representation". The cache
//! is generic over [`Scalar`] (`f64` or `f32`); every computation is done in `f64` and only the
//! stored coefficients are rounded, so the integral `G` is always the exact integral of the `g`
//! reconstructed from the stored values.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A floating-point type the cache cells are stored in.
pub trait Scalar: Copy + Default + PartialEq + Send + Sync + std::fmt::Debug + 'static {
    /// The name used in parameters and reports (`f32` or `f64`).
    const NAME: &'static str;
    /// The stored value as `f64` (exact).
    fn get(self) -> f64;
    /// Rounds to nearest.
    fn put(v: f64) -> Self;
    /// Rounds to nearest but never turns a positive value into zero: the inheritance rule of paper
    /// 001 §4.3 (a PDF coefficient, once positive, stays positive) must survive the rounding.
    fn put_positive(v: f64) -> Self;
}

impl Scalar for f64 {
    const NAME: &'static str = "f64";
    fn get(self) -> f64 {
        self
    }
    fn put(v: f64) -> Self {
        v
    }
    fn put_positive(v: f64) -> Self {
        v
    }
}

impl Scalar for f32 {
    const NAME: &'static str = "f32";
    fn get(self) -> f64 {
        f64::from(self)
    }
    fn put(v: f64) -> Self {
        v as f32
    }
    fn put_positive(v: f64) -> Self {
        let x = v as f32;
        if v > 0.0 && x == 0.0 {
            // Below half the smallest f32 subnormal: keep the smallest positive value instead.
            f32::from_bits(1)
        } else {
            x
        }
    }
}

/// The storage choice of an estimator (parameter `storage`, the text `"f32"` or `"f64"`, default
/// `f64`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
#[schemars(inline)]
pub enum Storage {
    /// Single precision: 20 bytes per cell.
    F32,
    /// Double precision (the paper's): 36 bytes per cell.
    #[default]
    F64,
}

impl Storage {
    /// The name (`f32` or `f64`).
    pub fn name(self) -> &'static str {
        match self {
            Storage::F32 => f32::NAME,
            Storage::F64 => f64::NAME,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positive_values_never_round_to_zero_and_the_parameter_is_a_name() {
        assert_eq!(<f32 as Scalar>::put_positive(1e-300), f32::from_bits(1));
        assert_eq!(<f32 as Scalar>::put_positive(0.0), 0.0);
        assert_eq!(<f32 as Scalar>::put(0.5).get(), 0.5);
        let parse = |v: serde_json::Value| serde_json::from_value::<Storage>(v).map_err(|e| e.to_string());
        assert_eq!(parse(serde_json::json!("f32")), Ok(Storage::F32));
        assert_eq!(parse(serde_json::json!("f64")), Ok(Storage::F64));
        assert!(parse(serde_json::json!("f16")).is_err());
        assert!(parse(serde_json::json!(32)).is_err());
        assert_eq!(serde_json::to_value(Storage::default()).ok(), Some(serde_json::json!("f64")));
        for s in [Storage::F32, Storage::F64] {
            assert_eq!(serde_json::to_value(s).ok(), Some(serde_json::json!(s.name())));
        }
    }
}

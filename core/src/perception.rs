//! The threshold-versus-intensity function of Ferwerda et al. 1996 (photopic branch), used by
//! paper 003 for PMC-IP's kernel (§4.2) and for its perceptual error `Err = mean e^2 / tvi(L)`
//! and `P-Eff = 1 / (T Err)` (§4.4). Radiance values are read as cd/m^2.

/// `tvi(L)`: the just-noticeable luminance difference at adaptation luminance `l` (photopic):
/// `log10 tvi = -0.72` for `log10 L <= -2.6`, `log10 L - 1.255` for `log10 L >= 1.9`, and
/// `(0.249 log10 L + 0.65)^2.7 - 0.72` between. Always positive; `L <= 0` gives the floor.
pub fn tvi(l: f64) -> f64 {
    let lg = if l > 0.0 { l.log10() } else { f64::NEG_INFINITY };
    let t = if lg <= -2.6 {
        -0.72
    } else if lg >= 1.9 {
        lg - 1.255
    } else {
        (0.249 * lg + 0.65).powf(2.7) - 0.72
    };
    10f64.powf(t)
}

/// Luminance of a linear RGB triple (Rec. 709 weights).
pub fn luminance(c: crate::math::Rgb) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tvi_is_positive_continuous_and_increasing() {
        assert!((tvi(0.0) - 10f64.powf(-0.72)).abs() < 1e-12);
        for lg in [-2.6, 1.9] {
            let (a, b) = (tvi(10f64.powf(lg - 1e-9)), tvi(10f64.powf(lg + 1e-9)));
            assert!((a - b).abs() < 1e-2 * a, "{lg}: {a} {b}");
        }
        let mut last = 0.0;
        for k in -40..40 {
            let v = tvi(10f64.powf(k as f64 / 10.0));
            assert!(v >= 0.99 * last && v > 0.0);
            last = v;
        }
    }
}

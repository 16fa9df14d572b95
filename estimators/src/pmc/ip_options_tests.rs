//! Tests of PMC-IP's options (paper 003 §4.2): the kernel weights under `allocate` and
//! `luminance_scale` (their unbiasedness is tested with the sampler's, in `ip_tests.rs`).

use super::*;
use crate::params::{ParamValue, Params};

fn with_text(name: &str, v: &str) -> Params {
    let mut p = Params::new();
    p.0.insert(name.into(), ParamValue::Text(v.into()));
    p
}

/// The options' defaults are the paper's rule (`luminance_scale` 1 reads radiance as cd/m^2),
/// and the scale and `std_dev` change the weights as documented.
#[test]
fn allocation_options_change_the_kernel_weights_as_documented() {
    let mut stats = vec![Moments::default(); 3];
    stats[0].extend([0.5, 1.5]);
    stats[1].extend([10.0, 30.0]);
    stats[2].extend([0.0, 0.0]);
    let base = PmcIp::from_params(&Params::new()).unwrap();
    let one = PmcIp::from_params(&Params::new().with("luminance_scale", 1.0)).unwrap();
    assert_eq!(base.weights(&stats), one.weights(&stats));
    let (s, eps) = (10.0, base.eps);
    let scaled = PmcIp::from_params(&Params::new().with("luminance_scale", s)).unwrap();
    let m = &stats[1];
    let expected = eps + s * s * m.variance() / crate::perception::tvi(s * m.mean());
    assert!((scaled.raw_weight(m) - expected).abs() < 1e-12 * expected);
    let sd = PmcIp::from_params(&with_text("allocate", "std_dev")).unwrap();
    let expected = eps + m.variance().sqrt() / crate::perception::tvi(m.mean()).sqrt();
    assert!((sd.raw_weight(m) - expected).abs() < 1e-12 * expected);
    // A noiseless pixel keeps the eps floor under every rule.
    for ip in [&base, &scaled, &sd] {
        assert_eq!(ip.raw_weight(&stats[2]), eps);
    }
    for bad in [("luminance_scale", 0.0), ("luminance_scale", 1e7)] {
        let e = PmcIp::from_params(&Params::new().with(bad.0, bad.1)).unwrap_err().to_string();
        assert!(e.contains(bad.0), "{e}");
    }
    assert!(PmcIp::from_params(&with_text("allocate", "variances")).unwrap_err().to_string().contains("allocate"));
}

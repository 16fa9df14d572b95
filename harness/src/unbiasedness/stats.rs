//! The repetitions that would resolve a 0.1% relative bias, for the `unbiasedness` table (the tests
//! themselves are [`crate::analysis::unbiasedness`]).

/// The relative bias `--full` aims to resolve (0.1%).
pub const TARGET_REL_BIAS: f64 = 1e-3;

/// The repetitions `R'` at which the detectable relative bias `d` (measured at `reps`) would reach
/// [`TARGET_REL_BIAS`], when a share `est_share` of the tested variance comes from the estimates
/// (the rest from a stored reference, which more repetitions do not shrink): `d^2 (s R / R' + 1 - s)
/// = target^2`. `None` when the reference alone is too noisy or `d` is unknown.
pub fn reps_for_target(d: f64, reps: usize, est_share: f64) -> Option<f64> {
    if !d.is_finite() || d <= 0.0 {
        return None;
    }
    let s = est_share.clamp(0.0, 1.0);
    let room = TARGET_REL_BIAS * TARGET_REL_BIAS - (1.0 - s) * d * d;
    // Rounded up, ignoring the last-bit noise of the division.
    (room > 0.0).then(|| (reps as f64 * s * d * d / room - 1e-9).ceil().max(2.0))
}

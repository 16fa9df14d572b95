//! Which integrals and channels of a cell have a spread at all: those whose repetitions (and the
//! gate's) agree to within round-off ([`crate::analysis::roundoff`]) are compared with the reference
//! directly, since a t-test on a spread made of rounding errors measures the arithmetic, not the
//! estimator.

use super::bias::Gate;
use crate::run::cell::CellResult;
use mcbench_core::testbed::Reference;
use serde::{Deserialize, Serialize};

/// How the spread of a tested cell was judged (the `spread` of summary.json's `tests` rows).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Spread {
    /// The repetitions spread beyond round-off (in every integral and channel, or in a cell
    /// without a gate, in some): the t-tests decide.
    #[default]
    Sampled,
    /// Every integral and channel of the cell, and of its gate when there is one, agrees to within
    /// round-off: the mean is compared with the reference directly.
    ZeroVariance,
    /// Behind a gate, some integrals and channels are zero-variance and the rest sampled: the
    /// zero-variance ones are not t-tested on their rounding errors (a mean within an exact
    /// reference's bound joins the per-integral family as an agreement, any other is left
    /// untested: while other integrals vary it may be a rare value the cell and its gate missed),
    /// the rest are tested as before.
    Mixed,
}

impl Spread {
    /// How notes name it.
    pub fn name(self) -> &'static str {
        match self {
            Spread::Sampled => "sampled",
            Spread::ZeroVariance => "zero variance",
            Spread::Mixed => "mixed",
        }
    }
}

/// The zero-variance integrals and channels of a cell.
pub(super) struct ZeroChannels {
    /// Per integral and channel: its round-off bound when its repetitions, and its gate's, spread
    /// no more than that; `None` when it has a spread.
    pub(super) zero: Vec<[Option<f64>; 3]>,
    /// How many are zero-variance.
    pub(super) count: usize,
    /// Integrals times channels.
    pub(super) total: usize,
    /// The largest standard deviation over repetitions among the zero-variance ones: 0 when their
    /// repetitions are all exactly equal.
    pub(super) largest_sd: f64,
}

impl ZeroChannels {
    /// Classifies every integral and channel of `cell` (at least 2 repetitions; none with fewer):
    /// zero-variance when its sample standard deviation, and the gate's (scaled to the cell; when
    /// the gate has one), are at most its round-off bound.
    pub(super) fn of(cell: &CellResult, reference: &Reference, gate: Option<&Gate>) -> ZeroChannels {
        let bounds = crate::analysis::roundoff::bounds(cell, reference);
        let mut largest_sd = 0.0f64;
        let zero: Vec<[Option<f64>; 3]> = cell
            .moments
            .iter()
            .zip(&bounds)
            .enumerate()
            .map(|(i, (m, u))| {
                [0, 1, 2].map(|c| {
                    let sd = m[c].variance().sqrt();
                    let gate_sd = gate.and_then(|g| g.integral_var.get(i)).map_or(f64::NAN, |v| v[c].sqrt());
                    let quiet = m[c].count() >= 2 && sd <= u[c] && (gate_sd.is_nan() || gate_sd <= u[c]);
                    quiet.then(|| {
                        largest_sd = largest_sd.max(sd);
                        u[c]
                    })
                })
            })
            .collect();
        let count = zero.iter().flatten().filter(|z| z.is_some()).count();
        ZeroChannels { count, total: zero.len() * 3, zero, largest_sd }
    }

    /// How the cell's spread is judged: zero variance when every integral and channel is; mixed
    /// when some are and a gate shows the rest are not tails the cell missed (without a gate a
    /// quiet integral of a noisy cell may be a rare-hit one that missed its hits: sampled).
    pub(super) fn spread(&self, gated: bool) -> Spread {
        if self.total > 0 && self.count == self.total {
            Spread::ZeroVariance
        } else if self.count > 0 && gated {
            Spread::Mixed
        } else {
            Spread::Sampled
        }
    }

    /// The round-off bound of integral `i`, channel `c`, when it is zero-variance and the cell's
    /// spread is judged `spread` (never for a sampled cell).
    pub(super) fn direct(&self, spread: Spread, i: usize, c: usize) -> Option<f64> {
        if spread == Spread::Sampled {
            return None;
        }
        self.zero.get(i).and_then(|z| z[c])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::bias::tests::{cell_from, exact};

    #[test]
    fn equal_and_round_off_repetitions_are_zero_variance_and_a_gate_with_spread_vetoes() {
        let r = exact(&[[0.5; 3], [0.25; 3]]);
        // Integral 0 exactly equal, integral 1 a few ulps apart.
        let reps: Vec<Vec<[f64; 3]>> =
            (0..8).map(|k| vec![[0.5; 3], [0.25 + (k % 3) as f64 * 0.25 * f64::EPSILON; 3]]).collect();
        let cell = cell_from(&reps, &r);
        let z = ZeroChannels::of(&cell, &r, None);
        assert_eq!((z.count, z.total), (6, 6));
        assert!(z.largest_sd > 0.0 && z.largest_sd < 1e-16, "{}", z.largest_sd);
        assert_eq!(z.spread(false), Spread::ZeroVariance);
        // A gate that saw spread in integral 1 (a tail the cell missed) makes it sampled.
        let mut noisy = reps.clone();
        noisy[0][1] = [0.3; 3];
        let gate = Gate::from_cell(&cell_from(&noisy, &r), "pilot", 1.0);
        let z = ZeroChannels::of(&cell, &r, Some(&gate));
        assert_eq!((z.count, z.spread(true)), (3, Spread::Mixed));
        assert_eq!(z.direct(Spread::Mixed, 0, 2), Some(crate::analysis::roundoff::bound(0.5, 4.0)));
        assert_eq!(z.direct(Spread::Mixed, 1, 0), None);
        // Without a gate a partly quiet cell is sampled: its quiet integral may have missed a tail.
        let z = ZeroChannels::of(&cell_from(&noisy, &r), &r, None);
        assert_eq!((z.count, z.spread(false)), (3, Spread::Sampled));
        assert_eq!(z.direct(Spread::Sampled, 0, 0), None);
        // A spread of a part in a million is a spread.
        let wide: Vec<Vec<[f64; 3]>> = (0..8).map(|k| vec![[0.5 + 1e-6 * k as f64; 3], [0.25; 3]]).collect();
        assert_eq!(ZeroChannels::of(&cell_from(&wide, &r), &r, None).count, 3);
    }
}

//! Which estimator wins where in `canonical-sweep`: per profile x target T x sigma_samp ratio the
//! unbiased estimator with the lowest measured variance x fetches, with statistical ties marked
//! (the runner-up within two combined error bars of the winner's variance) and exact equivalents
//! merged: at ratio >= 1 (`r <= 1`) ratio tracking *is* the double particle model, and the
//! terminating single particle model keeps the particle with probability `1 - r` exactly as delta
//! tracking does, so each pair is one estimator (`RT/DP`, `DT/ST`) whose two measurements differ by
//! noise only. Written to `winners.csv` and `winners.md`, with and without control variates.

use crate::canonical_cells::{Agreement, CellRow};
use crate::canonical_sweep::{FAMILIES, RATIOS};
use crate::canonical_sweep_post::{short, Analysis};
use mcbench::output::report::{markdown_table, md_text, sig};
use mcbench_core::estimator::Bias;
use mcbench_papers::testbeds::canonical_1d::TARGETS;
use mcbench_papers::testbeds::canonical_profiles::Profile;
use serde::Serialize;

/// Whether a family subtracts a control variate (explorer fetches; exact on some profiles).
pub fn has_cv(family: usize) -> bool {
    FAMILIES[family].control.is_some()
}

/// The winner of one cell.
pub struct Win<'a> {
    /// The winning cell (the better-measured member of an equivalent pair).
    pub best: &'a CellRow,
    /// Its label (`RT/DP`, `DT/ST` for the merged pairs).
    pub label: String,
    /// The runner-up's label when it is within two combined error bars (a statistical tie).
    pub tie: Option<String>,
    /// Whether the winner's variance is resolved by the run.
    pub resolved: bool,
}

impl Win<'_> {
    /// The family whose colour the winner takes: one per merged pair (ratio tracking for `RT/DP`,
    /// delta tracking for `DT/ST`), so equal estimators look equal in the heat maps.
    pub fn colour_family(&self) -> usize {
        let key = match self.label.split('@').next() {
            Some("RT/DP") => "ratio",
            Some("DT/ST") => "delta",
            _ => return self.best.family,
        };
        FAMILIES.iter().position(|f| f.key == key).unwrap_or(self.best.family)
    }
}

/// The label of a family at a ratio, merging the exact equivalents at ratio >= 1 (with `@ratio`
/// when `at`).
fn class_label(r: &CellRow, at: bool) -> String {
    let key = FAMILIES[r.family].key;
    let suffix = match (at, r.ratio) {
        (true, Some(x)) => format!("@{x}"),
        _ => String::new(),
    };
    let label: String = match (key, r.ratio) {
        ("ratio" | "double", Some(x)) if x >= 1.0 => "RT/DP".into(),
        ("delta" | "single-term", Some(x)) if x >= 1.0 => "DT/ST".into(),
        _ if r.ratio.is_none() => short(r),
        _ => FAMILIES[r.family].short.to_string(),
    };
    label + &suffix
}

/// The winner among `candidates` (unbiased cells that ran, by measured relative variance x cost);
/// labels carry `@ratio` when `at` (candidates at several ratios).
pub fn win<'a>(a: &Analysis, candidates: impl Iterator<Item = &'a CellRow>, at: bool) -> Option<Win<'a>> {
    let mut scored: Vec<(&CellRow, f64, String)> = candidates
        .filter(|r| r.claim == Bias::Unbiased)
        .filter_map(|r| r.rel_var_cost().filter(|v| v.is_finite()).map(|v| (r, v, class_label(r, at))))
        .collect();
    scored.sort_by(|x, y| x.1.total_cmp(&y.1));
    let mut seen: Vec<String> = Vec::new();
    scored.retain(|(_, _, label)| {
        let first = !seen.contains(label);
        seen.push(label.clone());
        first
    });
    let (best, score, label) = scored.first()?.clone();
    let err = |r: &CellRow| r.rel_sd().filter(|e| e.is_finite()).unwrap_or(0.0);
    let tie = scored.get(1).and_then(|(r, s, l)| {
        let margin = 2.0 * (err(best).powi(2) + err(r).powi(2)).sqrt() * score;
        (s - score <= margin).then(|| l.clone())
    });
    Some(Win { best, label, tie, resolved: best.agreement(a.z_crit) != Agreement::Unresolved })
}

/// The winner at one (profile, target, ratio), with or without control variates.
pub fn cell_win(a: &Analysis, p: Profile, t: f64, ratio: f64, with_cv: bool) -> Option<Win<'_>> {
    let at = a.rows.iter().filter(|r| r.profile == p && r.target == t && r.ratio == Some(ratio));
    win(a, at.filter(|r| with_cv || !has_cv(r.family)), false)
}

/// The table text of a win: label, `?` when unresolved, `≈X` for a tie.
pub fn cell_text(w: &Win<'_>) -> String {
    let mut s = w.label.clone();
    if !w.resolved {
        s.push('?');
    }
    if let Some(t) = &w.tie {
        s.push_str(&format!(" ≈{t}"));
    }
    s
}

/// One row of `winners.csv`: the winner at one profile, target and ratio, with or without control
/// variates (empty cells where no estimator qualifies).
#[derive(Serialize)]
pub struct WinnerRow {
    /// The extinction profile.
    pub profile: &'static str,
    /// The target transmittance T.
    pub target: f64,
    /// sigma_samp / max sigma_t.
    pub ratio: f64,
    /// Whether estimators with control variates compete.
    pub with_cv: bool,
    /// The winner's label (`RT/DP`, `DT/ST` for the merged equivalents).
    pub winner: Option<String>,
    /// The winning estimator's name in result files.
    pub estimator: Option<String>,
    /// The winner's measured variance x fetches relative to T^2.
    pub rel_var_cost: Option<f64>,
    /// Whether the winner's variance is resolved by the run.
    pub resolved: bool,
    /// The runner-up's label when within two combined error bars (a statistical tie).
    pub tie_with: Option<String>,
}

/// The rows of `winners.csv` and the text of `winners.md`.
pub fn tables(a: &Analysis) -> (Vec<WinnerRow>, String) {
    let mut rows = Vec::new();
    let mut md = String::from(
        "# canonical-sweep: which estimator wins where\n\nLowest measured variance x fetches per estimate (relative to T^2) among the unbiased \
         estimators run at each sigma_samp ratio (columns: sigma_samp / max sigma_t). `?`: the winner's variance is not resolved \
         by the run (heavy tails); `≈X`: X is within two combined error bars (a statistical tie). Labels: DT delta tracking, RT \
         ratio tracking, DP double particle, ST / SN single particle terminating / non-terminating, +L / +M control variate \
         (piecewise-linear / mean main part through explorer points at 0, 0.5, 1: 3 fetches per estimate), RR residual ratio \
         tracking (its own sigma_samp). At ratio >= 1, RT and DP are one estimator, and so are DT and ST (`RT/DP`, `DT/ST`). The \
         last column is the best over every ratio (and, with control variates, the residual estimators).\n",
    );
    for with_cv in [true, false] {
        md.push_str(if with_cv {
            "\n# All estimators\n"
        } else {
            "\n# Without control variates (DT, RT, DP, ST, SN)\n"
        });
        for p in Profile::ALL {
            let header: Vec<String> = ["T".to_string()]
                .into_iter()
                .chain(RATIOS.iter().map(|r| r.to_string()))
                .chain(["best".into()])
                .collect();
            let mut table = Vec::new();
            for t in TARGETS {
                let mut line = vec![t.to_string()];
                for ratio in RATIOS {
                    let w = cell_win(a, p, t, ratio, with_cv);
                    rows.push(WinnerRow {
                        profile: p.name(),
                        target: t,
                        ratio,
                        with_cv,
                        winner: w.as_ref().map(|w| w.label.clone()),
                        estimator: w.as_ref().map(|w| w.best.estimator.clone()),
                        rel_var_cost: w.as_ref().and_then(|w| w.best.rel_var_cost()),
                        resolved: w.as_ref().is_some_and(|w| w.resolved),
                        tie_with: w.as_ref().and_then(|w| w.tie.clone()),
                    });
                    line.push(w.as_ref().map(cell_text).unwrap_or_else(|| "-".into()));
                }
                let all = a.rows.iter().filter(|r| r.profile == p && r.target == t && (with_cv || !has_cv(r.family)));
                let best = win(a, all, true)
                    .map(|w| format!("{} ({})", cell_text(&w), sig(w.best.rel_var_cost().unwrap_or(f64::NAN), 2)));
                line.push(best.unwrap_or_default());
                table.push(line);
            }
            let header: Vec<&str> = header.iter().map(String::as_str).collect();
            md.push_str(&format!("\n## {}\n\n{}", md_text(p.name()), markdown_table(&header, &table)));
        }
    }
    (rows, md)
}

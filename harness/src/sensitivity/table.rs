//! The result files of a sensitivity run: `sensitivity.csv` (one row per part and setting),
//! `sensitivity.md` (per part: what the paper leaves open, the verdict at every setting, the
//! outcome) and one plot per part (the claim's value against the setting, the paper's number as a
//! line, the verdict as the marker).

use super::outcome::Outcome;
use super::{setting_text, Part};
use crate::error::Result;
use crate::output::plot::claim_sweep::{write_claim_sweep, ClaimSweepFigure, SettingPoint};
use crate::output::Claim;
use crate::verdict::Verdict;
use mcbench_core::params::ParamValue;
use serde::Serialize;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// One part at one setting.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SettingRow {
    /// Part id.
    pub part: String,
    /// Paper.
    pub paper: String,
    /// The claim in a few words.
    pub headline: String,
    /// What varies.
    pub vary: String,
    /// The setting.
    pub setting: String,
    /// `default`, `paper-like`, `default+paper-like` or empty.
    pub role: String,
    /// `id/variant` the claim was judged on.
    pub testbed: String,
    /// The paper's number.
    pub paper_value: Option<f64>,
    /// Ours.
    pub value: Option<f64>,
    /// Lower end of its interval.
    pub low: Option<f64>,
    /// Upper end.
    pub high: Option<f64>,
    /// The verdict there.
    pub verdict: Verdict,
    /// The proven bound there, where the part gives one ([`super::Bound`]).
    pub ceiling: Option<f64>,
    /// The compared pair, for ratio claims.
    pub pair: String,
    /// The cost regime, for time-based claims.
    pub regime: String,
    /// Why the verdict is what it is.
    pub reason: String,
    /// `exact` when `ceiling` is a proven bound, `best measured` when the part reports only
    /// `best_measured`, empty when it has neither.
    pub bound_kind: String,
    /// The best measured value there (the work ratio at free overhead), where the part computes
    /// one: achieved by our estimator, not a bound.
    pub best_measured: Option<f64>,
    /// The part's idealised value there ([`Part::limit`]): bounds a narrower family than the
    /// claim's, so it decides nothing.
    pub limit: Option<f64>,
}

impl SettingRow {
    /// The row of `part` at `value`, from the claim judged there.
    pub fn new(part: &Part, value: &ParamValue, c: &Claim, ceiling: Option<f64>, best_measured: Option<f64>) -> Self {
        let role = match (value == &part.default, part.paper_like.as_ref() == Some(value)) {
            (true, true) => "default+paper-like",
            (true, false) => "default",
            (false, true) => "paper-like",
            _ => "",
        };
        let finite = |x: Option<f64>| x.filter(|v| v.is_finite());
        SettingRow {
            part: part.id.clone(),
            paper: part.paper.clone(),
            headline: part.headline.clone(),
            vary: part.vary.clone(),
            setting: setting_text(value),
            role: role.into(),
            testbed: c.testbed.clone(),
            paper_value: finite(c.paper_value),
            value: finite(c.our_value),
            low: finite(c.interval.map(|i| i[0])),
            high: finite(c.interval.map(|i| i[1])),
            verdict: c.verdict(),
            ceiling: finite(ceiling),
            pair: c.pair.clone(),
            regime: c.regime.clone(),
            reason: if c.reason.is_empty() { c.note.clone() } else { c.reason.clone() },
            bound_kind: match (finite(ceiling), finite(best_measured)) {
                (Some(_), _) => "exact",
                (None, Some(_)) => "best measured",
                (None, None) => "",
            }
            .into(),
            best_measured: finite(best_measured),
            limit: finite(
                part.limit.as_ref().and_then(|l| part.values.iter().position(|v| v == value).map(|i| l.values[i])),
            ),
        }
    }
}

fn num(x: Option<f64>) -> String {
    x.map_or("-".into(), |v| format!("{v:.4}"))
}

/// `sensitivity.md`: the outcome table, then per part its settings (every text of the file and of
/// the verdicts escaped, [`md_text`](crate::output::report::md_text)).
pub fn markdown(outcomes: &[(&Part, Outcome)], rows: &[SettingRow]) -> String {
    use crate::output::report::md_text;
    let mut s = String::from(
        "# Where each claim holds\n\n| paper | claim | against | at our default | at the paper-like setting | outcome |\n|---|---|---|---|---|---|\n",
    );
    for (p, o) in outcomes {
        let at = |v: Option<&ParamValue>| {
            v.and_then(|v| rows.iter().find(|r| r.part == p.id && r.setting == setting_text(v)))
                .map_or("-".to_string(), |r| format!("{} = {}: {} ({})", p.vary, r.setting, num(r.value), r.verdict))
        };
        let (default, paper_like) = (md_text(&at(Some(&p.default))), md_text(&at(p.paper_like.as_ref())));
        let outcome = md_text(&o.sentence());
        let (paper, headline, vary) = (md_text(&p.paper), md_text(&p.headline), md_text(&p.vary));
        let _ = writeln!(s, "| {paper} | {headline} | {vary} | {default} | {paper_like} | {outcome} |");
    }
    for (p, o) in outcomes {
        let _ = write!(
            s,
            "\n## {} (paper {}) against {}\n\n{}\n\n**{}.** {}\n\n",
            md_text(&p.headline),
            md_text(&p.paper),
            md_text(&p.vary),
            md_text(&p.open),
            md_text(o.kind()),
            md_text(&o.sentence())
        );
        if let Some(b) = &p.bound {
            let _ = write!(s, "Ceiling (a proven bound): {} (`{}`).\n\n", md_text(&b.method), md_text(&b.command));
        }
        if let Some(b) = &p.limit {
            let _ = write!(
                s,
                "Limit (not a bound of the claim's family): {} (`{}`).\n\n",
                md_text(&b.method),
                md_text(&b.command)
            );
        }
        s.push_str("| setting | role | ours | interval | paper | verdict | ceiling | best measured | limit | reason |\n|---|---|---|---|---|---|---|---|---|---|\n");
        for r in rows.iter().filter(|r| r.part == p.id) {
            let interval = match (r.low, r.high) {
                (Some(a), Some(b)) => format!("[{a:.4}, {b:.4}]"),
                _ => "-".into(),
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                md_text(&r.setting),
                md_text(&r.role),
                num(r.value),
                interval,
                num(r.paper_value),
                md_text(r.verdict.as_str()),
                num(r.ceiling),
                num(r.best_measured),
                num(r.limit),
                md_text(&r.reason)
            );
        }
    }
    s
}

/// The plot of one part: `sensitivity_<part id>.svg` / `.png` in `dir`.
pub fn plot(dir: &Path, part: &Part, rows: &[&SettingRow]) -> Result<Vec<PathBuf>> {
    let points = rows
        .iter()
        .map(|r| SettingPoint {
            label: match r.role.as_str() {
                "default" => format!("{}*", r.setting),
                "paper-like" => format!("{} (paper)", r.setting),
                "default+paper-like" => format!("{}* (paper)", r.setting),
                _ => r.setting.clone(),
            },
            value: r.value,
            interval: r.low.zip(r.high).map(|(a, b)| [a, b]),
            verdict: r.verdict,
            ceiling: r.ceiling,
        })
        .collect();
    let fig = ClaimSweepFigure {
        title: format!("paper {}: {}", part.paper, part.headline),
        x_desc: format!("{} (* our default)", part.vary),
        y_desc: "claim value (line: the paper's; triangle: ceiling)".into(),
        points,
        paper: rows.iter().find_map(|r| r.paper_value),
    };
    write_claim_sweep(dir, &format!("sensitivity_{}", crate::output::plot::sanitize(&part.id)), &fig)
}

//! How a part ends: one outcome from its verdicts at every setting, decided in a fixed order
//! (held at the paper-like setting; else holds where it held; else cannot hold, when a proven
//! bound lies below the claim at every setting; else unsupportable as written, when the file
//! states why; else not held anywhere tried, when at least one setting is not held; else
//! inconclusive at every setting tried: an outcome is never stronger than its verdicts). A best
//! measured value below the claim is said beside the last two, never in place of a bound.

use super::table::SettingRow;
use super::{setting_text, Part};
use crate::verdict::Verdict;

/// The outcome of a part.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Held at the setting closest to the paper's.
    HeldAtPaperLike {
        /// That setting.
        setting: String,
        /// The claim's value and interval there.
        value: String,
    },
    /// Held at these settings (and not at the others).
    HoldsWhere {
        /// Where it held, with values.
        held: Vec<String>,
        /// The verdict at our default and the paper-like setting, with values.
        elsewhere: String,
        /// When the held settings are only where a monotone trend passes the paper's number (not
        /// held on both sides), that trend and where it crosses: a crossing, not a range.
        crossing: Option<String>,
    },
    /// A proven bound of the scene (the part's [`super::Bound`]) lies below the claim at every
    /// setting.
    CannotHold {
        /// What the bound is.
        method: String,
        /// The largest bound and where.
        best: String,
        /// The paper's number.
        paper: f64,
    },
    /// The file's reason the claim cannot be supported as written.
    Unsupportable(String),
    /// Held at no setting tried and not held at one at least, with no ceiling or reason that
    /// explains it.
    NotHeldAnywhere {
        /// The best value and where.
        best: String,
        /// The largest best measured value and the part's limit, and where, when it has them.
        measured: Option<String>,
    },
    /// Neither held nor not held at any setting tried: every verdict is inconclusive (or not
    /// measured), so the part decides nothing either way.
    InconclusiveEverywhere {
        /// The value closest to the paper's and where.
        best: String,
        /// The largest best measured value and the part's limit, and where, when it has them.
        measured: Option<String>,
    },
}

fn value_text(r: &SettingRow) -> String {
    let v = r.value.map_or("-".to_string(), |v| format!("{v:.3}"));
    match (r.low, r.high) {
        (Some(a), Some(b)) => format!("{v} [{a:.3}, {b:.3}]"),
        _ => v,
    }
}

fn at(r: &SettingRow, vary: &str) -> String {
    format!("{vary} = {}: {} ({})", r.setting, value_text(r), r.verdict)
}

impl Outcome {
    /// The outcome's class, one of the four the report names (or `not held at any setting tried`,
    /// or `inconclusive at every setting tried`).
    pub fn kind(&self) -> &'static str {
        match self {
            Outcome::HeldAtPaperLike { .. } => "held at the paper-like setting",
            Outcome::HoldsWhere { .. } => "holds where",
            Outcome::CannotHold { .. } => "cannot hold on this scene",
            Outcome::Unsupportable(_) => "unsupportable as written",
            Outcome::NotHeldAnywhere { .. } => "not held at any setting tried",
            Outcome::InconclusiveEverywhere { .. } => "inconclusive at every setting tried",
        }
    }

    /// One sentence: the class and the numbers behind it.
    pub fn sentence(&self) -> String {
        match self {
            Outcome::HeldAtPaperLike { setting, value } => {
                format!("held at the paper-like setting {setting}: {value}")
            }
            Outcome::HoldsWhere { held, elsewhere, crossing } => {
                let crossing = crossing.as_ref().map_or_else(String::new, |c| format!("; {c}"));
                format!("holds where {}; {elsewhere}{crossing}", held.join("; "))
            }
            Outcome::CannotHold { method, best, paper } => {
                format!("cannot hold on this scene: the ceiling ({method}) is below the paper's {paper} at every setting (largest {best})")
            }
            Outcome::Unsupportable(why) => format!("unsupportable as written: {why}"),
            Outcome::NotHeldAnywhere { best, measured } => {
                format!("not held at any setting tried; the closest: {best}{}", measured_text(measured))
            }
            Outcome::InconclusiveEverywhere { best, measured } => {
                format!("inconclusive at every setting tried; the closest: {best}{}", measured_text(measured))
            }
        }
    }
}

/// The outcome of `part` from its rows (one per setting, in setting order).
pub fn classify(part: &Part, rows: &[&SettingRow]) -> Outcome {
    let find = |v: &mcbench_core::params::ParamValue| rows.iter().find(|r| r.setting == setting_text(v)).copied();
    if let Some(r) = part.paper_like.as_ref().and_then(find).filter(|r| r.verdict == Verdict::Held) {
        return Outcome::HeldAtPaperLike { setting: format!("{} = {}", part.vary, r.setting), value: value_text(r) };
    }
    let mut held: Vec<String> = rows.iter().filter(|r| r.verdict == Verdict::Held).map(|r| at(r, &part.vary)).collect();
    if held.len() == rows.len() && rows.len() > 1 {
        let values: Vec<f64> = rows.iter().filter_map(|r| r.value).collect();
        let (lo, hi) = values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(*v), b.max(*v)));
        let (first, last) = (&rows[0].setting, &rows[rows.len() - 1].setting);
        held = vec![format!("every setting tried ({} from {first} to {last}: {lo:.3} to {hi:.3})", part.vary)];
    }
    if !held.is_empty() {
        let mut elsewhere = Vec::new();
        if let Some(r) = find(&part.default) {
            elsewhere.push(format!("at our default {}", at(r, &part.vary)));
        }
        if let Some(r) = part.paper_like.as_ref().and_then(find) {
            elsewhere.push(format!("at the paper-like {}", at(r, &part.vary)));
        }
        return Outcome::HoldsWhere { held, elsewhere: elsewhere.join("; "), crossing: crossing(part, rows) };
    }
    let paper = rows.iter().find_map(|r| r.paper_value);
    let ceilings: Vec<(f64, &SettingRow)> = rows.iter().filter_map(|r| Some((r.ceiling?, *r))).collect();
    if let (Some(p), false) = (paper, ceilings.is_empty()) {
        let all = ceilings.len() == rows.len();
        let (best, r) =
            ceilings.iter().fold((f64::NEG_INFINITY, rows[0]), |acc, (c, r)| if *c > acc.0 { (*c, r) } else { acc });
        if all && best < p {
            let method = part.bound.as_ref().map_or_else(String::new, |b| b.method.clone());
            return Outcome::CannotHold {
                method,
                best: format!("{best:.3} at {} = {}", part.vary, r.setting),
                paper: p,
            };
        }
    }
    let measured = rows
        .iter()
        .filter_map(|r| Some((r.best_measured?, *r)))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(m, r)| format!("best measured here (not a bound) at most {m:.3} at {} = {}", part.vary, r.setting));
    let limit = rows.iter().filter_map(|r| Some((r.limit?, *r))).max_by(|a, b| a.0.total_cmp(&b.0)).map(|(l, r)| {
        let method = part.limit.as_ref().map_or("limit", |b| b.method.as_str());
        format!("{method} (not a bound of the claim's family) at most {l:.3} at {} = {}", part.vary, r.setting)
    });
    let measured = match (measured, limit) {
        (Some(m), Some(l)) => Some(format!("{m}; {l}")),
        (m, l) => m.or(l),
    };
    if let Some(why) = &part.unsupportable {
        return Outcome::Unsupportable(why.clone());
    }
    let target = paper.unwrap_or(0.0);
    let best = rows
        .iter()
        .filter(|r| r.value.is_some())
        .min_by(|a, b| {
            let d = |r: &SettingRow| (r.value.unwrap_or(f64::NAN) - target).abs();
            d(a).total_cmp(&d(b))
        })
        .map_or_else(|| "no setting measured".to_string(), |r| at(r, &part.vary));
    if rows.iter().any(|r| r.verdict == Verdict::NotHeld) {
        Outcome::NotHeldAnywhere { best, measured }
    } else {
        Outcome::InconclusiveEverywhere { best, measured }
    }
}

/// The clause for a claim held only where a trend crosses the paper's number: every setting is a
/// number (in increasing order) with a value, the values are strictly monotone in the setting, the
/// held settings are one run with a setting not held on each side, and the paper's number lies
/// between the values at its ends. Then holding there is the trend passing the number, which says
/// nothing of a regime where the claim is true.
fn crossing(part: &Part, rows: &[&SettingRow]) -> Option<String> {
    let points: Vec<(f64, f64)> =
        rows.iter().map(|r| Some((r.setting.parse::<f64>().ok()?, r.value?))).collect::<Option<_>>()?;
    let paper = rows.iter().find_map(|r| r.paper_value)?;
    let increasing = |f: &dyn Fn(&(f64, f64)) -> f64| points.windows(2).all(|w| f(&w[1]) > f(&w[0]));
    if points.len() < 3 || !increasing(&|p| p.0) || !(increasing(&|p| p.1) || increasing(&|p| -p.1)) {
        return None;
    }
    let held: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].verdict == Verdict::Held).collect();
    let (first, last) = (*held.first()?, *held.last()?);
    let one_run = last - first + 1 == held.len();
    let flanked = first > 0
        && last + 1 < rows.len()
        && rows[first - 1].verdict == Verdict::NotHeld
        && rows[last + 1].verdict == Verdict::NotHeld;
    if !one_run || !flanked {
        return None;
    }
    let side = |v: f64| (v - paper).signum();
    let pass = points.windows(2).position(|w| side(w[0].1) != side(w[1].1))?;
    let (a, b) = (points[0], points[points.len() - 1]);
    Some(format!(
        "a crossing, not a range: the value moves monotonically with {} ({:.3} at {} to {:.3} at {}) and passes the paper's {paper} between {} and {}",
        part.vary, a.1, rows[0].setting, b.1, rows[rows.len() - 1].setting, rows[pass].setting, rows[pass + 1].setting
    ))
}

/// The best measured value as a clause of a sentence: achieved here, not a bound.
fn measured_text(measured: &Option<String>) -> String {
    measured.as_ref().map_or_else(String::new, |m| format!("; {m}"))
}

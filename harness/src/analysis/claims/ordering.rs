//! Claims about several cells at once, judged on ratio intervals ([`Ratio`]) at a level that holds
//! for the whole family:
//!
//! - [`ordering_claim`]: every one of a set of estimators has a lower (or higher) metric than every
//!   one of another set ("MIS has the lowest error of the unbiased methods"); Bonferroni over the
//!   pairs.
//! - [`optimum_claim`]: the best of a set of candidates (a parameter sweep) is one of those in a
//!   stated range ("FoM peaks below sigma_samp = 1"). The best inside and the best outside are
//!   picked from the data, so the interval of their ratio is at a Bonferroni level over every
//!   (inside, outside) pair: the simultaneous intervals cover whichever pair is picked.
//! - [`ratio_of_ratios_claim`]: a ratio of two ratios ("more MH moves reduce the error less than
//!   bridges do"), whose interval joins the two ratios' intervals at level `1 - 0.05 / 2` each.
//!
//! Each gives `held`, `not held` or `inconclusive` (with what would decide it); a missing cell is
//! inconclusive with the reason, and a claim that compares an estimator with itself is refused.

use super::ratio::{row, Ratio, RatioMetric, LEVEL};
use crate::analysis::metrics::SummaryRow;
use crate::output::{Claim, RunReport};
use crate::plan::cost_model::Regime;
use crate::verdict::Verdict;

/// Whether a smaller value of `metric` is better (errors) or a larger one (efficiencies).
pub fn lower_is_better(metric: RatioMetric) -> bool {
    matches!(metric, RatioMetric::Rmse | RatioMetric::Mse | RatioMetric::PErr | RatioMetric::RmseDisplay)
}

fn regime(metric: RatioMetric) -> String {
    match metric {
        RatioMetric::EfficiencyMse | RatioMetric::PEff => Regime::Measured.name().into(),
        _ => String::new(),
    }
}

/// The value of `metric` in a row, when it is defined (finite and positive).
pub fn metric_of(metric: RatioMetric, r: &SummaryRow) -> Option<f64> {
    metric.value(r)
}

/// The largest budget any row of `tb` has (the default budget of a claim that names none).
pub fn largest_budget(report: &RunReport, tb: (&str, &str)) -> Option<u64> {
    report.query().bed(tb).largest_budget()
}

/// The first estimator named twice in `names`, if any (a claim comparing it with itself).
pub fn repeated<'a>(names: &[&'a str]) -> Option<&'a str> {
    names.iter().enumerate().find(|(i, n)| names[..*i].contains(n)).map(|(_, n)| *n)
}

/// The verdict of a set of intervals of ratios that are each claimed `below` (else above) 1.
enum Decision {
    Held,
    NotHeld(usize),
    Open(Vec<usize>),
}

fn decide(ends: &[(f64, f64)], below: bool) -> Decision {
    let wrong = |(lo, hi): (f64, f64)| if below { lo > 1.0 } else { hi < 1.0 };
    let right = |(lo, hi): (f64, f64)| if below { hi < 1.0 } else { lo > 1.0 };
    if let Some(i) = ends.iter().position(|e| wrong(*e)) {
        return Decision::NotHeld(i);
    }
    let open: Vec<usize> = (0..ends.len()).filter(|i| !right(ends[*i])).collect();
    if open.is_empty() {
        Decision::Held
    } else {
        Decision::Open(open)
    }
}

/// The repetitions at which an interval `(lo, hi)` of a ratio `r` at its level would just clear
/// `threshold`, assuming its log half-width falls as `1/sqrt(repetitions)`.
fn repetitions_to_decide((value, reps): (f64, usize), (lo, hi): (f64, f64), threshold: f64) -> Option<f64> {
    let half = (hi / lo).ln() / 2.0;
    let gap = (value / threshold).ln().abs();
    let need = (reps as f64 * (half / gap).powi(2)).ceil();
    (need.is_finite() && gap > 0.0).then_some(need)
}

/// The smallest ratio `d` (and so `1 / d`) that an interval `(lo, hi)` of a ratio at `level` tells
/// apart from 1 with 80% power: the log standard error read off the interval's width,
/// `se = ln(hi / lo) / (2 z)` with `z` the level's normal quantile, and `d = exp(se (z + z_0.8))`.
/// `None` for an empty or non-positive interval.
pub fn detectable_ratio((lo, hi): (f64, f64), level: f64) -> Option<f64> {
    let normal = |p: f64| mcbench_core::stats::hypothesis::t_quantile(p, f64::INFINITY);
    let z = normal(1.0 - (1.0 - level) / 2.0);
    let se = (hi / lo).ln() / (2.0 * z);
    let d = (se * (z + normal(0.8))).exp();
    (lo > 0.0 && d.is_finite() && d > 1.0).then_some(d)
}

/// The repetitions at which [`detectable_ratio`] would fall to `target` (the log standard error
/// falls as `1/sqrt(repetitions)`).
pub fn repetitions_to_detect(detectable: f64, reps: usize, target: f64) -> f64 {
    (reps as f64 * (detectable.ln() / target.ln()).powi(2)).ceil()
}

fn missing(base: Claim, why: String) -> Claim {
    Claim { verdict: Some(Verdict::Inconclusive), held: None, reason: why.clone(), note: why, ..base }
}

/// A claim refused because it compares `name` with itself.
pub fn refused(base: Claim, name: &str) -> Claim {
    let why = format!("refused: the claim compares {name} with itself");
    Claim { verdict: Some(Verdict::NotMeasured), held: None, reason: why.clone(), note: why, ..base }
}

/// The rows of `names` on `tb` at `budget`, or the first name without one.
fn rows<'a>(
    report: &'a RunReport,
    tb: (&str, &str),
    names: &[&'a str],
    budget: u64,
) -> Result<Vec<&'a SummaryRow>, String> {
    names.iter().map(|n| row(report, tb, n, budget).ok_or_else(|| n.to_string())).collect()
}

/// What an ordering or optimum claim compares: the test bed, the budget (`None`: the largest the
/// test bed ran) and the metric.
#[derive(Clone, Copy, Debug)]
pub struct Family<'a> {
    /// (test bed, variant).
    pub tb: (&'a str, &'a str),
    /// The budget, or the largest.
    pub budget: Option<u64>,
    /// The metric.
    pub metric: RatioMetric,
    /// The paper's number (shown beside ours).
    pub paper: Option<f64>,
}

impl Family<'_> {
    fn base(&self, claim: &str) -> Claim {
        Claim {
            testbed: format!("{}/{}", self.tb.0, self.tb.1),
            claim: claim.into(),
            paper_value: self.paper,
            regime: regime(self.metric),
            ..Default::default()
        }
    }

    fn budget(&self, report: &RunReport) -> Option<u64> {
        self.budget.or_else(|| largest_budget(report, self.tb))
    }
}

/// "Every one of `estimators` has the `lowest` (else highest) `metric` against every one of
/// `others`": the ratio `metric(e) / metric(o)` of each pair at a Bonferroni level over the pairs.
/// Held when every interval lies on the claimed side of 1, not held when one lies on the other
/// side, inconclusive otherwise. Our value, interval and pair are those of the binding pair (the
/// interval reaching furthest towards the other side); the note lists every pair.
pub fn ordering_claim(
    report: &RunReport,
    family: &Family<'_>,
    (estimators, others): (&[&str], &[&str]),
    lowest: bool,
    claim: &str,
) -> Claim {
    let base = family.base(claim);
    let all: Vec<&str> = estimators.iter().chain(others).copied().collect();
    if let Some(n) = repeated(&all) {
        return refused(base, n);
    }
    let Some(budget) = family.budget(report) else {
        return missing(base, format!("no rows on {}/{}", family.tb.0, family.tb.1));
    };
    let (es, os) = match (rows(report, family.tb, estimators, budget), rows(report, family.tb, others, budget)) {
        (Ok(e), Ok(o)) => (e, o),
        (Err(n), _) | (_, Err(n)) => {
            return missing(
                base,
                format!("no cell for {n} at budget {budget}: the ordering cannot be judged without it"),
            )
        }
    };
    let mut pairs: Vec<(String, Ratio)> = Vec::new();
    for a in &es {
        for b in &os {
            let Some(r) = Ratio::of(family.metric, a, b) else {
                let why =
                    format!("{} not defined for {} or {} at {budget}", family.metric.name(), a.estimator, b.estimator);
                return missing(base, why);
            };
            pairs.push((format!("{} vs {}", a.estimator, b.estimator), r));
        }
    }
    let level = 1.0 - (1.0 - LEVEL) / pairs.len().max(1) as f64;
    let ends: Vec<(f64, f64)> = pairs.iter().map(|(_, r)| r.interval_at(level)).collect();
    // The binding pair: the interval reaching furthest towards the other side of 1.
    let bind = (0..pairs.len())
        .max_by(|&i, &j| {
            let reach = |k: usize| if lowest { ends[k].1 } else { 1.0 / ends[k].0 };
            reach(i).total_cmp(&reach(j))
        })
        .unwrap_or(0);
    let side = if lowest { "below" } else { "above" };
    let adj = format!("level {level:.4}, Bonferroni over {} pairs", pairs.len());
    let (verdict, held, reason) = match decide(&ends, lowest) {
        Decision::Held => (Verdict::Held, Some(true), format!("every interval lies {side} 1 ({adj})")),
        Decision::NotHeld(i) => {
            (Verdict::NotHeld, Some(false), format!("{}: the interval lies on the other side of 1 ({adj})", pairs[i].0))
        }
        Decision::Open(open) => {
            let need = open
                .iter()
                .filter_map(|&i| repetitions_to_decide((pairs[i].1.value, pairs[i].1.reps), ends[i], 1.0))
                .fold(0.0, f64::max);
            let names: Vec<&str> = open.iter().map(|&i| pairs[i].0.as_str()).collect();
            let more = if need > 0.0 {
                format!("about {need} repetitions would decide it")
            } else {
                "no repetition count decides it (a ratio sits at 1)".into()
            };
            (Verdict::Inconclusive, None, format!("the intervals of {} straddle 1 ({adj}); {more}", names.join(", ")))
        }
    };
    let listed: Vec<String> =
        pairs.iter().zip(&ends).map(|((p, r), (lo, hi))| format!("{p}: {:.4} [{lo:.4}, {hi:.4}]", r.value)).collect();
    let (lo, hi) = ends[bind];
    Claim {
        our_value: Some(pairs[bind].1.value),
        held,
        note: format!(
            "{} ratios at {budget} ({} repetitions), claimed {side} 1: {}",
            family.metric.name(),
            pairs[bind].1.reps,
            listed.join("; ")
        ),
        verdict: Some(verdict),
        interval: Some([lo, hi]),
        pair: pairs[bind].0.clone(),
        reason,
        ..base
    }
}

/// "The best of the candidates is one of `inside`" (against `outside`): the best inside and the
/// best outside by point estimate, `lowest` (else highest) metric being best. Held when the best
/// inside beats every outside candidate, not held when the best outside beats every inside one,
/// inconclusive otherwise; every interval is at a Bonferroni level over the `inside x outside`
/// pairs, since both bests are picked from the data. Our value is `metric(best inside) /
/// metric(best outside)` with its interval at that level.
pub fn optimum_claim(
    report: &RunReport,
    family: &Family<'_>,
    (inside, outside): (&[&str], &[&str]),
    lowest: bool,
    claim: &str,
) -> Claim {
    let base = family.base(claim);
    let all: Vec<&str> = inside.iter().chain(outside).copied().collect();
    if let Some(n) = repeated(&all) {
        return refused(base, n);
    }
    let Some(budget) = family.budget(report) else {
        return missing(base, format!("no rows on {}/{}", family.tb.0, family.tb.1));
    };
    let (ins, outs) = match (rows(report, family.tb, inside, budget), rows(report, family.tb, outside, budget)) {
        (Ok(i), Ok(o)) => (i, o),
        (Err(n), _) | (_, Err(n)) => {
            return missing(base, format!("no cell for {n} at budget {budget}: the best cannot be picked without it"))
        }
    };
    let value = |r: &SummaryRow| metric_of(family.metric, r);
    let best = |set: &[&SummaryRow]| {
        let v: Option<Vec<f64>> = set.iter().map(|r| value(r)).collect();
        let v = v?;
        let key = |i: usize| if lowest { -v[i] } else { v[i] };
        (0..set.len()).max_by(|&i, &j| key(i).total_cmp(&key(j)))
    };
    let (Some(bi), Some(bo)) = (best(&ins), best(&outs)) else {
        return missing(base, format!("{} not defined for every candidate at {budget}", family.metric.name()));
    };
    let level = 1.0 - (1.0 - LEVEL) / (ins.len() * outs.len()).max(1) as f64;
    let against = |a: &SummaryRow, set: &[&SummaryRow]| -> Option<Vec<(f64, f64)>> {
        set.iter().map(|b| Ratio::of(family.metric, a, b).map(|r| r.interval_at(level))).collect()
    };
    let (Some(in_wins), Some(out_wins), Some(r)) =
        (against(ins[bi], &outs), against(outs[bo], &ins), Ratio::of(family.metric, ins[bi], outs[bo]))
    else {
        return missing(base, format!("{} not defined for every candidate at {budget}", family.metric.name()));
    };
    let adj = format!("level {level:.4}, Bonferroni over {} inside x {} outside pairs", ins.len(), outs.len());
    let (a, b) = (&ins[bi].estimator, &outs[bo].estimator);
    let (verdict, held, reason) = match (decide(&in_wins, lowest), decide(&out_wins, lowest)) {
        (Decision::Held, _) => {
            (Verdict::Held, Some(true), format!("the best inside, {a}, beats every outside candidate ({adj})"))
        }
        (_, Decision::Held) => {
            (Verdict::NotHeld, Some(false), format!("the best outside, {b}, beats every inside candidate ({adj})"))
        }
        _ => {
            let (lo, hi) = r.interval_at(level);
            let need = repetitions_to_decide((r.value, r.reps), (lo, hi), 1.0)
                .map_or("no repetition count decides it".into(), |n| format!("about {n} repetitions would decide it"));
            (
                Verdict::Inconclusive,
                None,
                format!("neither best beats every candidate on the other side ({adj}); {need}"),
            )
        }
    };
    let listed: Vec<String> = ins
        .iter()
        .map(|r| ("inside", r))
        .chain(outs.iter().map(|r| ("outside", r)))
        .map(|(w, r)| format!("{} {:.4e} ({w})", r.estimator, value(r).unwrap_or(f64::NAN)))
        .collect();
    let (lo, hi) = r.interval_at(level);
    let power = detectable_ratio((lo, hi), level).map_or(String::new(), |d| {
        let tenth = repetitions_to_detect(d, r.reps, 1.1);
        format!("; detectable ratio {d:.3} (80% power at this level; a 10% difference needs about {tenth} repetitions)")
    });
    Claim {
        our_value: Some(r.value),
        held,
        note: format!(
            "{} at {budget} ({} repetitions), {} is best; best inside / best outside {:.4} [{lo:.4}, {hi:.4}]{power}: {}",
            family.metric.name(),
            r.reps,
            if lowest { "lowest" } else { "highest" },
            r.value,
            listed.join(", ")
        ),
        verdict: Some(verdict),
        interval: Some([lo, hi]),
        pair: format!("{a} vs {b}"),
        reason,
        ..base
    }
}

/// "`(metric(n0) / metric(n1)) / (metric(d0) / metric(d1))` lies above (else below)
/// `threshold`": each ratio's interval at level `1 - 0.05 / 2`, so that both hold at once with
/// 95%, joined into `[lo_n / hi_d, hi_n / lo_d]`. Held when that lies on the claimed side.
pub fn ratio_of_ratios_claim(
    report: &RunReport,
    family: &Family<'_>,
    (numerator, denominator): ([&str; 2], [&str; 2]),
    (threshold, above): (f64, bool),
    claim: &str,
) -> Claim {
    let mut base = family.base(claim);
    base.pair = format!("({} vs {}) vs ({} vs {})", numerator[0], numerator[1], denominator[0], denominator[1]);
    for [a, b] in [numerator, denominator] {
        if a == b {
            return refused(base, a);
        }
    }
    let Some(budget) = family.budget(report) else {
        return missing(base, format!("no rows on {}/{}", family.tb.0, family.tb.1));
    };
    let ratio = |[a, b]: [&str; 2]| -> Result<Ratio, String> {
        let (ra, rb) = rows(report, family.tb, &[a, b], budget)
            .map(|v| (v[0], v[1]))
            .map_err(|n| format!("no cell for {n} at budget {budget}"))?;
        Ratio::of(family.metric, ra, rb).ok_or_else(|| format!("{} not defined for {a} or {b}", family.metric.name()))
    };
    let (n, d) = match (ratio(numerator), ratio(denominator)) {
        (Ok(n), Ok(d)) => (n, d),
        (Err(why), _) | (_, Err(why)) => return missing(base, why),
    };
    let level = 1.0 - (1.0 - LEVEL) / 2.0;
    let ((nl, nh), (dl, dh)) = (n.interval_at(level), d.interval_at(level));
    let value = n.value / d.value;
    let (lo, hi) = (nl / dh, nh / dl);
    let (yes, no) = if above { (lo > threshold, hi < threshold) } else { (hi < threshold, lo > threshold) };
    let side = if above { "above" } else { "below" };
    let (verdict, held, reason) = if !(lo.is_finite() && hi.is_finite()) {
        (Verdict::Inconclusive, None, "no interval: the cells carry no error spread".to_string())
    } else if yes {
        (Verdict::Held, Some(true), format!("the 95% interval lies {side} {threshold}"))
    } else if no {
        (Verdict::NotHeld, Some(false), format!("the 95% interval lies on the other side of {threshold}"))
    } else {
        let more = repetitions_to_decide((value, n.reps.min(d.reps)), (lo, hi), threshold)
            .map_or("no repetition count decides it".into(), |k| format!("about {k} repetitions would decide it"));
        (Verdict::Inconclusive, None, format!("the 95% interval straddles {threshold}; {more}"))
    };
    Claim {
        our_value: Some(value),
        held,
        note: format!(
            "{m} at {budget}: {} / {} = {:.4} [{nl:.4}, {nh:.4}], {} / {} = {:.4} [{dl:.4}, {dh:.4}] (each at level {level:.3}, {} repetitions); their ratio {value:.4} [{lo:.4}, {hi:.4}]",
            numerator[0],
            numerator[1],
            n.value,
            denominator[0],
            denominator[1],
            d.value,
            n.reps.min(d.reps),
            m = family.metric.name(),
        ),
        verdict: Some(verdict),
        interval: Some([lo, hi]),
        reason,
        ..base
    }
}

#[cfg(test)]
#[path = "ordering_tests.rs"]
mod tests;

//! Judging paper claims against a run: slope claims ([`slope`]), speed-up claims, ratio claims
//! ([`ratio`]), claims about several cells at once: orderings, optima and ratios of ratios
//! ([`ordering`]), and the unbiasedness tests' verdicts on estimators and controls ([`control`]).

pub mod bootstrap;
pub mod control;
pub mod exact_ratio;
pub mod ordering;
pub mod ratio;
pub mod slope;

pub use control::{control_flagged, decisive_test, unbiased_verdict};
pub use ordering::{optimum_claim, ordering_claim, ratio_of_ratios_claim, Family};
pub use ratio::{ratio_claim, Ratio, RatioMetric, RatioSpec};
pub use slope::{
    last_segment_slope, slope_matches, slope_matches_over, slope_reaches, slope_steeper, slope_steeper_than,
    SLOPE_TOLERANCE,
};

use crate::analysis::{Fit, SpeedUp, SpeedUpOutcome};
use crate::output::query::Query;
use crate::output::{Claim, RunReport};
use crate::plan::cost_model::Regime;
use crate::verdict::Verdict;

/// The fit of an estimator on a test bed, if the run has one.
pub fn fit<'a>(report: &'a RunReport, testbed: &str, variant: &str, estimator: &str) -> Option<&'a Fit> {
    Query::new(&report.fits).testbed(testbed).variant(variant).estimator(estimator).first()
}

pub(crate) fn not_measured(testbed: &str, claim: &str, paper: f64, why: String) -> Claim {
    Claim {
        testbed: testbed.into(),
        claim: claim.into(),
        paper_value: Some(paper),
        our_value: None,
        held: None,
        note: why,
        ..Default::default()
    }
}

/// How close a speed-up must come to the paper's: at least half its factor (scenes, budgets and
/// machines differ; the order of magnitude is what carries over).
pub const SPEEDUP_SHARE: f64 = 0.5;

/// "X beats `baseline` by `paper` x at equal cost" in `regime`, judged on the 95% interval of our
/// speed-up: held when it lies at or above [`SPEEDUP_SHARE`] of the paper's factor, not held when it
/// lies below, inconclusive (with the repetitions that would decide) when it straddles it.
/// `baseline` is the pair as the paper states it (paper 001's factors are against BRDF sampling);
/// `None` is the sweep's baseline. The note gives the other regime, the wall clock, the break-even
/// ray cost, the limit as rays get costly and the ray cost at which the paper's factor is reached.
pub fn speedup_claim(
    report: &RunReport,
    tb: (&str, &str),
    (estimator, baseline): (&str, Option<&str>),
    paper: f64,
    claim: &str,
    regime: Regime,
) -> Claim {
    let found = |all: &[SpeedUp]| Query::new(all).bed(tb).estimator(estimator).first().cloned();
    let s = match baseline {
        None => found(&report.speedups),
        Some(b) => found(&crate::analysis::speedups(&report.rows, &report.fits, b, &report.meta.cost_model)),
    };
    let base = s.as_ref().map(|s| s.baseline.clone()).or(baseline.map(String::from));
    let base = base.unwrap_or_else(|| "the sweep's baseline".into());
    let text = format!("{claim} [{} cost]", regime.name());
    let Some(s) = s else {
        let why = format!("no speed-up for {estimator} against {base} (not available, skipped, or no fit)");
        return Claim { regime: regime.name().into(), ..not_measured(tb.0, &text, paper, why) };
    };
    if s.outcome == SpeedUpOutcome::Unbounded {
        return Claim {
            testbed: format!("{}/{}", tb.0, tb.1),
            claim: text,
            paper_value: Some(paper),
            our_value: None,
            held: Some(true),
            note: format!(
                "{estimator} against {} at {} spp: exact (RMSE at round-off), speed-up unbounded; overhead {:.3}x in \
                 CPU time, {:.3}x (renderer)",
                s.baseline, s.budget, s.overhead, s.overhead_renderer
            ),
            verdict: Some(Verdict::Held),
            interval: None,
            pair: format!("{estimator} vs {}", s.baseline),
            regime: regime.name().into(),
            reason: "exact: the method's error is round-off, which no budget of the baseline reaches, so the \
                     speed-up is unbounded and above any finite factor"
                .into(),
            p_value: None,
        };
    }
    let value = s.in_regime(regime);
    // The speed-up's interval (bootstrap or delta method) judged by the verdict rule of ratios.
    let ratio = s.ratio(regime);
    let (lo, hi) = ratio.interval();
    let target = SPEEDUP_SHARE * paper;
    let (verdict, held, why) = ratio.verdict(target, true);
    let reason = format!("{why} (half the paper's factor)");
    let model = &report.meta.cost_model;
    let reach = s.curve().map(|c| {
        format!(
            "speed-up {:.3} at 1 ns rays, {:.3} at 10 µs, limit {:.3} as rays get costly; above 1x {}; at or above the paper's {paper}x {}",
            c.at(1.0),
            c.at(1e4),
            c.limit(),
            c.reaching(1.0).describe(),
            c.reaching(paper).describe()
        )
    });
    let note = format!(
        "{estimator} against {base} at {} spp: {:.3}x fewer samples; overhead {:.3}x in CPU time, {:.3}x with rays at {} ns and fetches at {} ns (renderer), {:.3}x on the wall clock; speed-up {:.3} (CPU) [{:.3}, {:.3}], {:.3} (renderer) [{:.3}, {:.3}] ({}); {}",
        s.budget,
        s.sample_ratio,
        s.overhead,
        s.overhead_renderer,
        model.ray_ns,
        model.fetch_ns,
        s.overhead_wall,
        s.speedup,
        s.speedup_ci_low,
        s.speedup_ci_high,
        s.speedup_renderer,
        s.speedup_renderer_ci_low,
        s.speedup_renderer_ci_high,
        ratio.method(),
        reach.unwrap_or_else(|| "no ray-cost curve (file written before it)".into())
    );
    Claim {
        testbed: format!("{}/{}", tb.0, tb.1),
        claim: text,
        paper_value: Some(paper),
        our_value: Some(value),
        held,
        note,
        verdict: Some(verdict),
        interval: Some([lo, hi]),
        pair: format!("{estimator} vs {}", s.baseline),
        regime: regime.name().into(),
        reason,
        p_value: None,
    }
}

/// [`speedup_claim`] in both cost regimes (measured first).
pub fn speedup_claims(
    report: &RunReport,
    tb: (&str, &str),
    pair: (&str, Option<&str>),
    paper: f64,
    claim: &str,
) -> Vec<Claim> {
    Regime::ALL.iter().map(|r| speedup_claim(report, tb, pair, paper, claim, *r)).collect()
}

/// A claim about the mean of an estimator diagnostic at one budget (e.g. paper 001 Table 1's cell
/// count and memory): held when ours is within `rel_tol` of the paper's number. `at` is
/// (estimator, budget, diagnostic name).
pub fn diagnostic_claim(
    report: &RunReport,
    tb: (&str, &str),
    at: (&str, u64, &str),
    paper: f64,
    rel_tol: f64,
    claim: &str,
) -> Claim {
    let (estimator, budget, name) = at;
    let d = Query::new(&report.diagnostics).bed(tb).estimator(estimator).at(budget).iter().find(|d| d.name == name);
    match d {
        None => not_measured(tb.0, claim, paper, format!("no `{name}` diagnostic of {estimator} at budget {budget}")),
        Some(d) => Claim {
            testbed: format!("{}/{}", tb.0, tb.1),
            claim: claim.into(),
            paper_value: Some(paper),
            our_value: Some(d.mean),
            held: Some((d.mean - paper).abs() <= rel_tol * paper.abs()),
            note: format!("mean `{name}` per estimate at {budget} spp; held if within {:.0}%", rel_tol * 100.0),
            ..Default::default()
        },
    }
}

/// A stored reference is precise enough when every measured RMSE at the largest budget is
/// at least 3x the reference's RMS standard error. One claim per test bed with a stored reference.
pub fn reference_precision(plan: &crate::plan::Plan, report: &RunReport) -> Vec<Claim> {
    let last = plan.sweep.budgets.last().map_or(0, |b| b.amount);
    let mut out = Vec::new();
    for b in &plan.beds {
        let r = b.bed.reference();
        if r.is_exact() {
            continue;
        }
        let n = (r.std_err.len() * 3).max(1) as f64;
        let ref_rms = (r.std_err.iter().flat_map(|s| s.0).map(|x| x * x).sum::<f64>() / n).sqrt();
        let min_rmse = report
            .query()
            .testbed(&b.spec.id)
            .variant(&b.variant)
            .at(last)
            .iter()
            .map(|row| row.rmse)
            .fold(f64::INFINITY, f64::min);
        out.push(Claim {
            testbed: b.label(),
            claim: "stored reference: every measured RMSE at the largest budget is >= 3x the stored reference's RMS standard error".into(),
            paper_value: Some(3.0),
            our_value: Some(min_rmse / ref_rms),
            held: Some(min_rmse >= 3.0 * ref_rms),
            note: format!("smallest RMSE {min_rmse:.3e} at budget {last}, reference RMS standard error {ref_rms:.3e} (its variance is subtracted from every MSE)"),
            ..Default::default()
        });
    }
    out
}

//! `stability` (SPEC §10, issue 9 item 3): every numerical stability case of the specification
//! with its outcome, `correct` (within error bars of an exact or stored reference, or of an
//! error-free numeric reference) or `refused` (a typed one-line error), never a panic or a NaN.
//!
//! The sweep itself is small (albedo exactly 1 and exactly 0 on `gradient-box` through the normal
//! harness, so those cells get the usual summary, fits and tests); the post hook runs every case of
//! [`cases`] with [`super::stability_cases::run`] plus the numeric cases of
//! [`super::stability_numeric`], writes `stability.csv` and `pdf_zero.csv`, and adds one claim
//! per case: held when the outcome is what theory expects ([`Expect`]).

use super::stability_cases::{self as sc, one_line, Case, Expect, Outcome};
use super::stability_numeric::{self as num, Sequence};
use super::{available, ExperimentDef};
use crate::config::{powers_of_four, Mode, Sweep, TestBedSpec};
use crate::error::Result;
use crate::output::{write_atomic, Claim, RunReport};
use crate::plan::Plan;
use crate::runner::RunResults;
use estimators::params::Params;
use std::path::{Path, PathBuf};

/// Ids of the harness sweep (the post hook names its own).
pub const IDS: &[&str] = &["is0_cv0", "is1_cv2"];

/// Definition.
pub static DEF: ExperimentDef = ExperimentDef {
    name: "stability",
    reproduces: "SPEC §10 (numerical stability cases), issue 9 item 3",
    summary: "every SPEC §10 stability case: correct within error bars or refused with a one-line error",
    ids: IDS,
    sweep,
    claims: |_| Vec::new(),
    post: Some(post),
};

fn sweep(mode: Mode) -> Sweep {
    let (estimators, _) = available(IDS);
    let bed = |v: &str| TestBedSpec {
        id: "gradient-box".into(),
        variant: Some(v.into()),
        params: Params::new().with("resolution", 4.0),
    };
    Sweep {
        experiment: DEF.name.into(),
        testbeds: vec![bed("furnace"), bed("albedo-0")],
        estimators,
        budgets: powers_of_four(1..=2),
        reps: if mode == Mode::Quick { 8 } else { 32 },
        seed: 1,
        mode,
        baseline: None,
    }
}

fn p(pairs: &[(&str, f64)]) -> Params {
    pairs.iter().fold(Params::new(), |p, (k, v)| p.with(k, *v))
}

/// Every estimator case; `k` scales the repetitions (1 quick, 4 full).
pub fn cases(k: u64) -> Vec<Case> {
    use Expect::{Correct, Refused};
    let case = |id,
                spec_item,
                tb: (&'static str, &'static str, Params),
                est: (&'static str, Params),
                samples,
                reps,
                expect| Case {
        id,
        spec_item,
        testbed: tb.0,
        variant: tb.1,
        bed: tb.2,
        estimator: est.0,
        params: est.1,
        samples,
        reps: reps * k,
        expect,
    };
    let box2 = |v| ("gradient-box", v, p(&[("resolution", 2.0)]));
    let canon = |v, extra: &[(&str, f64)]| ("canonical-1d", v, p(extra));
    let plain = |id| (id, Params::new());
    let stiff = ("gradient-plane", "stiff", p(&[("resolution", 2.0)]));
    let tau4 = [("tau", 1e4)];
    let empty = [("tau", 0.0)];
    let half = canon("constant-T0.5", &[]);
    vec![
        case("albedo-1-furnace-is0", "albedo exactly 1", box2("furnace"), plain("is0_cv0"), 4, 100, Correct),
        case("albedo-1-furnace-is1cv2", "albedo exactly 1", box2("furnace"), plain("is1_cv2"), 16, 60, Correct),
        case(
            "albedo-1-spm",
            "albedo exactly 1",
            canon("hole-T0.1", &[("albedo", 1.0)]),
            ("single_particle_nonterminating", p(&[("sigma_samp_ratio", 2.0)])),
            8,
            300,
            Correct,
        ),
        case("albedo-0-is0", "albedo exactly 0", box2("albedo-0"), plain("is0_cv0"), 4, 100, Correct),
        case("albedo-0-is1cv2", "albedo exactly 0", box2("albedo-0"), plain("is1_cv2"), 16, 60, Correct),
        case(
            "albedo-0-spm",
            "albedo exactly 0",
            canon("hole-T0.1", &[("albedo", 0.0)]),
            ("single_particle_nonterminating", p(&[("sigma_samp_ratio", 1.0)])),
            8,
            300,
            Correct,
        ),
        case(
            "thick-box-is0",
            "sigma_t 1e4",
            ("gradient-box", "thick", Params::new()),
            plain("is0_cv0"),
            4,
            40,
            Correct,
        ),
        case(
            "thick-box-is1cv2",
            "sigma_t 1e4",
            ("gradient-box", "thick", Params::new()),
            plain("is1_cv2"),
            16,
            20,
            Correct,
        ),
        case(
            "tau-1e4-delta",
            "sigma_t 1e4 (optical depth 1e4)",
            canon("constant-T0.5", &tau4),
            plain("delta_tracking"),
            4,
            100,
            Correct,
        ),
        case(
            "tau-1e4-ratio",
            "sigma_t 1e4 (optical depth 1e4)",
            canon("constant-T0.5", &tau4),
            plain("ratio_tracking"),
            4,
            50,
            Correct,
        ),
        case(
            "tau-1e4-double",
            "sigma_t 1e4 (optical depth 1e4)",
            canon("step-T0.5", &tau4),
            plain("double_particle"),
            4,
            50,
            Refused,
        ),
        case(
            "tau-1e4-residual",
            "sigma_t 1e4 (optical depth 1e4)",
            canon("step-T0.5", &tau4),
            plain("residual_ratio_tracking"),
            4,
            50,
            Correct,
        ),
        case(
            "empty-medium-delta",
            "sigma_t = 0 regions",
            canon("constant-T0.5", &empty),
            plain("delta_tracking"),
            4,
            50,
            Correct,
        ),
        case(
            "empty-medium-ratio",
            "sigma_t = 0 regions",
            canon("constant-T0.5", &empty),
            plain("ratio_tracking"),
            4,
            50,
            Correct,
        ),
        case(
            "empty-medium-residual",
            "sigma_t = 0 regions",
            canon("constant-T0.5", &empty),
            plain("residual_ratio_tracking"),
            4,
            50,
            Correct,
        ),
        case(
            "empty-rays-delta",
            "empty rays (missing the medium)",
            ("eq21-medium", "transmittance", p(&[("resolution", 4.0)])),
            plain("delta_tracking"),
            4,
            200,
            Correct,
        ),
        case(
            "empty-rays-residual",
            "empty rays (missing the medium)",
            ("eq21-medium", "transmittance", p(&[("resolution", 4.0)])),
            plain("residual_ratio_tracking"),
            4,
            200,
            Correct,
        ),
        case(
            "samp-1e-6-ratio",
            "sigma_samp 1e-6 x extinction",
            half.clone(),
            ("ratio_tracking", p(&[("sigma_samp_ratio", 1e-6)])),
            4,
            200,
            Refused,
        ),
        case(
            "samp-1e-6-double",
            "sigma_samp 1e-6 x extinction",
            half.clone(),
            ("double_particle", p(&[("sigma_samp_ratio", 1e-6)])),
            4,
            200,
            Refused,
        ),
        case(
            "samp-1e-6-terminating",
            "sigma_samp 1e-6 x extinction",
            half.clone(),
            ("single_particle_terminating", p(&[("sigma_samp_ratio", 1e-6)])),
            4,
            10,
            Refused,
        ),
        case(
            "samp-1e-6-nonterminating",
            "sigma_samp 1e-6 x extinction",
            half.clone(),
            ("single_particle_nonterminating", p(&[("sigma_samp_ratio", 1e-6)])),
            4,
            200,
            Refused,
        ),
        case(
            "samp-1e6-ratio",
            "sigma_samp 1e6 x extinction",
            half.clone(),
            ("ratio_tracking", p(&[("sigma_samp_ratio", 1e6)])),
            1,
            16,
            Correct,
        ),
        case(
            "samp-1e6-double",
            "sigma_samp 1e6 x extinction",
            half.clone(),
            ("double_particle", p(&[("sigma_samp_ratio", 1e6)])),
            1,
            16,
            Correct,
        ),
        case(
            "samp-1e6-terminating",
            "sigma_samp 1e6 x extinction",
            half.clone(),
            ("single_particle_terminating", p(&[("sigma_samp_ratio", 1e6)])),
            1,
            16,
            Correct,
        ),
        case(
            "negative-residual-hole",
            "negative difference extinction",
            canon("hole-T0.1", &[]),
            ("residual_ratio_tracking", p(&[("control", 1.0)])),
            8,
            300,
            Correct,
        ),
        case(
            "negative-residual-step",
            "negative difference extinction",
            canon("step-T0.01", &[]),
            ("residual_ratio_tracking", p(&[("control", 1.0)])),
            8,
            300,
            Correct,
        ),
        case(
            "negative-double-control",
            "negative difference extinction",
            canon("hole-T0.1", &[]),
            ("double_particle", p(&[("control", 1.0), ("sigma_samp_ratio", 0.5)])),
            8,
            300,
            Correct,
        ),
        case("phong-1e4-is0", "Phong n = 10000", stiff.clone(), plain("is0_cv0"), 64, 200, Correct),
        case(
            "phong-1e4-brdf",
            "Phong n = 10000; pdf zero: brdf_is0_cv0 (below the horizon)",
            stiff.clone(),
            plain("brdf_is0_cv0"),
            64,
            200,
            Correct,
        ),
        case(
            "phong-1e4-is1cv2",
            "Phong n = 10000; pdf zero: smc_surface cache pdf (direction outside the domain)",
            stiff,
            plain("is1_cv2"),
            64,
            100,
            Correct,
        ),
        case(
            "envmap-1e6-bis",
            "environment dynamic range 1e6; pdf zero: engine target 0 (log weight -inf)",
            ("envmap-sequence", "mixed", p(&[("resolution", 2.0), ("frames", 2.0), ("sun", 1e6)])),
            ("bidirectional_is", p(&[("candidates", 32.0)])),
            4,
            400,
            Correct,
        ),
        case(
            "envmap-1e6-smc",
            "environment dynamic range 1e6; SMC log weights",
            ("envmap-sequence", "mixed", p(&[("resolution", 2.0), ("frames", 2.0), ("sun", 1e6)])),
            ("smc", p(&[("candidates", 32.0), ("moves", 2.0)])),
            4,
            400,
            Correct,
        ),
        case(
            "mostly-zero-mis",
            "integrand zero on most of the domain; pdf zero: lighting MIS (BRDF pdf 0)",
            ("checker-direct", "occluded", p(&[("resolution", 2.0)])),
            plain("mis"),
            8,
            200,
            Correct,
        ),
        case(
            "mostly-zero-pmc-hi",
            "integrand zero on most of the domain; pdf zero: pmc_hi kernel pdf 0",
            ("checker-direct", "occluded", p(&[("resolution", 2.0)])),
            plain("pmc_hi"),
            16,
            200,
            Correct,
        ),
        case(
            "pdf-zero-source-driven",
            "pdf zero: source_driven (f = 0 where the density vanishes)",
            ("eq21-medium", "single-scatter", p(&[("resolution", 2.0)])),
            plain("source_driven"),
            4,
            200,
            Correct,
        ),
        case(
            "pdf-zero-scattering-driven",
            "pdf zero: scattering_driven (f = 0 where the density vanishes)",
            ("eq21-medium", "single-scatter", p(&[("resolution", 2.0)])),
            plain("scattering_driven"),
            4,
            200,
            Correct,
        ),
    ]
}

/// Where a pdf can be zero in `estimators/src`, the guard, and the case that exercises it.
pub const PDF_ZERO: &[(&str, &str, &str)] = &[
    ("independent/brdf_is0_cv0.rs", "sample skipped (scores 0) when the BRDF pdf is 0: it is only 0 where the integrand is", "phong-1e4-brdf"),
    ("smc_surface/mod.rs (sample_direction)", "a direction outside the cache domain gets cache pdf 0 and is weighted by the mixture pdf, which is > 0", "phong-1e4-is1cv2"),
    ("cache/grid.rs (put_positive) + cache/mod.rs quantise", "a positive PDF coefficient never rounds to 0; tree leaves are floor(c s) + 1 > 0", "phong-1e4-is1cv2"),
    ("media_smc/walk.rs (/ v.pdf)", "v.pdf is the cache/phase mixture density of the drawn direction (> 0 by construction)", "albedo-1-furnace-is1cv2, thick-box-is1cv2"),
    ("lighting.rs (MIS, b.pdf > 0 guard)", "a BRDF sample of pdf 0 scores 0", "mostly-zero-mis"),
    ("pmc/hi.rs (pdf > 0 guard)", "a kernel pdf of 0 scores 0 (only where every component is 0)", "mostly-zero-pmc-hi"),
    ("smc/engine.rs (t / s.pdf, ln t - ln pdf)", "environment samples have pdf > 0; a zero target gives log weight -inf, all -inf gives no population and estimate 0", "envmap-1e6-bis, smc-all-weights-zero"),
    ("smc/mh.rs (ln q_back)", "a proposal with reverse density 0 is rejected (log ratio -inf)", "envmap-1e6-smc"),
    ("single_scatter/source_driven.rs, scattering_driven.rs, mis.rs", "f = 0 is scored 0 before dividing by the density", "pdf-zero-source-driven, pdf-zero-scattering-driven"),
    ("tracking/mod.rs (non-terminating q_tran)", "q_tran = 0 (or 0/0 at albedo 0, r = 1) is guarded by q_tran > 0", "albedo-0-spm"),
];

/// The numeric cases: (id, spec item, expected, outcome).
fn numeric_cases(mode: Mode) -> Vec<(&'static str, &'static str, Expect, Outcome)> {
    let n = 100_000_000;
    let cache_n = 10_000_000;
    let _ = mode;
    let ((mixed_m, mixed_r), (trend_m, trend_r)) =
        rayon::join(|| num::running_means(Sequence::Mixed, n), || num::running_means(Sequence::Trend, n));
    let (cache_mixed, cache_trend) = rayon::join(
        || num::cache_cell(Sequence::Mixed, cache_n, num::MEAN_DRIFT_LIMIT),
        || num::cache_cell(Sequence::Trend, cache_n, 1e-9),
    );
    let item = "1e8 samples into one running mean";
    vec![
        ("running-mean-1e8-mixed-moments", item, Expect::Correct, mixed_m),
        ("running-mean-1e8-mixed-rgbmean", item, Expect::Correct, mixed_r),
        ("running-mean-1e8-trend-moments", item, Expect::Correct, trend_m),
        ("running-mean-1e8-trend-rgbmean", item, Expect::Correct, trend_r),
        ("cache-1e7-mixed", "1e7 samples into one cache", Expect::Correct, cache_mixed),
        (
            "cache-1e7-trend",
            "1e7 samples into one cache (uncompensated cell mean: limit 1e-9)",
            Expect::Correct,
            cache_trend,
        ),
        ("smc-log-weights-underflow", "SMC weights that underflow", Expect::Correct, num::underflowing_weights()),
        ("smc-all-weights-zero", "every weight zero (ESS undefined)", Expect::Refused, num::all_zero_weights()),
    ]
}

/// `k=v;k=v` of a parameter set (empty when none).
fn params_text(p: &Params) -> String {
    p.0.iter()
        .map(|(k, v)| match v {
            estimators::params::ParamValue::Number(x) => format!("{k}={x}"),
            estimators::params::ParamValue::Text(t) => format!("{k}={t}"),
        })
        .collect::<Vec<_>>()
        .join(";")
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn num_field(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        format!("{x:.9e}")
    }
}

/// Runs every case, writes `stability.csv` and `pdf_zero.csv`, adds one claim per case.
pub fn post(
    plan: &Plan,
    _run: &RunResults,
    report: &mut RunReport,
    results: &Path,
    _plots: Option<&Path>,
) -> Result<Vec<PathBuf>> {
    let mode = plan.sweep.mode;
    let seed = plan.sweep.seed;
    let k = if mode == Mode::Quick { 1 } else { 4 };
    let mut rows: Vec<[String; 11]> = Vec::new();
    let mut push = |id: &str, item: &str, bed: String, est: String, params: String, expect: Expect, o: Outcome| {
        let expected = if expect == Expect::Correct { "correct" } else { "refused" };
        report.paper.push(Claim {
            testbed: bed.clone(),
            claim: format!("SPEC §10 {item}: `{id}` ({est}) is {expected}"),
            paper_value: None,
            our_value: (!o.statistic.is_nan()).then_some(o.statistic),
            held: Some(o.outcome == expected),
            note: format!("{}: {}", o.outcome, one_line(&o.text)),
        });
        let (tb, variant) = bed.split_once('/').unwrap_or((&bed, ""));
        rows.push([
            id.into(),
            item.into(),
            tb.into(),
            variant.into(),
            est,
            params,
            o.outcome.into(),
            expected.into(),
            num_field(o.value),
            num_field(o.reference),
            format!("{}={}|{}", o.statistic_name, num_field(o.statistic), one_line(&o.text)),
        ]);
    };
    for c in cases(k) {
        let o = sc::run(&c, seed);
        let bed_params = params_text(&c.bed);
        let est_params = params_text(&c.params);
        let params = match (est_params.is_empty(), bed_params.is_empty()) {
            (_, true) => est_params,
            (true, false) => format!("bed[{bed_params}]"),
            (false, false) => format!("{est_params} bed[{bed_params}]"),
        };
        push(c.id, c.spec_item, format!("{}/{}", c.testbed, c.variant), c.estimator.into(), params, c.expect, o);
    }
    for (id, item, expect, o) in numeric_cases(mode) {
        push(id, item, "numeric/".into(), "-".into(), String::new(), expect, o);
    }
    let mut csv = String::from(
        "case,spec_item,testbed,variant,estimator,params,outcome,expected,value,reference,statistic,error_text\n",
    );
    for r in &rows {
        let (stat, text) = r[10].split_once('|').unwrap_or((&r[10], ""));
        let fields: Vec<String> =
            r[..10].iter().map(|s| csv_field(s)).chain([csv_field(stat), csv_field(text)]).collect();
        csv.push_str(&fields.join(","));
        csv.push('\n');
    }
    write_atomic(&results.join("stability.csv"), csv.as_bytes())?;
    let mut pz = String::from("site,guard,cases\n");
    for (site, guard, cases) in PDF_ZERO {
        pz.push_str(&format!("{},{},{}\n", csv_field(site), csv_field(guard), csv_field(cases)));
    }
    write_atomic(&results.join("pdf_zero.csv"), pz.as_bytes())?;
    Ok(Vec::new())
}

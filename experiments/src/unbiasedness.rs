//! `unbiasedness` (issue 9 item 1; SPEC §6 and the last bullets of §7): every registered estimator
//! on every test bed and variant it runs on, with the SPEC §6 test matched to the reference kind
//! (exact: per-integral t-tests with Holm-Bonferroni; stored: Welch against the stored run; both
//! combined by Bonferroni with the pooled z-test, see [`table::combined`]), the biased controls in
//! the same run and required to be flagged (except where [`table::control_exemption`] says why a
//! control is unbiased by construction on a test bed). One table, `unbiasedness.csv`: estimator x test bed -> p-value, verdict,
//! the relative bias the run could detect with 80% power, the repetitions that would resolve a 0.1%
//! relative bias, and whether the paper calls the estimator unbiased.
//!
//! Estimators differ too much in cost and budget semantics for one sweep (a budget of 10 spp is
//! PMC-IP's 2+4+4 schedule, 4 particles per frame an SMC run, 4 rays a tracker's estimate), so the
//! experiment is a list of [`Part`]s, each an ordinary [`Sweep`] (test beds x estimators at one
//! small budget, its own repetitions) paired by the registry's needs: the first part is the
//! experiment's sweep (what `--config` overrides), the others run in the post hook
//! ([`crate::unbiasedness_run`]) into the same results folder, summary rows and tests. Test beds are
//! shrunk to a few pixels (every variant of every test bed is run), except where the reference is
//! stored at a fixed resolution (`checker-image` 48x48, the `multiple` media and `gradient-box`
//! 16x16, Perlin single scattering 4x4, `gradient-box/thick` 4x4).

use crate::{unbiasedness_table as table, ExperimentDef};
use estimators::budget::Budget;
use estimators::params::Params;
use mcbench::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};
use mcbench::output::{Claim, RunReport};

/// Every registered estimator id (a unit test checks this list against the registry, so a new
/// estimator cannot be left out of the experiment silently).
pub const IDS: &[&str] = &[
    "is0_cv0",
    "brdf_is0_cv0",
    "clamped_is0_cv0",
    "is0_cv1",
    "is0_cv2",
    "is1_cv0",
    "is1_cv1",
    "is1_cv2",
    "brdf_is1_cv2",
    "rm_is1_cv2",
    "bidirectional_is",
    "bidirectional_is_sn",
    "smc",
    "smc_bridge",
    "smc_path",
    "smc_adaptive",
    "mis",
    "pmc_hi",
    "pmc_hi_feedback",
    "uniform_image",
    "pmc_ip",
    "threshold_image",
    "ray_marching",
    "delta_tracking",
    "ratio_tracking",
    "residual_ratio_tracking",
    "double_particle",
    "single_particle_terminating",
    "single_particle_nonterminating",
    "spm_terminating",
    "spm_nonterminating",
    "spm_adaptive",
    "attenuation_driven",
    "attenuation_driven_sir",
    "source_driven",
    "scattering_driven",
];

/// Definition.
pub static DEF: ExperimentDef = ExperimentDef {
    name: "unbiasedness",
    reproduces: "SPEC §6 over every estimator x test bed (issue 9 item 1)",
    summary: "every estimator on every test bed and variant it runs on: Holm t / pooled z / Welch, detectable bias, the biased controls flagged",
    ids: IDS,
    sweep,
    claims,
    post: Some(crate::unbiasedness_run::post),
};

/// One part of the experiment: a sweep at one budget suited to its estimators.
pub struct Part {
    /// Short name (progress lines, README).
    pub name: &'static str,
    /// The sweep (one budget).
    pub sweep: Sweep,
}

fn bed(id: &str, variant: &str, params: Params) -> TestBedSpec {
    TestBedSpec { id: id.into(), variant: Some(variant.into()), params }
}

fn ests(ids: &[&str]) -> Vec<EstimatorSpec> {
    ids.iter().map(|id| EstimatorSpec::new(id)).collect()
}

/// The ray-marching control: a coarse fixed step (4 steps on the 20-unit central ray) whose Jensen
/// bias is detectable; the id's default step 0.9 is the paper's baseline, biased far below what a
/// run of this size can resolve, so it is not what the teeth are shown with (as in `transmittance`).
fn marching_control() -> EstimatorSpec {
    EstimatorSpec { id: "ray_marching".into(), params: Params::new().with("step", 5.0) }
}

/// Repetitions per part: (quick, full). Quick keeps the experiment near a minute on 2 cores; full
/// multiplies them by 4 to 16 (the table says per row whether 0.1% was resolved and what R would).
fn reps(mode: Mode, quick: usize, full: usize) -> usize {
    if mode == Mode::Quick {
        quick
    } else {
        full
    }
}

fn part(
    name: &'static str,
    mode: Mode,
    beds: Vec<TestBedSpec>,
    estimators: Vec<EstimatorSpec>,
    spp: u64,
    r: (usize, usize),
) -> Part {
    Part {
        name,
        sweep: Sweep {
            experiment: DEF.name.into(),
            testbeds: beds,
            estimators,
            budgets: vec![Budget { kind: estimators::budget::BudgetKind::Samples, amount: spp }],
            reps: reps(mode, r.0, r.1),
            seed: 1,
            mode,
            baseline: None,
        },
    }
}

/// Every part for a mode, in run order (the first is [`DEF`]'s sweep).
pub fn parts(mode: Mode) -> Vec<Part> {
    let res = |n: f64| Params::new().with("resolution", n);
    let surface_beds = ["default", "diffuse", "glossy", "stiff"]
        .iter()
        .map(|v| bed("gradient-plane", v, res(4.0)))
        .chain(["default", "occluded"].iter().map(|v| bed("checker-direct", v, res(4.0))))
        .collect();
    let surface = ests(&[
        "is0_cv0",
        "brdf_is0_cv0",
        "is0_cv1",
        "is0_cv2",
        "is1_cv0",
        "is1_cv1",
        "is1_cv2",
        "brdf_is1_cv2",
        "mis",
        "pmc_hi",
        "pmc_hi_feedback",
        "clamped_is0_cv0",
    ]);
    let env = |v: &str| bed("envmap-sequence", v, res(2.0).with("frames", 4.0));
    let mut env_ests = ests(&["bidirectional_is", "smc", "smc_bridge", "smc_path", "smc_adaptive"]);
    // The self-normalised control with 2 candidates (as envmap-smc's dedicated check): its bias
    // shrinks like 1/M, so more candidates would hide it.
    env_ests.push(EstimatorSpec { id: "bidirectional_is_sn".into(), params: Params::new().with("candidates", 2.0) });
    let image = ["default", "occluded"].iter().map(|v| bed("checker-image", v, Params::new())).collect();
    let trackers = [
        "delta_tracking",
        "ratio_tracking",
        "residual_ratio_tracking",
        "double_particle",
        "single_particle_terminating",
        "single_particle_nonterminating",
    ];
    let mut tracking_ests = ests(&trackers);
    tracking_ests.push(marching_control());
    let mut tracking_beds = Vec::new();
    for m in ["eq21-medium", "perlin-medium"] {
        tracking_beds.push(bed(m, "central-ray", Params::new().with("points", 8.0)));
        tracking_beds.push(bed(m, "transmittance", res(4.0)));
    }
    let mut canonical = Vec::new();
    for v in estimators::testbeds::canonical_1d::VARIANTS {
        canonical.push(bed("canonical-1d", v, Params::new()));
    }
    let scatter_beds =
        vec![bed("eq21-medium", "single-scatter", res(4.0)), bed("perlin-medium", "single-scatter", Params::new())];
    let mut scatter = ests(&[
        "delta_tracking",
        "attenuation_driven",
        "attenuation_driven_sir",
        "source_driven",
        "scattering_driven",
        "mis",
    ]);
    scatter.push(marching_control());
    let multiple_beds = ["eq21-medium", "perlin-medium"].iter().map(|m| bed(m, "multiple", Params::new())).collect();
    // Every medium id on the radiance variants: the transmittance-only trackers are skipped there
    // with their reason (summary.json `skipped`), not left out.
    let radiance_ids = [
        "spm_terminating",
        "spm_nonterminating",
        "spm_adaptive",
        "delta_tracking",
        "ratio_tracking",
        "residual_ratio_tracking",
        "double_particle",
        "single_particle_terminating",
        "single_particle_nonterminating",
    ];
    let mut multiple = ests(&radiance_ids);
    multiple.push(marching_control());
    let boxes = estimators::testbeds::gradient_box::ENTRY
        .variants
        .iter()
        .map(|v| bed("gradient-box", v, Params::new()))
        .collect();
    let mut box_ests = ests(&["is0_cv0", "is0_cv1", "is0_cv2", "is1_cv0", "is1_cv1", "is1_cv2", "rm_is1_cv2"]);
    box_ests.extend(multiple.iter().cloned());
    vec![
        part("surface", mode, surface_beds, surface, 64, (512, 8192)),
        part(
            "envmap",
            mode,
            ["specular", "mixed", "specular-lns", "mixed-lns"].iter().map(|v| env(v)).collect(),
            env_ests,
            4,
            (1500, 20_000),
        ),
        part("image", mode, image, ests(&["uniform_image", "pmc_ip", "threshold_image"]), 10, (32, 256)),
        part("tracking", mode, tracking_beds, tracking_ests.clone(), 4, (1024, 32_768)),
        part("canonical", mode, canonical, tracking_ests, 4, (16_384, 65_536)),
        part("single-scatter", mode, scatter_beds, scatter, 4, (1024, 8192)),
        part("multiple", mode, multiple_beds, multiple, 4, (64, 256)),
        part("gradient-box", mode, boxes, box_ests, 16, (256, 1024)),
    ]
}

fn sweep(mode: Mode) -> Sweep {
    parts(mode).swap_remove(0).sweep
}

/// The claims come from the table, which needs every part's cells: see the post hook.
fn claims(_report: &RunReport) -> Vec<Claim> {
    Vec::new()
}

/// Re-exported for the post hook and tests.
pub use table::Row;

//! `residual_ratio_tracking` (paper 002 §4.2 `Transmittance`, \[NSJ14\]): a main part `sigma_main`
//! through explorer points (cheap approximate extinction, spaced `explorer_spacing`, default 0.5;
//! computed once per pixel and reused by all its rays, as the paper reuses explorer data of
//! neighbouring rays): `control = 1` (default) the piecewise-linear fit of §4, `control = 2` the
//! constant at its mean, the L2-optimal constant of §3.4; `T = T_main * E` with `E *= 1 - r`,
//! `r = sigma_diff / sigma_samp`, and a constant `sigma_samp` = the largest `|sigma_diff|` seen on
//! the last `recent` rays (default 4; at least `sigma_floor`, default 0.05; the first ray uses
//! `sigma_samp0`, default 0.3 x majorant). Neither a majorant nor `|sigma_diff| <= sigma_samp` is
//! needed (negative difference extinction, §3.3). The harness estimates pixels independently, so
//! explorer data is not shared across pixels here.

use super::params::ResidualParams;
use super::{supports_transmittance, track_scaled, transmittance, Rule};
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::{check_count, parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::free_flight::{Interp, SamplingDensity};
use mcbench_core::task::{MediumProbe, Task};
use mcbench_core::testbed::{Needs, TestBed};
use std::collections::VecDeque;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "residual_ratio_tracking",
    paper: "002",
    label: "residual ratio tracking (new method)",
    bias: Bias::Unbiased,
    needs: Needs::MEDIUM,
    samplers: &["free_flight"],
    summary: "control variate through explorer points + constant sigma_samp ~ max |sigma_diff| of the last rays",
    build: |p| {
        let p = parse::<ResidualParams>("residual_ratio_tracking", p)?;
        Ok(Box::new(ResidualRatioTracking::from_params(&p, "residual_ratio_tracking")?))
    },
    params: ParamSpec::of::<ResidualParams>().display("residual ratio tracking").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct ResidualRatioTracking {
    /// Explorer spacing.
    pub spacing: f64,
    /// Rays remembered for sigma_samp.
    pub recent: usize,
    /// Smallest sigma_samp.
    pub floor: f64,
    /// sigma_samp of the first ray (`None`: 0.3 x majorant).
    pub first: Option<f64>,
    /// The main part's shape.
    pub kind: MainPart,
}

impl ResidualRatioTracking {
    /// Builds from its parameters (shared by the single-scatter estimators, whose rays are tracked
    /// the same way), refusing out-of-range values naming `owner`.
    pub fn from_params(p: &ResidualParams, owner: &str) -> Result<Self, ConfigError> {
        let (spacing, floor) = (p.explorer_spacing, p.sigma_floor);
        for (name, v) in [("explorer_spacing", spacing), ("sigma_floor", floor)] {
            if v <= 0.0 {
                return Err(ConfigError::invalid(format!("{owner}.{name}"), v, "must be > 0"));
            }
        }
        let recent = check_count("recent", p.recent, 1000)?;
        let Some(kind) = MainPart::from_control(p.control, owner)? else {
            return Err(ConfigError::invalid(
                format!("{owner}.control"),
                0,
                "the residual estimator needs a main part: 1 (piecewise linear) or 2 (mean)",
            ));
        };
        Ok(ResidualRatioTracking { spacing, recent, floor, first: p.sigma_samp0.filter(|first| *first > 0.0), kind })
    }

    /// A fresh sigma_samp memory for a scene with this majorant.
    pub fn memory(&self, majorant: f64) -> RecentMaximum {
        RecentMaximum::new(self.recent, self.floor, self.first.unwrap_or(0.3 * majorant))
    }
}

/// The shape of a control variate's main part fitted through explorer points (paper 002 §3.3-4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MainPart {
    /// The piecewise-linear interpolation of the explorer values (paper 002 §4, Fig. 5).
    Linear,
    /// The constant mean of that interpolation over the segment: the explorer points' estimate of
    /// the mean extinction, the L2-optimal constant main part of §3.4.
    Mean,
}

impl MainPart {
    /// The `control` parameter: 0 (none), 1 ([`MainPart::Linear`]) or 2 ([`MainPart::Mean`]).
    pub fn from_control(control: u32, owner: &str) -> Result<Option<MainPart>, ConfigError> {
        match control {
            0 => Ok(None),
            1 => Ok(Some(MainPart::Linear)),
            2 => Ok(Some(MainPart::Mean)),
            v => Err(ConfigError::invalid(
                format!("{owner}.control"),
                v,
                "must be 0 (none), 1 (piecewise-linear main part) or 2 (constant at its mean)",
            )),
        }
    }
}

/// The main part through explorer points on `[t0, t1]` of the integral's ray and its transmittance
/// `exp(-int sigma_main)` (cheap fetches, or full ones when the scene has no approximation): the
/// piecewise-linear fit, or the constant at its mean (both have the same integral, so the same
/// `T_main`).
pub fn main_part(probe: &MediumProbe<'_>, seg: (f64, f64), spacing: f64, kind: MainPart) -> (SamplingDensity, f64) {
    let ray = *probe.ray();
    main_part_along(probe, (ray.origin, ray.dir), seg, spacing, kind)
}

/// [`main_part`] along any line `origin + s dir` (e.g. a shadow ray).
pub fn main_part_along(
    probe: &MediumProbe<'_>,
    (origin, dir): (Vec3, Vec3),
    (t0, t1): (f64, f64),
    spacing: f64,
    kind: MainPart,
) -> (SamplingDensity, f64) {
    let n = ((t1 - t0) / spacing).ceil().max(1.0) as usize;
    let t: Vec<f64> = (0..=n).map(|j| t0 + (t1 - t0) * j as f64 / n as f64).collect();
    let v: Vec<f64> = t.iter().map(|&s| probe.sigma_approx(origin + dir * s)).collect();
    let main = SamplingDensity::new(t, v, Interp::Linear);
    let integral = main.integral(t0, t1);
    let main = match kind {
        MainPart::Linear => main,
        MainPart::Mean => SamplingDensity::constant(integral / (t1 - t0)),
    };
    (main, (-integral).exp())
}

/// The paper's constant `sigma_samp` (§4.3): the largest `|sigma_diff|` seen on the last `recent`
/// rays, at least `floor`; `first` before any ray was seen.
#[derive(Clone, Debug)]
pub struct RecentMaximum {
    recent: usize,
    floor: f64,
    first: f64,
    maxima: VecDeque<f64>,
}

impl RecentMaximum {
    /// An empty memory.
    pub fn new(recent: usize, floor: f64, first: f64) -> Self {
        RecentMaximum { recent, floor, first, maxima: VecDeque::new() }
    }
    /// The sampling extinction for the next ray.
    pub fn sigma(&self) -> f64 {
        self.maxima.iter().copied().reduce(f64::max).unwrap_or(self.first).max(self.floor)
    }
    /// Remembers the largest `|sigma_diff|` of a finished ray.
    pub fn push(&mut self, seen: f64) {
        self.maxima.push_back(seen);
        if self.maxima.len() > self.recent {
            self.maxima.pop_front();
        }
    }
}

impl Estimator for ResidualRatioTracking {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        // The main part, its transmittance and its optical depth on the segment (the same for
        // every ray of the estimate: computed on the first).
        let mut main: Option<(SamplingDensity, f64, f64)> = None;
        let mut memory: Option<RecentMaximum> = None;
        transmittance(task, rng, |probe, seg, rng| {
            let (m, tm, depth) = main.get_or_insert_with(|| {
                let (m, tm) = main_part(probe, seg, self.spacing, self.kind);
                let depth = m.integral(seg.0, seg.1);
                (m, tm, depth)
            });
            let memory = memory.get_or_insert_with(|| self.memory(probe.majorant()));
            let sigma = memory.sigma();
            let mut seen = 0.0f64;
            let line = (probe.ray().origin, probe.ray().dir);
            let e =
                track_scaled(probe, line, seg, &SamplingDensity::constant(sigma), Some(m), Rule::Double, rng, |i| {
                    seen = seen.max(i.sigma_diff.abs())
                })?;
            memory.push(seen);
            task.note("sigma_samp", sigma);
            // In log space where the product overflows and T_main underflows (optical depth 1e4).
            Ok(e.times_transmittance(*tm, *depth))
        })
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        supports_transmittance(bed)
    }
}

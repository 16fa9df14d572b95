//! `mis`: the paper 003 baseline (§5, Table 2): multiple importance sampling (Veach 1997) with one
//! BRDF sample and one light sample per round (the light chosen with probability proportional to
//! its power, a uniform point on it), combined with the balance heuristic (`power` = 2 selects the
//! power heuristic). A round's estimate is `f(x_b) w_b(x_b) / p_b(x_b) + f(x_l) w_l(x_l) / p_l(x_l)`;
//! an odd budget ends with a BRDF-only round `f / p_b`. The estimate averages the rounds. On
//! point-light single scattering in a medium the same id is paper 002's MIS
//! ([`crate::single_scatter::mis`]).

use crate::single_scatter::mis::MisScatter;
use crate::single_scatter::params::MisParams;
use crate::single_scatter::SingleScatterOr;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::{HemisphereProbe, Task};
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "mis",
    paper: "003",
    label: "MIS",
    bias: Bias::Unbiased,
    needs: Needs::NONE,
    samplers: &["brdf", "rect_light"],
    summary: "one BRDF + one light sample per round, balance heuristic (power = 2: power heuristic); on point-light single scattering (paper 002), source- + scattering-driven points, balance heuristic",
    build: |p| {
        let p = parse::<MisParams>("mis", p)?;
        Ok(Box::new(SingleScatterOr {
            single_scatter: Box::new(MisScatter::from_params(&p)?),
            other: Box::new(Mis { power: p.power }),
        }))
    },
    params: ParamSpec::of::<MisParams>().display("MIS").words(crate::words::param),
    checks: Checks::DEFAULT,
};

/// The estimator.
pub struct Mis {
    /// Heuristic exponent: 1 balance, 2 power.
    pub power: f64,
}

pub use mcbench_core::lighting::{light_pdf, light_selection};
use mcbench_core::lighting::{mis_round, MisStrategy};

impl Mis {
    /// One round: a BRDF sample and (when `light` is set) a light sample
    /// ([`mcbench_core::lighting::mis_round`] through the counted integrand).
    pub fn round(&self, probe: &HemisphereProbe<'_>, select: &[f64], light: bool, rng: &mut StreamRng) -> Rgb {
        let strategy = MisStrategy { lights: probe.lights(), select, power: self.power };
        mis_round(probe.point().position, probe.brdf(), &strategy, light, |w, f| probe.integrand_with_brdf(w, f), rng)
    }
}

impl Estimator for Mis {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.hemisphere().ok_or_else(|| EstimateError::Refused("mis needs a surface".into()))?;
        if probe.lights().is_empty() {
            return Err(EstimateError::Refused("mis needs area lights".into()));
        }
        let select = light_selection(probe.lights());
        let (mut sum, mut rounds) = (Rgb::ZERO, 0u64);
        let budget = task.budget();
        while task.more() {
            let left = match budget.kind {
                mcbench_core::budget::BudgetKind::Samples => budget.amount - task.costs().samples,
                _ => 2,
            };
            sum += self.round(&probe, &select, left >= 2, rng);
            rounds += 1;
        }
        Ok(if rounds > 0 { sum / rounds as f64 } else { Rgb::ZERO })
    }
    fn supports(&self, bed: &dyn mcbench_core::testbed::TestBed) -> Result<(), String> {
        match bed.hemisphere() {
            Some(h) if !h.lights().is_empty() => Ok(()),
            _ => Err("mis needs a surface with area lights (paper 003) or point-light single scattering in a medium (paper 002)".into()),
        }
    }
}

//! Planted changes, for calibrating `mcbench compare` (book: compare.md): one estimator id,
//! `planted_mc` (independent uniform sampling of the hemisphere), in three versions: as it is
//! ([`PLAIN`]), every estimate scaled by 1.02 (a 2% bias, [`BIASED`]), and using five of every six
//! samples it draws ([`NOISY`]: independent sampling has variance 1/N, so 1.2 times the variance at
//! the same cost). A registry holds one version, so two runs of [`CONFIG`] under two registries
//! compare the same estimator name before and after a change. Not part of the suite.

use mcbench::mcbench_core::params::{parse, NoParams};
use mcbench::{
    Bias, Checks, EstimateError, Estimator, EstimatorEntry, Needs, ParamSpec, Registry, Rgb, StreamRng, Task,
};

/// The sweep the calibration runs: a 256-pixel image of the diffuse plane, three budgets, 64
/// repetitions (about a second on the debug binary), the unchanged `is0_cv0` and `planted_mc`.
pub const CONFIG: &str = "name = 'cmp'\nreps = 64\nbudgets = [16, 64, 256]\n\
[[testbeds]]\nid = 'gradient-plane'\nvariant = 'diffuse'\nparams = { resolution = 16 }\n\
[[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'planted_mc'\n";

/// Uniform sampling of the hemisphere, scaled by `scale`, keeping five of six samples when
/// `drop_sixth`.
struct Planted {
    scale: f64,
    drop_sixth: bool,
}

impl Estimator for Planted {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        use mcbench::mcbench_core::{math::Frame, samplers::uniform_hemisphere};
        let probe = task.hemisphere().ok_or(EstimateError::Refused("needs a surface".into()))?;
        let frame = Frame::around(probe.point().normal);
        let (mut sum, mut n, mut k) = (Rgb::ZERO, 0.0, 0u64);
        while task.more() {
            let wi = frame.to_world(uniform_hemisphere::sample_local(rng));
            let v = probe.integrand(wi) / uniform_hemisphere::pdf(1.0);
            k += 1;
            if !(self.drop_sixth && k % 6 == 0) {
                sum += v;
                n += 1.0;
            }
        }
        Ok(sum / n * self.scale)
    }
}

macro_rules! planted {
    ($(#[$doc:meta])* $name:ident, $scale:expr, $drop:expr) => {
        $(#[$doc])*
        pub static $name: EstimatorEntry = EstimatorEntry {
            id: "planted_mc",
            paper: "harness",
            label: "uniform hemisphere sampling (planted change)",
            bias: Bias::Unbiased,
            needs: Needs::SURFACE,
            samplers: &["uniform_hemisphere"],
            summary: "uniform hemisphere sampling with a planted change, for calibrating comparisons",
            build: |p| {
                parse::<NoParams>("planted_mc", p)?;
                Ok(Box::new(Planted { scale: $scale, drop_sixth: $drop }))
            },
            params: ParamSpec::NONE,
            checks: Checks::DEFAULT,
        };
    };
}

planted!(
    /// The unchanged version.
    PLAIN, 1.0, false
);
planted!(
    /// Every estimate scaled by 1.02: a 2% bias.
    BIASED, 1.02, false
);
planted!(
    /// Five of every six samples used: 1.2 times the variance at the same cost.
    NOISY, 1.0, true
);

/// The suite's registry with one version of `planted_mc`.
pub fn registry(version: &'static EstimatorEntry) -> Registry {
    crate::registry().with_estimator(version)
}

/// Runs [`CONFIG`] in process with `version` as `planted_mc` at `seed` into `<dir>/<name>` (the
/// config written to `<dir>/cmp.toml`; no plots, no per-integral file). Panics when the run fails:
/// for the comparison's test and calibration.
pub fn run(dir: &std::path::Path, name: &str, version: &'static EstimatorEntry, seed: u64) {
    let config = dir.join("cmp.toml");
    std::fs::write(&config, CONFIG).expect("config");
    let results = dir.join(name);
    let (c, r) = (config.to_string_lossy().to_string(), results.to_string_lossy().to_string());
    let seed = seed.to_string();
    let args =
        ["mcbench", "run", "--config", &c, "--seed", &seed, "--no-plots", "--integrals", "none", "--results", &r];
    assert_eq!(mcbench::cli::main_with_args(registry(version), args), 0, "run {name} failed");
}

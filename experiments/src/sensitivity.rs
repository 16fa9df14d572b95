//! The `sensitivity` experiment: every headline claim of papers 000-004 against the parameters
//! the papers leave open (optical thickness, spp range, BRDF, explorer spacing, the light against
//! the pixel rays, fetch range, defensive constants, light samples, rotation rate), judged at
//! every setting exactly as its own experiment judges it, with our default and the setting closest
//! to the paper's marked ([`mcbench::sensitivity`]; the parts are `sensitivity.toml` beside this
//! file). Runs only when named: `mcbench run sensitivity`.

use mcbench::error::Result;
use mcbench::registry::PostContext;
use mcbench::registry::{Experiment, Registry};
use mcbench::sensitivity::{run, SensitivityFile};
use std::path::{Path, PathBuf};

/// The experiment's parts.
pub const TOML: &str = include_str!("sensitivity.toml");

/// The parsed file (it is embedded; a test of this crate checks it parses).
pub fn file() -> SensitivityFile {
    SensitivityFile::parse(TOML).unwrap_or_else(|e| panic!("the sensitivity file of the suite does not parse: {e}"))
}

fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    run::post(&file(), cx)
}

fn preflight(registry: &Registry, first: &mcbench::config::Sweep, cells: &Path) -> Result<()> {
    run::preflight(&file(), registry, first, cells)
}

/// The experiment.
pub fn experiment() -> Experiment {
    run::experiment(&file(), post, preflight)
        .unwrap_or_else(|e| panic!("the sensitivity file of the suite gives no sweep: {e}"))
}

#[cfg(test)]
mod tests {
    use mcbench::config::Mode;

    /// Every part builds at every setting in both modes (names, parameters, stored references),
    /// and its claim names what the setting runs.
    #[test]
    fn every_setting_of_every_part_builds() {
        let registry = crate::test_registry();
        let file = super::file();
        let mut settings = 0;
        for part in &file.parts {
            for mode in [Mode::Quick, Mode::Full] {
                for v in &part.values {
                    let (sweep, claim) = part.setting(&file.name, 1, mode, v).expect("setting");
                    let names: Vec<String> = sweep.estimators.iter().map(|e| e.name()).collect();
                    for e in claim.estimators() {
                        assert!(names.iter().any(|n| n == e), "{}: {e} is not run", part.id);
                    }
                    if mode == Mode::Quick {
                        mcbench::plan::Plan::prepare(sweep, &registry)
                            .unwrap_or_else(|e| panic!("{} at {v:?}: {e}", part.id));
                    }
                    settings += 1;
                }
            }
        }
        assert!(settings >= 2 * file.parts.len());
    }
}

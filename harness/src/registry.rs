//! The registry a run looks names up in: estimators, test beds and named experiments. It is a
//! value, built in `main` and handed to [`crate::cli::main_with`] and to planning, so a crate of
//! your own adds its plug-ins (and, if it wants them, a [`Catalog`] such as the papers' built-ins
//! of `mcbench-papers`) without touching mcbench:
//!
//! ```
//! use mcbench::{EstimatorEntry, Registry};
//!
//! // An estimator of your own: here the papers' independent estimator under another id.
//! static MINE: EstimatorEntry = EstimatorEntry { id: "my_estimator", ..mcbench_papers::independent::is0_cv0::ENTRY };
//!
//! // The harness's own experiments, the papers' estimators and test beds, and yours.
//! let registry = Registry::new().with_catalog(mcbench_papers::catalog()).with_estimator(&MINE);
//! assert!(registry.estimator("my_estimator").is_ok());
//! assert!(registry.estimator("is1_cv2").is_ok(), "the built-in ones stay");
//! registry.check().expect("no id registered twice");
//! // In `main`: std::process::exit(mcbench::cli::main_with(registry));
//! ```

use crate::config::{Mode, Sweep};
use crate::error::Result;
use crate::output::plot::DisplayNames;
use crate::output::{Claim, RunReport};
use crate::plan::Plan;
use crate::run::runner::RunResults;
use crate::store::folder::OutputDir;
use crate::store::references::ReferenceDir;
use mcbench_core::entry::{EstimatorEntry, Exemption, TestBedEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::export::SceneExport;
use mcbench_core::references::{Chain, ReferenceKey, ReferenceSource, StoredReference};
use mcbench_core::{Catalog, SamplerEntry};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What an experiment's own analysis after the run gets ([`PostFn`]).
pub struct PostContext<'a> {
    /// The plan that ran.
    pub plan: &'a Plan,
    /// The finished cells.
    pub results: &'a RunResults,
    /// The report to extend (claims, skipped pairs, diagnostics).
    pub report: &'a mut RunReport,
    /// The results folder: its files are written through it and committed with the run's.
    pub out: &'a OutputDir,
    /// The plots folder, when plots are drawn.
    pub plots: Option<&'a Path>,
    /// The registry the run looked its names up in.
    pub registry: &'a Registry,
}

/// An experiment's own analysis after the run: its [`PostContext`] -> extra plot files. For real
/// figures and tables beyond what every run writes.
pub type PostFn = fn(PostContext<'_>) -> Result<Vec<PathBuf>>;

/// The claims of an experiment, judged on a finished run.
pub type ClaimsFn = fn(&RunReport) -> Vec<Claim>;

/// Checks an experiment's own reads before anything is written: (registry, the sweep as it will
/// run, the results folder's cell store `cells.store`). For experiments whose analysis runs
/// further sweeps.
pub type PreflightFn = fn(&Registry, &Sweep, &Path) -> Result<()>;

/// Where an experiment's sweeps come from.
#[derive(Clone)]
pub enum Sweeps {
    /// Fixed sweeps.
    Fixed {
        /// The sweep of `--quick` (the default).
        quick: Box<Sweep>,
        /// The sweep of `--full`.
        full: Box<Sweep>,
    },
    /// Derived from the registry the experiment runs in (e.g. `unbiasedness`: every registered
    /// estimator on every test bed it runs on).
    Derived(fn(&Registry, Mode) -> Sweep),
}

/// A named experiment: a sweep for quick and for full mode, the claims it judges, and optionally
/// an analysis of its own.
#[derive(Clone)]
pub struct Experiment {
    /// Name (results folder, CLI argument).
    pub name: String,
    /// The paper figure or table it reproduces (free text).
    pub reproduces: String,
    /// One line for `mcbench list experiments`.
    pub summary: String,
    /// Its sweeps.
    pub sweeps: Sweeps,
    /// Claims judged on the finished run.
    pub claims: Option<ClaimsFn>,
    /// Analysis after the run.
    pub post: Option<PostFn>,
    /// Checks of what the analysis will read, before the run writes anything.
    pub preflight: Option<PreflightFn>,
}

impl Experiment {
    /// The sweep for a mode, in `registry`.
    pub fn sweep(&self, registry: &Registry, mode: Mode) -> Sweep {
        match &self.sweeps {
            Sweeps::Fixed { quick, full } => match mode {
                Mode::Quick => (**quick).clone(),
                Mode::Full => (**full).clone(),
            },
            Sweeps::Derived(f) => f(registry, mode),
        }
    }
}

impl std::fmt::Debug for Experiment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Experiment").field("name", &self.name).finish_non_exhaustive()
    }
}

/// Estimators, test beds and experiments by name, and where stored references are found.
#[derive(Clone)]
pub struct Registry {
    pub(crate) estimators: Vec<&'static EstimatorEntry>,
    pub(crate) test_beds: Vec<&'static TestBedEntry>,
    experiments: Vec<Experiment>,
    /// Names of experiments that run only when named (not in the default suite).
    on_demand: Vec<String>,
    references: Arc<dyn ReferenceSource>,
    /// The references the catalogs ship, asked after `references`.
    built_in: Vec<&'static dyn ReferenceSource>,
    /// `references`, then `built_in`.
    chain: Chain,
    /// Test beds as other renderers' scenes (`mcbench export`).
    exports: Vec<&'static SceneExport>,
    /// Exemptions of controls added by the crate that registers them ([`crate::plugins`]).
    pub(crate) exemptions: Vec<(&'static str, Exemption)>,
    /// Samplers added by the crate that registers them ([`crate::plugins`]).
    pub(crate) samplers: Vec<&'static SamplerEntry>,
    /// The estimators and test beds before a selection narrowed them ([`crate::selection`]).
    pub(crate) unselected: Option<Arc<Selected>>,
}

/// The estimators and test beds of a registry before a selection.
pub(crate) type Selected = (Vec<&'static EstimatorEntry>, Vec<&'static TestBedEntry>);

impl Default for Registry {
    fn default() -> Self {
        Registry {
            estimators: Vec::new(),
            test_beds: Vec::new(),
            experiments: Vec::new(),
            on_demand: Vec::new(),
            references: Arc::new(ReferenceDir::new(DEFAULT_REFERENCES)),
            built_in: Vec::new(),
            exports: Vec::new(),
            chain: Chain(vec![Arc::new(ReferenceDir::new(DEFAULT_REFERENCES))]),
            exemptions: Vec::new(),
            samplers: Vec::new(),
            unselected: None,
        }
    }
}

/// Where stored references are looked up unless told otherwise (`--references`, `--results`):
/// `results/references` below the working directory.
pub const DEFAULT_REFERENCES: &str = "results/references";

impl std::fmt::Debug for Registry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Registry")
            .field("estimators", &self.estimators.iter().map(|e| e.id).collect::<Vec<_>>())
            .field("test_beds", &self.test_beds.iter().map(|t| t.id).collect::<Vec<_>>())
            .field("experiments", &self.experiments.iter().map(|e| e.name.as_str()).collect::<Vec<_>>())
            .field("references", &self.references.location())
            .finish()
    }
}

impl Registry {
    /// Nothing registered.
    pub fn empty() -> Self {
        Registry::default()
    }

    /// The harness's own experiments and no plug-in: `unbiasedness`, which runs over whatever
    /// is registered, in the default suite, and `calibration` on demand. Add estimators and test
    /// beds with [`Registry::with_catalog`], [`Registry::with_estimator`] and
    /// [`Registry::with_test_bed`].
    pub fn new() -> Self {
        Registry::default()
            .with_experiment(crate::unbiasedness::experiment())
            .with_experiment_on_demand(crate::calibration::experiment())
    }

    /// Adds every estimator and test bed of `catalog`, in its order.
    pub fn with_catalog(mut self, catalog: Catalog) -> Self {
        self.estimators.extend(catalog.estimators);
        self.test_beds.extend(catalog.testbeds);
        self.built_in.extend(catalog.references);
        self.exports.extend(catalog.exports);
        self.rechain()
    }

    fn rechain(mut self) -> Self {
        let built_in = self.built_in.iter().map(|s| Arc::new(BuiltIn(*s)) as Arc<dyn ReferenceSource>);
        self.chain = Chain(std::iter::once(self.references.clone()).chain(built_in).collect());
        self
    }

    /// The same without any named experiment (to register them in another order).
    pub fn without_experiments(mut self) -> Self {
        self.experiments.clear();
        self.on_demand.clear();
        self
    }

    /// Looks stored references up in `source` (for example a [`ReferenceDir`]) first, then in
    /// those the catalogs ship ([`Catalog::with_references`]).
    pub fn with_references(mut self, source: impl ReferenceSource + 'static) -> Self {
        self.references = Arc::new(source);
        self.rechain()
    }

    /// Where test beds find stored references: the source of [`Registry::with_references`],
    /// then the catalogs' own.
    pub fn references(&self) -> &dyn ReferenceSource {
        &self.chain
    }

    /// The display names of plots' legends and titles: the registered entries' display names
    /// (their labels and ids where they have none).
    pub fn display_names(&self) -> DisplayNames<'_> {
        DisplayNames::new(&self.estimators, &self.test_beds)
    }

    /// The test beds the catalogs can write as other renderers' scenes (`mcbench export`).
    pub fn exports(&self) -> &[&'static SceneExport] {
        &self.exports
    }

    /// Adds an estimator.
    pub fn with_estimator(mut self, entry: &'static EstimatorEntry) -> Self {
        self.estimators.push(entry);
        self
    }

    /// Adds a test bed.
    pub fn with_test_bed(mut self, entry: &'static TestBedEntry) -> Self {
        self.test_beds.push(entry);
        self
    }

    /// Adds a named experiment.
    pub fn with_experiment(mut self, experiment: Experiment) -> Self {
        self.experiments.push(experiment);
        self
    }

    /// Adds a named experiment that runs only when named (`mcbench run NAME`), not in the default
    /// suite: for long measurements such as `calibration`.
    pub fn with_experiment_on_demand(mut self, experiment: Experiment) -> Self {
        self.on_demand.push(experiment.name.clone());
        self.experiments.push(experiment);
        self
    }

    /// Checks that no id or name is registered twice (the CLI refuses to start otherwise).
    pub fn check(&self) -> std::result::Result<(), ConfigError> {
        fn dup<'a>(kind: &'static str, names: impl Iterator<Item = &'a str>) -> std::result::Result<(), ConfigError> {
            let mut seen: Vec<&str> = Vec::new();
            for n in names {
                if seen.contains(&n) {
                    return Err(ConfigError::invalid(kind, n, "registered twice"));
                }
                seen.push(n);
            }
            Ok(())
        }
        dup("estimator", self.estimators.iter().map(|e| e.id))?;
        dup("test bed", self.test_beds.iter().map(|t| t.id))?;
        dup("experiment", self.experiments.iter().map(|e| e.name.as_str()))
    }

    /// Every estimator, in registration order.
    pub fn estimators(&self) -> &[&'static EstimatorEntry] {
        &self.estimators
    }

    /// The same registry with the estimators and test beds it had before `--estimators` /
    /// `--testbeds` narrowed it (itself when nothing did): what derived experiments whose items
    /// depend on each other (the `calibration` families) are derived from before being narrowed.
    pub fn unselected(&self) -> Registry {
        let mut out = self.clone();
        if let Some(full) = self.unselected.as_deref() {
            out.estimators = full.0.clone();
            out.test_beds = full.1.clone();
            out.unselected = None;
        }
        out
    }

    /// Every test bed, in registration order.
    pub fn test_beds(&self) -> &[&'static TestBedEntry] {
        &self.test_beds
    }

    /// Every named experiment, in registration order.
    pub fn experiments(&self) -> &[Experiment] {
        &self.experiments
    }

    /// The experiments of the default suite, in its order: every named experiment but those
    /// registered on demand.
    pub fn suite(&self) -> impl Iterator<Item = &Experiment> {
        self.experiments.iter().filter(|e| !self.on_demand.contains(&e.name))
    }

    /// An estimator by id; unknown ids list the valid ones.
    pub fn estimator(&self, id: &str) -> std::result::Result<&'static EstimatorEntry, ConfigError> {
        self.estimators
            .iter()
            .copied()
            .find(|e| e.id == id)
            .ok_or_else(|| ConfigError::unknown("estimator", id, self.estimators.iter().map(|e| e.id)))
    }

    /// A test bed by id; unknown ids list the valid ones.
    pub fn test_bed(&self, id: &str) -> std::result::Result<&'static TestBedEntry, ConfigError> {
        self.test_beds
            .iter()
            .copied()
            .find(|e| e.id == id)
            .ok_or_else(|| ConfigError::unknown("test bed", id, self.test_beds.iter().map(|e| e.id)))
    }

    /// A named experiment; unknown names list the valid ones.
    pub fn experiment(&self, name: &str) -> std::result::Result<&Experiment, ConfigError> {
        self.experiments
            .iter()
            .find(|e| e.name == name)
            .ok_or_else(|| ConfigError::unknown("experiment", name, self.experiments.iter().map(|e| e.name.as_str())))
    }
}

/// A `'static` source as an owned one (for the chain).
struct BuiltIn(&'static dyn ReferenceSource);

impl ReferenceSource for BuiltIn {
    fn stored(&self, key: &ReferenceKey) -> std::result::Result<Option<StoredReference>, ConfigError> {
        self.0.stored(key)
    }
    fn location(&self) -> String {
        self.0.location()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups_name_the_valid_ids_and_duplicates_are_found() {
        let r = Registry::new().with_catalog(mcbench_papers::catalog());
        assert!(r.estimator("is1_cv2").is_ok() && r.test_bed("gradient-box").is_ok());
        let e = r.estimator("nope").err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("is0_cv0"), "{e}");
        assert!(r.check().is_ok());
        let twice = r.clone().with_estimator(mcbench_papers::builtins::ESTIMATORS[0]);
        assert!(twice.check().expect_err("duplicate").to_string().contains("registered twice"));
        assert!(Registry::empty().estimators().is_empty());
    }
}

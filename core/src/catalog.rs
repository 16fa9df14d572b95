//! A set of plug-ins a crate hands over: estimators and test beds, as registry entries.
//!
//! A crate of estimators exposes one function returning its [`Catalog`]; the harness adds it to
//! its registry (`Registry::empty().with_catalog(catalog)`), so the crate needs no dependency on
//! the harness:
//!
//! ```
//! use mcbench_core::{Catalog, EstimatorEntry, TestBedEntry};
//!
//! static ESTIMATORS: &[&EstimatorEntry] = &[];
//! static TESTBEDS: &[&TestBedEntry] = &[];
//!
//! pub fn catalog() -> Catalog {
//!     Catalog::new(ESTIMATORS, TESTBEDS)
//! }
//! assert!(catalog().estimator("none").is_err());
//! ```

use crate::entry::{EstimatorEntry, TestBedEntry};
use crate::error::ConfigError;
use crate::export::SceneExport;
use crate::references::ReferenceSource;

/// Estimators and test beds, in the order they are listed, and the stored references the crate
/// ships for its test beds.
#[derive(Clone, Default)]
pub struct Catalog {
    /// The estimators.
    pub estimators: Vec<&'static EstimatorEntry>,
    /// The test beds.
    pub testbeds: Vec<&'static TestBedEntry>,
    /// Stored references built into the crate, looked up after the folder a run names
    /// ([`crate::references::Chain`]).
    pub references: Vec<&'static dyn ReferenceSource>,
    /// Test beds written as other renderers' scenes (`mcbench export`).
    pub exports: Vec<&'static SceneExport>,
}

impl Catalog {
    /// The estimators and test beds of two lists.
    pub fn new(estimators: &[&'static EstimatorEntry], testbeds: &[&'static TestBedEntry]) -> Self {
        Catalog {
            estimators: estimators.to_vec(),
            testbeds: testbeds.to_vec(),
            references: Vec::new(),
            exports: Vec::new(),
        }
    }

    /// The same with `source`, the stored references the crate ships (for example compiled in
    /// with `include_str!`), looked up after the folder a run names.
    pub fn with_references(mut self, source: &'static dyn ReferenceSource) -> Self {
        self.references.push(source);
        self
    }

    /// The same with `exports`, test beds written as other renderers' scenes.
    pub fn with_exports(mut self, exports: &[&'static SceneExport]) -> Self {
        self.exports.extend_from_slice(exports);
        self
    }

    /// Looks an estimator up by id.
    pub fn estimator(&self, id: &str) -> Result<&'static EstimatorEntry, ConfigError> {
        self.estimators
            .iter()
            .copied()
            .find(|e| e.id == id)
            .ok_or_else(|| ConfigError::unknown("estimator", id, self.estimators.iter().map(|e| e.id)))
    }

    /// Looks a test bed up by id.
    pub fn testbed(&self, id: &str) -> Result<&'static TestBedEntry, ConfigError> {
        self.testbeds
            .iter()
            .copied()
            .find(|e| e.id == id)
            .ok_or_else(|| ConfigError::unknown("test bed", id, self.testbeds.iter().map(|e| e.id)))
    }
}

impl std::fmt::Debug for Catalog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Catalog")
            .field("estimators", &self.estimators.iter().map(|e| e.id).collect::<Vec<_>>())
            .field("testbeds", &self.testbeds.iter().map(|t| t.id).collect::<Vec<_>>())
            .finish()
    }
}

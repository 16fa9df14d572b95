//! Stored references as files: the folder the harness reads them from and writes them to
//! (`<results>/references`, or `--references DIR`). A reference is found by its key
//! ([`mcbench_core::references::ReferenceKey`]: test bed, variant, and the parameters its values
//! depend on), never through a path compiled into the binary: a binary copied elsewhere is pointed
//! at the folder with `--references` (or `--results`), and a reference made with parameters
//! (`mcbench reference --param k=v`) is found by any run that uses them.

use crate::error::{HarnessError, Result};
use mcbench_core::entry::TestBedEntry;
use mcbench_core::error::ConfigError;
use mcbench_core::params::Params;
use mcbench_core::references::{NoReferences, ReferenceKey, ReferenceSource, StoredReference};
use std::path::{Path, PathBuf};

/// A folder of stored references, one JSON file per key ([`ReferenceKey::file_name`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceDir {
    dir: PathBuf,
}

impl ReferenceDir {
    /// The folder `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        ReferenceDir { dir: dir.into() }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Writes `stored` under `key`'s file name ([`ReferenceKey::file_name`]), atomically; returns
    /// the path.
    pub fn write(&self, key: &ReferenceKey, stored: &StoredReference) -> Result<PathBuf> {
        let path = self.dir.join(key.file_name());
        let text = serde_json::to_string(stored).map_err(|e| HarnessError::write(&path, e))?;
        crate::output::write_atomic(&path, text.as_bytes())?;
        Ok(path)
    }
}

impl ReferenceSource for ReferenceDir {
    fn stored(&self, key: &ReferenceKey) -> std::result::Result<Option<StoredReference>, ConfigError> {
        let path = self.dir.join(key.file_name());
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(ConfigError::invalid("reference", path.display(), format!("cannot be read ({e})"))),
        };
        let stored: StoredReference = serde_json::from_str(&text).map_err(|e| {
            ConfigError::invalid(
                "reference",
                path.display(),
                format!("malformed ({e}); make it again with `{}`", key.command()),
            )
        })?;
        if !stored.matches(key) {
            return Err(ConfigError::invalid(
                "reference",
                path.display(),
                format!(
                    "holds the reference of {}/{} {}, not of {}",
                    stored.testbed,
                    stored.variant,
                    serde_json::Value::Object(stored.params.clone()),
                    key.describe()
                ),
            ));
        }
        Ok(Some(stored))
    }

    fn location(&self) -> String {
        self.dir.display().to_string()
    }
}

/// What `mcbench reference` made.
pub struct Made {
    /// The file written.
    pub path: PathBuf,
    /// The reference.
    pub stored: StoredReference,
}

/// `mcbench reference`: computes the reference of `variant` of a test bed with `params` (and, for
/// stored Monte Carlo references, `samples` per value) and writes it into `folder` under its key.
/// Exact variants compute theirs when built (a quadrature worth storing, such as Perlin single
/// scattering, is then found instead of recomputed); the others run the test bed's reference hook.
pub fn make(
    entry: &TestBedEntry,
    variant: &str,
    params: &Params,
    samples: Option<u64>,
    folder: &ReferenceDir,
    wait: bool,
) -> Result<Made> {
    entry.check_variant(variant)?;
    crate::store::folder::check_output_dir("--references", folder.path())?;
    (entry.params.resolve)(entry.id, params)?;
    let built = (entry.build)(variant, params, &NoReferences);
    let (key, stored) = match (built, entry.compute_reference) {
        (Ok(bed), _) if bed.reference().is_exact() => {
            let key = match bed.reference_key() {
                Some(k) => k,
                None => {
                    let resolved = (entry.params.resolve)(entry.id, params)?;
                    let map = resolved.as_object().cloned().unwrap_or_default();
                    ReferenceKey {
                        testbed: entry.id.into(),
                        variant: variant.into(),
                        params: map,
                        default: params.0.is_empty(),
                    }
                }
            };
            let reference = bed.reference().clone();
            let stored = StoredReference {
                testbed: key.testbed.clone(),
                variant: key.variant.clone(),
                params: key.params.clone(),
                command: key.command(),
                resolution: bed.resolution(),
                reference,
            };
            (key, stored)
        }
        (_, Some(compute)) => {
            let threads = std::thread::available_parallelism().map(|t| t.get()).unwrap_or(1);
            compute(variant, params, samples, threads)?
        }
        (Err(e), None) => return Err(e.into()),
        (Ok(_), None) => {
            return Err(ConfigError::invalid(
                "testbed",
                entry.id,
                "has a stored reference but no way to compute one (its entry has no compute_reference)",
            )
            .into())
        }
    };
    let _lock = crate::store::folder::FolderLock::acquire(folder.path(), wait, &[])?;
    let path = folder.write(&key, &stored)?;
    Ok(Made { path, stored })
}

//! `mcbench export`: a built-in test bed as another renderer's scene (book: exported-beds.md).
//!
//! The output folder receives the exporter's files (the scene, its textures, `bed.md`) and the
//! bed's reference as `reference.npy` (float64, shape (H, W, 3), row 0 at the top; pixel
//! (row, column) is integral `row * width + column`), plus `reference_var.npy`, the per-pixel
//! variance of the reference's mean, for stored Monte Carlo references. Every input is checked
//! before anything is written; each file is written atomically.

use crate::error::{HarnessError, Result};
use crate::registry::Registry;
use mcbench_core::export::SceneFile;
use mcbench_core::params::Params;
use mcbench_core::testbed::TestBed;
use std::path::{Path, PathBuf};

/// What to export.
#[derive(Clone, Debug)]
pub struct ExportRequest<'a> {
    /// Test bed id.
    pub testbed: &'a str,
    /// Variant.
    pub variant: &'a str,
    /// The test bed's parameters.
    pub params: &'a Params,
    /// Format name (`mitsuba`).
    pub format: &'a str,
    /// Output folder.
    pub out: &'a Path,
}

/// The files a request writes, in order (the exporter's, then the reference's): checked, nothing
/// written yet.
pub fn files(registry: &Registry, req: &ExportRequest) -> Result<Vec<SceneFile>> {
    let entry = registry.test_bed(req.testbed)?;
    entry.check_variant(req.variant)?;
    let exporter = mcbench_core::export::find(registry.exports(), req.testbed, req.variant, req.format)?;
    let bed = (entry.build)(req.variant, req.params, registry.references())?;
    let mut out = (exporter.write)(req.variant, req.params)?;
    out.extend(reference_files(bed.as_ref()));
    Ok(out)
}

/// `reference.npy` and, for a stored reference, `reference_var.npy`.
pub fn reference_files(bed: &dyn TestBed) -> Vec<SceneFile> {
    let (w, h) = bed.resolution();
    let r = bed.reference();
    let values: Vec<f64> = r.value.iter().flat_map(|v| v.0).collect();
    let mut out = vec![SceneFile::new("reference.npy", crate::ingest::npy::encode_f64(h, w, 3, &values))];
    if !r.is_exact() {
        let var: Vec<f64> = r.std_err.iter().flat_map(|s| s.0.map(|e| e * e)).collect();
        out.push(SceneFile::new("reference_var.npy", crate::ingest::npy::encode_f64(h, w, 3, &var)));
    }
    out
}

/// Checks the request and the output folder, then writes every file atomically into `req.out`
/// (created when missing); returns the paths written.
pub fn export(registry: &Registry, req: &ExportRequest) -> Result<Vec<PathBuf>> {
    crate::store::folder::check_output_dir("--out", req.out)?;
    let files = files(registry, req)?;
    for f in &files {
        let path = req.out.join(&f.name);
        if std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir()) {
            return Err(HarnessError::bad_output("--out", &path, "is a folder where a file of the scene goes"));
        }
    }
    let mut written = Vec::with_capacity(files.len());
    for f in &files {
        let path = req.out.join(&f.name);
        crate::output::write_atomic(&path, &f.bytes)?;
        written.push(path);
    }
    Ok(written)
}

//! Reading one estimator's repetitions at one budget into a cell: one image per repetition (its
//! shape the reference's) or one CSV of scalars (one column per integral), and the optional CSV of
//! seconds. Every value must be finite; a refusal names the file and the manifest's field.

use super::accumulate::CellBuilder;
use super::manifest::{rep_name, resolve, BudgetFiles};
use crate::error::{HarnessError, Result};
use crate::run::cell::{CellKey, CellResult};
use mcbench_core::math::Rgb;
use mcbench_core::testbed::TestBed;
use std::path::Path;

/// What a cell is read from: the manifest's folder and file, the field prefix of its budget
/// (`estimators[i].budgets[j]`), and the bed it is compared with.
pub struct Source<'a> {
    /// The manifest file (named in refusals of its fields).
    pub manifest: &'a Path,
    /// The manifest's folder.
    pub dir: &'a Path,
    /// `estimators[i].budgets[j]`.
    pub field: String,
    /// The reference's bed.
    pub bed: &'a dyn TestBed,
}

impl Source<'_> {
    fn path(&self, field: &str, rel: &str) -> Result<std::path::PathBuf> {
        resolve(self.dir, rel)
            .map_err(|why| HarnessError::bad_file(self.manifest, format!("field `{}.{field}`: {why}", self.field)))
    }
    fn bad(&self, path: &Path, field: &str, why: impl std::fmt::Display) -> HarnessError {
        HarnessError::bad_file(path, format!("field `{}.{field}`: {why}", self.field))
    }
}

/// The cell of one budget's repetitions under `key`.
pub fn cell(src: &Source<'_>, b: &BudgetFiles, key: CellKey) -> Result<CellResult> {
    let integrals = src.bed.integrals();
    let seconds = match &b.seconds {
        Some(rel) => {
            let path = src.path("seconds", rel)?;
            let text = std::fs::read_to_string(&path).map_err(|e| src.bad(&path, "seconds", e))?;
            let t = super::scalars::read(&text, b.reps).map_err(|e| src.bad(&path, "seconds", e))?;
            if !t.values.first().is_some_and(Vec::is_empty) || t.seconds.is_none() {
                return Err(src.bad(&path, "seconds", "the columns must be `rep,seconds`"));
            }
            t.seconds
        }
        None => None,
    };
    let mut builder = CellBuilder::new(key, src.bed.reference(), b.samples);
    if b.files.contains("{rep") {
        let (w, h) = src.bed.resolution();
        for rep in 0..b.reps {
            let rel = rep_name(&b.files, rep)
                .ok_or_else(|| src.bad(src.manifest, "files", "a `{rep}` placeholder is `{rep}` or `{rep:0N}`"))?;
            let path = src.path("files", &rel)?;
            let img = super::image::read(&path).map_err(|e| src.bad(&path, "files", e))?;
            if (img.width, img.height) != (w, h) {
                let why = format!("image is {}x{} (width x height), the reference is {w}x{h}", img.width, img.height);
                return Err(src.bad(&path, "files", why));
            }
            if let Some((row, col, c)) = img.first_non_finite() {
                return Err(src.bad(
                    &path,
                    "files",
                    format!("pixel (row {row}, column {col}) channel {c} is not finite"),
                ));
            }
            builder.push(&img.pixels, seconds.as_ref().map(|s| s[rep]));
        }
        if let Some(rel) = rep_name(&b.files, b.reps) {
            if src.dir.join(&rel).exists() {
                let path = src.dir.join(&rel);
                return Err(src.bad(
                    &path,
                    "reps",
                    format!("repetition {} exists, the manifest says reps = {}", b.reps, b.reps),
                ));
            }
        }
    } else {
        let path = src.path("files", &b.files)?;
        let text = std::fs::read_to_string(&path).map_err(|e| src.bad(&path, "files", e))?;
        let t = super::scalars::read(&text, b.reps).map_err(|e| src.bad(&path, "files", e))?;
        if seconds.is_some() && t.seconds.is_some() {
            return Err(src.bad(&path, "seconds", "seconds are given twice (a `seconds` column and a `seconds` file)"));
        }
        let held = t.values.first().map_or(0, Vec::len);
        if held != integrals {
            return Err(src.bad(
                &path,
                "files",
                format!("{held} value columns, the reference has {integrals} integrals"),
            ));
        }
        let seconds = seconds.or(t.seconds);
        for (rep, row) in t.values.iter().enumerate() {
            let values: Vec<Rgb> = row.iter().map(|v| Rgb([*v; 3])).collect();
            builder.push(&values, seconds.as_ref().map(|s| s[rep]));
        }
    }
    Ok(builder.finish())
}

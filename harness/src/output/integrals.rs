//! `integrals.csv` (book: outputs.md): per integral and channel at the largest budget, the reference, the
//! mean and standard error of the estimates and the test bed's geometry. It is most of a results
//! folder's bytes (one row per integral, channel and estimator), so it is written gzip-compressed
//! by default, as `integrals.csv.gz` (`zcat` reads it; pandas' and polars' `read_csv` read it as
//! it is); `--integrals csv` writes the plain `integrals.csv` and `--integrals none` neither.
//! Estimator and test-bed parameters are not repeated per row: `estimator_id` is, and summary.csv
//! holds `params` and `testbed_params` per (testbed, variant, estimator).

use crate::error::{HarnessError, Result};
use crate::store::folder::OutputDir;
use flate2::write::GzEncoder;
use std::io::{Read, Write};
use std::path::Path;

/// The plain file name (book: outputs.md).
pub const CSV: &str = "integrals.csv";
/// The gzip-compressed file name (the default).
pub const GZ: &str = "integrals.csv.gz";

/// How a run writes its per-integral file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum IntegralsFormat {
    /// `integrals.csv.gz`: the CSV, gzip-compressed.
    #[default]
    Gz,
    /// `integrals.csv`: plain CSV.
    Csv,
    /// Neither file.
    None,
}

impl IntegralsFormat {
    /// The file it writes (`None` for none).
    pub fn file_name(self) -> Option<&'static str> {
        match self {
            IntegralsFormat::Gz => Some(GZ),
            IntegralsFormat::Csv => Some(CSV),
            IntegralsFormat::None => None,
        }
    }
}

/// One row of `integrals.csv` (book: outputs.md) with the test bed's geometry columns appended.
#[derive(Clone, Debug, PartialEq)]
pub struct IntegralRow {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// Integral index.
    pub integral: usize,
    /// Pixel column.
    pub px: usize,
    /// Pixel row.
    pub py: usize,
    /// Channel 0..3 (R, G, B).
    pub channel: usize,
    /// Reference value.
    pub reference: f64,
    /// Reference standard error.
    pub reference_se: f64,
    /// Mean estimate over repetitions.
    pub mean: f64,
    /// Standard error of the mean.
    pub std_err: f64,
    /// Geometry (name, value).
    pub geometry: Vec<(&'static str, f64)>,
    /// Registered id of the estimator.
    pub estimator_id: String,
}

/// The contract's columns (book: contract.md), in their order; the geometry columns and `estimator_id` follow.
pub const COLUMNS: [&str; 11] = [
    "testbed",
    "variant",
    "estimator",
    "integral",
    "px",
    "py",
    "channel",
    "reference",
    "reference_se",
    "mean",
    "std_err",
];

/// The order rows are written in: by (test bed, variant) in the order they first appear, then by
/// integral and channel, estimators in their order within each. The rows of one integral sit
/// together, so the estimators' values for a pixel read side by side, and the columns they share
/// (reference, geometry) repeat within the compressor's window: the gzip file is a third smaller
/// than in cell order.
fn integral_major(rows: &[IntegralRow]) -> Vec<&IntegralRow> {
    let mut groups: Vec<(&str, &str)> = Vec::new();
    let mut order = Vec::with_capacity(rows.len());
    for (i, r) in rows.iter().enumerate() {
        let key = (r.testbed.as_str(), r.variant.as_str());
        let g = groups.iter().position(|g| *g == key).unwrap_or_else(|| {
            groups.push(key);
            groups.len() - 1
        });
        order.push((g, r.integral, r.channel, i));
    }
    order.sort_unstable();
    order.into_iter().map(|(_, _, _, i)| &rows[i]).collect()
}

/// The CSV text: the contract's columns, the geometry columns (the union over rows, empty where a
/// row has none), then `estimator_id`; rows by integral and channel, the estimators of one side by
/// side (see `integral_major`).
pub fn csv_bytes(rows: &[IntegralRow]) -> Result<Vec<u8>> {
    let mut geo: Vec<&'static str> = Vec::new();
    for r in rows {
        for (name, _) in &r.geometry {
            if !geo.contains(name) {
                geo.push(name);
            }
        }
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut write = || -> csv::Result<()> {
        let mut header: Vec<&str> = COLUMNS.to_vec();
        header.extend(&geo);
        header.push("estimator_id");
        w.write_record(&header)?;
        for r in integral_major(rows) {
            let mut rec = vec![
                r.testbed.clone(),
                r.variant.clone(),
                r.estimator.clone(),
                r.integral.to_string(),
                r.px.to_string(),
                r.py.to_string(),
                r.channel.to_string(),
                r.reference.to_string(),
                r.reference_se.to_string(),
                r.mean.to_string(),
                r.std_err.to_string(),
            ];
            for g in &geo {
                rec.push(r.geometry.iter().find(|(n, _)| n == g).map(|(_, v)| v.to_string()).unwrap_or_default());
            }
            rec.push(r.estimator_id.clone());
            w.write_record(&rec)?;
        }
        Ok(())
    };
    write().map_err(|e| HarnessError::write(CSV, e))?;
    w.into_inner().map_err(|e| HarnessError::write(CSV, e))
}

/// Writes the per-integral file of a run into its results folder in `format`, and removes the
/// other form an earlier run may have left there (so that no reader takes a stale one).
pub fn write(dir: &OutputDir, rows: &[IntegralRow], format: IntegralsFormat) -> Result<()> {
    for other in [CSV, GZ] {
        if format.file_name() != Some(other) {
            match std::fs::remove_file(dir.join(other)) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(HarnessError::write(dir.join(other), e))
                }
                _ => {}
            }
        }
    }
    let Some(name) = format.file_name() else { return Ok(()) };
    let bytes = csv_bytes(rows)?;
    let bytes = match format {
        IntegralsFormat::Gz => {
            // No file name and no time in the gzip header: equal rows give equal bytes.
            let mut e = GzEncoder::new(Vec::new(), flate2::Compression::best());
            e.write_all(&bytes).and_then(|()| e.finish()).map_err(|e| HarnessError::write(dir.join(name), e))?
        }
        _ => bytes,
    };
    dir.write(name, &bytes).map(|_| ())
}

/// The CSV text of a results folder's per-integral file, plain or gzip-compressed (whichever is
/// there, the plain one first); `None` when the folder has neither.
pub fn read_text(dir: &Path) -> Result<Option<String>> {
    let plain = dir.join(CSV);
    if plain.is_file() {
        return std::fs::read_to_string(&plain).map(Some).map_err(|e| HarnessError::bad_file(&plain, e));
    }
    let gz = dir.join(GZ);
    if !gz.is_file() {
        return Ok(None);
    }
    let bytes = std::fs::read(&gz).map_err(|e| HarnessError::bad_file(&gz, e))?;
    let mut text = String::new();
    flate2::read::GzDecoder::new(&bytes[..]).read_to_string(&mut text).map_err(|e| HarnessError::bad_file(&gz, e))?;
    Ok(Some(text))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(i: usize, geometry: Vec<(&'static str, f64)>) -> IntegralRow {
        IntegralRow {
            testbed: "gradient-plane".into(),
            variant: "default".into(),
            estimator: "is0_cv0".into(),
            integral: i,
            px: i,
            py: 0,
            channel: 0,
            reference: 0.5,
            reference_se: 0.0,
            mean: 0.25 + i as f64,
            std_err: 0.125,
            geometry,
            estimator_id: "is0_cv0".into(),
        }
    }

    #[test]
    fn every_format_reads_back_the_same_text_and_none_writes_nothing() {
        let rows = [row(0, vec![("s", 1.5)]), row(1, vec![("hit_x", 2.0)])];
        let text = String::from_utf8(csv_bytes(&rows).expect("csv")).expect("utf8");
        assert!(text.starts_with("testbed,variant,estimator,integral,px,py,channel,reference,reference_se,mean,std_err,s,hit_x,estimator_id\n"), "{text}");
        assert!(text.contains(",1.5,,is0_cv0\n") && text.contains(",,2,is0_cv0\n"), "{text}");
        for (format, name) in [(IntegralsFormat::Gz, GZ), (IntegralsFormat::Csv, CSV)] {
            let dir = tempfile::tempdir().expect("tempdir");
            write(&OutputDir::new(dir.path()), &rows, format).expect("writes");
            assert!(dir.path().join(name).is_file());
            assert_eq!(read_text(dir.path()).expect("reads").as_deref(), Some(text.as_str()));
        }
        let dir = tempfile::tempdir().expect("tempdir");
        let out = OutputDir::new(dir.path());
        write(&out, &rows, IntegralsFormat::Csv).expect("writes");
        write(&out, &rows, IntegralsFormat::Gz).expect("writes");
        assert!(!dir.path().join(CSV).exists(), "the other form is removed");
        write(&out, &rows, IntegralsFormat::None).expect("writes nothing");
        assert_eq!(read_text(dir.path()).expect("reads"), None);
        assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0);
    }

    #[test]
    fn rows_are_written_integral_major_estimators_in_their_order() {
        let mut rows = Vec::new();
        for (e, variant) in [("b", "v1"), ("a", "v1"), ("b", "v0")] {
            for i in [1, 0] {
                rows.push(IntegralRow { estimator: e.into(), variant: variant.into(), ..row(i, Vec::new()) });
            }
        }
        let text = String::from_utf8(csv_bytes(&rows).expect("csv")).expect("utf8");
        let keys: Vec<String> =
            text.lines().skip(1).map(|l| l.split(',').take(4).collect::<Vec<_>>()[1..].join(" ")).collect();
        assert_eq!(keys, ["v1 b 0", "v1 a 0", "v1 b 1", "v1 a 1", "v0 b 0", "v0 b 1"]);
    }

    #[test]
    fn equal_rows_give_equal_gzip_bytes() {
        let rows = [row(0, Vec::new())];
        let (a, b) = (tempfile::tempdir().expect("tempdir"), tempfile::tempdir().expect("tempdir"));
        for d in [&a, &b] {
            write(&OutputDir::new(d.path()), &rows, IntegralsFormat::Gz).expect("writes");
        }
        assert_eq!(std::fs::read(a.path().join(GZ)).expect("a"), std::fs::read(b.path().join(GZ)).expect("b"));
    }
}

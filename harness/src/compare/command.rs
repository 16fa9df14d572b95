//! `mcbench compare A B` and the comparison after `run --baseline NAME`: read both sides, refuse
//! bad input before anything is written, write the files, print the summary.

use super::load::{self, Side};
use super::{write, Comparison, Margins};
use crate::error::{HarnessError, Result};
use std::path::{Path, PathBuf};

/// What `mcbench compare` was given.
#[derive(Clone, Debug)]
pub struct CompareArgs {
    /// A: a results folder or a baseline name.
    pub a: String,
    /// B: a results folder or a baseline name.
    pub b: String,
    /// The results root baselines are looked up in (and the default output is written below).
    pub results: PathBuf,
    /// The output folder (default: [`write::default_out`]).
    pub out: Option<PathBuf>,
    /// The margins of no change.
    pub margins: Margins,
    /// Exit 1 when a row regressed.
    pub fail_on_regression: bool,
    /// `--two-sample EA EB`: estimator EA of A against estimator EB of B.
    pub two_sample: Option<(String, String)>,
}

/// Refuses margins that are not positive finite numbers of a sensible size.
pub fn check_margins(m: Margins) -> Result<()> {
    for (field, v, max) in
        [("--margin", m.ratio, 10.0), ("--slope-margin", m.slope, 10.0), ("--time-margin", m.time, 10.0)]
    {
        if !(v.is_finite() && v > 0.0 && v <= max) {
            let e = mcbench_core::error::ConfigError::invalid(
                field,
                v.to_string(),
                format!("must be above 0 and at most {max}"),
            );
            return Err(e.into());
        }
    }
    Ok(())
}

/// `mcbench compare`.
pub fn compare_command(args: &CompareArgs) -> Result<()> {
    check_margins(args.margins)?;
    let (la, da) = load::resolve("A", &args.a, &args.results)?;
    let (lb, db) = load::resolve("B", &args.b, &args.results)?;
    let a = load::read_side(&la, &da)?;
    let b = load::read_side(&lb, &db)?;
    let out = args.out.clone().unwrap_or_else(|| write::default_out(&args.results, &la, &lb));
    let pair = args.two_sample.as_ref().map(|(x, y)| (x.as_str(), y.as_str()));
    let c = finish_with(&a, &b, &out, args.margins, pair)?;
    let regressed = c.changes.iter().filter(|r| r.verdict == super::change::ChangeVerdict::Regressed).count();
    if args.fail_on_regression && regressed > 0 {
        return Err(HarnessError::Failed(format!("{regressed} rows regressed (--fail-on-regression)")));
    }
    Ok(())
}

/// Compares, writes the files into `out` and prints the summary.
pub fn finish(a: &Side, b: &Side, out: &Path, margins: Margins) -> Result<Comparison> {
    finish_with(a, b, out, margins, None)
}

/// [`finish`], with the two-sample test of an estimator of A against one of B when `two_sample`
/// names them (computed, and refused on bad input, before anything is written).
pub fn finish_with(
    a: &Side,
    b: &Side,
    out: &Path,
    margins: Margins,
    two_sample: Option<(&str, &str)>,
) -> Result<Comparison> {
    write::check_out(out)?;
    let mut c = super::compare(a, b, margins)?;
    if let Some((x, y)) = two_sample {
        c.two_sample = Some(super::two_sample::two_sample(a, b, x, y)?);
    }
    write::write_files(out, &c)?;
    print!("{}", write::summary(&c));
    if let Some(t) = &c.two_sample {
        print!("{}", super::two_sample_html::console(t));
    }
    println!("comparison: {}", out.join(write::FILES[2]).display());
    Ok(c)
}

/// Before a run with `--baseline NAME`: the baseline read (and the output folder checked), so that
/// a missing or malformed baseline is refused (exit 2) before the run writes anything.
pub fn check_baseline(results: &Path, name: &str) -> Result<Side> {
    super::baseline::check_name("--baseline", name)?;
    let dir = super::baseline::folder(results, name);
    if !dir.is_dir() {
        let e = mcbench_core::error::ConfigError::invalid("--baseline", name, format!("no baseline {}", dir.display()));
        return Err(e.into());
    }
    write::check_out(&write::default_out(results, name, "latest"))?;
    load::read_side(name, &dir)
}

/// After a run with `--baseline NAME`: the run's experiment folders compared with the baseline
/// `a` ([`check_baseline`]), written to `<results>/compare/<NAME>-vs-latest`.
pub fn against_baseline(results: &Path, a: &Side, dirs: &[PathBuf], margins: Margins) -> Result<Comparison> {
    let mut experiments = std::collections::BTreeMap::new();
    for d in dirs {
        let e = load::read_experiment(d)?;
        experiments.insert(e.report.meta.experiment.clone(), e);
    }
    let b = Side { label: "latest".into(), dir: results.to_path_buf(), experiments };
    finish(a, &b, &write::default_out(results, &a.label, "latest"), margins)
}

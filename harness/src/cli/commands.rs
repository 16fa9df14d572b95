//! The smaller subcommands: `conformance`, `plot` and `reference`, and the parsing of `--param`
//! pairs.

use super::*;

/// `mcbench conformance`: every check on the named estimators (all when none is named); one line
/// per estimator, the failures below it.
pub(super) fn conformance(ids: &[String], registry: &Registry) -> Result<()> {
    let entries: Vec<&mcbench_core::entry::EstimatorEntry> = if ids.is_empty() {
        registry.estimators().to_vec()
    } else {
        ids.iter().map(|id| registry.estimator(id)).collect::<std::result::Result<_, _>>()?
    };
    let suite = crate::conformance::Conformance::new(registry)?;
    let mut failed = 0;
    for e in entries {
        let failures = suite.check(e);
        println!(
            "{}: {}",
            e.id,
            if failures.is_empty() { "conforms".to_string() } else { format!("{} failures", failures.len()) }
        );
        for f in &failures {
            println!("  [{}] {}", f.check, f.detail);
        }
        failed += usize::from(!failures.is_empty());
    }
    if failed > 0 {
        return Err(HarnessError::Failed(format!("{failed} estimators failed the conformance suite")));
    }
    Ok(())
}

/// `mcbench plot`: redraws a finished run's plots into `<plots>/<results folder's name>` (the
/// folder name comes from the command line, never from the files read).
pub(super) fn plot(
    results_dir: &std::path::Path,
    plots: &std::path::Path,
    wait: bool,
    registry: &Registry,
) -> Result<()> {
    let name = std::fs::canonicalize(results_dir)
        .ok()
        .and_then(|p| p.file_name().and_then(|n| n.to_str()).map(String::from))
        .ok_or_else(|| HarnessError::bad_file(results_dir, "not a results folder"))?;
    let _read = crate::store::folder::read_lock(results_dir, wait)?;
    let report = crate::output::read_results(results_dir)?;
    let dir = plots.join(&name);
    crate::store::folder::check_own_dir("--plots", &dir)?;
    let _lock = crate::store::folder::FolderLock::acquire(&dir, wait, &[])?;
    execute::draw(&report, &dir, results_dir, &registry.display_names())?;
    println!("plots, report.md and index.html written to {}", dir.display());
    Ok(())
}

pub(super) fn valid_experiments(registry: &Registry) -> String {
    registry.experiments().iter().map(|e| e.name.as_str()).collect::<Vec<_>>().join(", ")
}

pub(super) fn reference(args: ReferenceArgs, registry: &Registry) -> Result<()> {
    let entry = registry.test_bed(&args.testbed)?;
    let variant = args.variant.clone().unwrap_or_else(|| entry.variants[0].to_string());
    let params = param_pairs(&args.params)?;
    // A folder named with --references is used as named; `<results>/references` must be a folder
    // of its own, not a symbolic link.
    let folder = match args.references {
        Some(dir) => {
            crate::store::folder::check_output_dir("--references", &dir)?;
            crate::store::references::ReferenceDir::new(dir)
        }
        None => {
            let dir = args.results.join("references");
            crate::store::folder::check_own_dir("--results", &dir)?;
            crate::store::references::ReferenceDir::new(dir)
        }
    };
    let t0 = Instant::now();
    let made = crate::store::references::make(entry, &variant, &params, args.samples, &folder, args.wait)?;
    let r = &made.stored.reference;
    let kind = match &r.kind {
        mcbench_core::testbed::ReferenceKind::Exact { method, bound } => {
            format!("exact: {method}; absolute error bound {bound:.3e}")
        }
        mcbench_core::testbed::ReferenceKind::Stored { command, samples } => {
            format!("stored: `{command}`, {samples} samples per value")
        }
    };
    println!(
        "{}/{variant}: {} integrals, {kind}, computed in {:.2} s",
        entry.id,
        r.value.len(),
        t0.elapsed().as_secs_f64()
    );
    println!("written to {}", made.path.display());
    Ok(())
}

/// `mcbench export`'s arguments.
#[derive(Args, Debug)]
pub(super) struct ExportArgs {
    /// Test bed id (`gradient-plane`, `gradient-box`).
    testbed: String,
    /// Variant (the first the format exports when omitted).
    #[arg(long)]
    variant: Option<String>,
    /// A test-bed parameter (repeatable): `--param resolution=4`.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    params: Vec<String>,
    /// The scene format.
    #[arg(long, value_name = "FORMAT", default_value = "mitsuba")]
    format: String,
    /// Output folder (created when missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Where stored references are read (default: `results/references`).
    #[arg(long, value_name = "DIR")]
    references: Option<PathBuf>,
}

/// `mcbench export`: the scene files and the reference image, then one line per file written.
pub(super) fn export(args: &ExportArgs, registry: &Registry) -> Result<()> {
    let registry = &with_references(registry, std::path::Path::new("results"), &args.references);
    let params = param_pairs(&args.params)?;
    let (testbed, format) = (args.testbed.as_str(), args.format.as_str());
    // Without --variant: the first the format exports, else the test bed's first (refused below).
    let exported =
        registry.exports().iter().find(|e| e.testbed == testbed && e.format == format).map(|e| e.variants[0]);
    let variant = args
        .variant
        .as_deref()
        .or(exported)
        .or_else(|| registry.test_bed(testbed).ok().map(|e| e.variants[0]))
        .unwrap_or("");
    let req = crate::export::ExportRequest { testbed, variant, params: &params, format, out: &args.out };
    let written = crate::export::export(registry, &req)?;
    println!("{testbed}/{variant} as {format}: {} files written to {}", written.len(), args.out.display());
    for p in &written {
        println!("  {}", p.display());
    }
    Ok(())
}

/// `--param key=value` pairs as parameters: a number where the value parses as one, else text.
pub(super) fn param_pairs(pairs: &[String]) -> Result<Params> {
    let mut p = Params::new();
    for pair in pairs {
        let (k, v) = pair.split_once('=').ok_or_else(|| {
            mcbench_core::error::ConfigError::invalid("--param", pair, "must be key=value (e.g. --param resolution=8)")
        })?;
        let value = match v.trim().parse::<f64>() {
            Ok(x) => mcbench_core::params::ParamValue::Number(x),
            Err(_) => mcbench_core::params::ParamValue::Text(v.trim().to_string()),
        };
        p.0.insert(k.trim().to_string(), value);
    }
    Ok(p)
}

/// `mcbench ingest`: reads the manifest's files, writes the results and prints each estimator's
/// declared bias beside its test's verdict.
pub(super) fn ingest(
    manifest: &std::path::Path,
    results_root: std::path::PathBuf,
    plots_root: std::path::PathBuf,
    plots: bool,
    wait: bool,
    integrals: IntegralsFormat,
    registry: &Registry,
) -> Result<()> {
    let opts = crate::ingest::IngestOptions { results_root, plots_root, plots, wait, integrals, registry };
    let t0 = std::time::Instant::now();
    let (out, judged) = crate::ingest::ingest(manifest, &opts)?;
    let seconds = t0.elapsed().as_secs_f64();
    let tally = crate::output::console::print_experiment(&out.report, seconds, false, registry);
    let report = plots.then(|| out.plots_dir.join("index.html"));
    crate::output::console::print_totals(&[tally], seconds, crate::run::phases::process_seconds(), report.as_deref());
    for j in &judged {
        let said = match j.expectation {
            crate::ingest::Expectation::AsDeclared => "as declared",
            crate::ingest::Expectation::Contradicted => "CONTRADICTS the declaration",
            crate::ingest::Expectation::Undecided => "undecided",
            crate::ingest::Expectation::NoClaim => "no declaration",
        };
        println!("{}: declared {:?}, unbiasedness test {}: {said}", j.estimator, j.declared, j.verdict);
    }
    println!("results: {}", out.results_dir.display());
    Ok(())
}

//! The `mcbench` command line (book: cli.md): `list`, `run`, `reference`, `merge`, `plot`, `compare`, `ingest`, `export`, and the
//! default quick suite. Every subcommand exits by the one table of [`crate::error`]: bad input is
//! one line on stderr naming the field or file, exit code 2, and nothing written; a results folder
//! that another run holds is exit code 3 (or a wait, with `--wait`).

use crate::config::{Mode, SweepFile};
use crate::error::{HarnessError, Result};
use crate::output::integrals::IntegralsFormat;
use crate::registry::Registry;
use crate::run::execute::{self, ExecOptions};
use crate::run::progress::Progress;
use crate::run::shard::ShardSpec;
use crate::selection::Selection;
use clap::{Args, Parser, Subcommand, ValueEnum};
use mcbench_core::params::Params;
use std::ffi::OsString;
use std::path::PathBuf;
use std::time::Instant;

mod commands;
mod run_command;
use commands::*;
use run_command::*;

/// Convergence-study harness for adaptive Monte Carlo rendering estimators.
#[derive(Parser, Debug)]
#[command(name = "mcbench", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Settings for the default suite (no subcommand).
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// List test beds, estimators (with the test beds each runs on) or experiments.
    List {
        /// What to list (all when omitted).
        what: Option<ListWhat>,
        /// Also each estimator's and test bed's parameters (name, type, default, meaning).
        #[arg(long)]
        params: bool,
    },
    /// Run experiments by name, or a custom sweep from --config.
    Run {
        /// Experiment names (see `mcbench list experiments`).
        experiments: Vec<String>,
        #[command(flatten)]
        args: RunArgs,
    },
    /// Compute and store the reference of a test bed.
    Reference(ReferenceArgs),
    /// Merge the folders of `run --shard i/n` into the files a single run writes.
    Merge {
        /// Shard folders (`<results>/<experiment>/shard-<i>-of-<n>`), or the experiment's results
        /// folder holding them.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Results root (the experiment's folder is written below it).
        #[arg(long, value_name = "DIR", default_value = "results")]
        results: PathBuf,
        /// Plots root.
        #[arg(long, value_name = "DIR", default_value = "plots")]
        plots: PathBuf,
        /// Worker threads (default: all cores).
        #[arg(long, value_name = "T", value_parser = clap::value_parser!(u64).range(1..=1024))]
        threads: Option<u64>,
        /// Skip plots and reports.
        #[arg(long)]
        no_plots: bool,
        /// Wait for another run holding the output folders instead of refusing.
        #[arg(long)]
        wait: bool,
        /// Plain progress lines on stderr even when it is not a terminal.
        #[arg(long)]
        progress: bool,
        /// Where stored references are read (default: `<results>/references`).
        #[arg(long, value_name = "DIR")]
        references: Option<PathBuf>,
        /// The per-integral file: gz (integrals.csv.gz), csv (plain integrals.csv) or none
        #[arg(long, value_name = "FORMAT", value_enum, default_value_t = IntegralsFormat::Gz, hide_possible_values = true)]
        integrals: IntegralsFormat,
        /// Print the merged run's tables, not only its one-line summary.
        #[arg(long, short = 'v')]
        verbose: bool,
    },
    /// Run the conformance suite on estimators (every registered one when none is named): builds,
    /// finite output on the stability cases, determinism, its samplers' chi-square tests, and
    /// unbiasedness at a small budget. Exit 1 when an estimator fails.
    Conformance {
        /// Estimator ids.
        estimators: Vec<String>,
        /// Only these estimators too: ids or `*` globs, comma separated.
        #[arg(long = "estimators", value_name = "LIST")]
        estimator_list: Option<String>,
        /// Only the cases of these test beds: ids or `*` globs, comma separated.
        #[arg(long, value_name = "LIST")]
        testbeds: Option<String>,
        /// Results root (stored references are read from its `references` folder).
        #[arg(long, value_name = "DIR", default_value = "results")]
        results: PathBuf,
        /// Where stored references are read (default: `<results>/references`).
        #[arg(long, value_name = "DIR")]
        references: Option<PathBuf>,
    },
    /// Analyse per-repetition estimates another program wrote, described by a manifest.toml.
    Ingest {
        /// The manifest (book: your-renderer.md).
        manifest: PathBuf,
        /// Results root (the manifest's `name` folder is written below it).
        #[arg(long, value_name = "DIR", default_value = "results")]
        results: PathBuf,
        /// Plots root.
        #[arg(long, value_name = "DIR", default_value = "plots")]
        plots: PathBuf,
        /// Skip plots and reports.
        #[arg(long)]
        no_plots: bool,
        /// Wait for another run holding the output folders instead of refusing.
        #[arg(long)]
        wait: bool,
        /// Where stored references are read (default: `<results>/references`).
        #[arg(long, value_name = "DIR")]
        references: Option<PathBuf>,
        /// The per-integral file: gz (integrals.csv.gz), csv (plain integrals.csv) or none
        #[arg(long, value_name = "FORMAT", value_enum, default_value_t = IntegralsFormat::Gz, hide_possible_values = true)]
        integrals: IntegralsFormat,
    },
    /// Write a test bed as another renderer's scene, with its reference as reference.npy
    /// (book: exported-beds.md).
    Export(ExportArgs),
    /// Compare two runs: per cell, the change from A to B in RMSE, efficiency, FoM and slope with
    /// 95% intervals and verdicts (improved, regressed, no change, inconclusive).
    Compare {
        /// A (the before): a results folder (a run's `--results` root or one experiment's folder)
        /// or a baseline's name.
        a: String,
        /// B (the after): the same.
        b: String,
        /// Results root whose `baselines` folder holds named baselines.
        #[arg(long, value_name = "DIR", default_value = "results")]
        results: PathBuf,
        /// Output folder (default: `<results>/compare/<A>-vs-<B>`).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// No change: RMSE ratios B / A with a 95% interval within [1/(1+M), 1+M] (efficiency and
        /// FoM ratios within the square of that band).
        #[arg(long, value_name = "M", default_value_t = crate::compare::change::DEFAULT_MARGIN, allow_negative_numbers = true)]
        margin: f64,
        /// No change: slope differences with a 95% interval within ±M.
        #[arg(long, value_name = "M", default_value_t = crate::compare::change::DEFAULT_SLOPE_MARGIN, allow_negative_numbers = true)]
        slope_margin: f64,
        /// The rows that divide by CPU time (the efficiencies): the drift of CPU time between
        /// runs allowed on top of their band, as a factor 1 + M.
        #[arg(long, value_name = "M", default_value_t = crate::compare::change::DEFAULT_TIME_MARGIN, allow_negative_numbers = true)]
        time_margin: f64,
        /// Exit 1 when a row regressed.
        #[arg(long)]
        fail_on_regression: bool,
        /// Test estimator EA of A against estimator EB of B without a reference (per shared test
        /// bed, variant and budget: same, differ or inconclusive; written to two_sample.csv).
        #[arg(long, num_args = 2, value_names = ["EA", "EB"])]
        two_sample: Option<Vec<String>>,
    },
    /// Redraw the plots and report of a results folder.
    Plot {
        /// A results folder holding summary.csv and summary.json of a finished run.
        results_dir: PathBuf,
        /// Plots root (the folder `<plots>/<name of results_dir>` is written).
        #[arg(long, default_value = "plots")]
        plots: PathBuf,
        /// Wait for a run writing the folders instead of refusing.
        #[arg(long)]
        wait: bool,
    },
}

#[derive(Args, Debug)]
struct ReferenceArgs {
    /// Test bed id.
    testbed: String,
    /// Variant (the first when omitted).
    #[arg(long)]
    variant: Option<String>,
    /// A test-bed parameter the reference is made for (repeatable): `--param resolution=8`.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    params: Vec<String>,
    /// Paths per integral for stored Monte Carlo references (the test bed's default when omitted).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1u64 << 40))]
    samples: Option<u64>,
    /// Results root (the reference goes to its `references` folder).
    #[arg(long, default_value = "results")]
    results: PathBuf,
    /// The references folder (default: `<results>/references`).
    #[arg(long, value_name = "DIR")]
    references: Option<PathBuf>,
    /// Wait for another run writing the references folder instead of refusing.
    #[arg(long)]
    wait: bool,
}

/// `--repetitions`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum RepetitionsArg {
    Fixed,
    Rounds,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum ListWhat {
    Testbeds,
    Estimators,
    Experiments,
}

#[derive(Args, Debug)]
struct RunArgs {
    /// Small sizes (the default).
    #[arg(long, conflicts_with = "full")]
    quick: bool,
    /// The papers' sizes.
    #[arg(long)]
    full: bool,
    /// Experiment seed.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    seed: Option<u64>,
    /// Repetitions per integral (2 to 1000000).
    #[arg(long, value_name = "R", allow_negative_numbers = true, value_parser = clap::value_parser!(u64).range(2..=crate::config::limits::MAX_REPS as u64))]
    reps: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "T", allow_negative_numbers = true, value_parser = clap::value_parser!(u64).range(1..=crate::config::limits::MAX_THREADS))]
    threads: Option<u64>,
    /// How `unbiasedness` spends its repetitions: fixed (every row its part's) or rounds (doubling
    /// until decided, within the fixed mode's work or the share --rounds-budget sets; calibration
    /// measures that rule; no --shard)
    #[arg(long, value_name = "MODE", value_enum, default_value_t = RepetitionsArg::Fixed, hide_possible_values = true)]
    repetitions: RepetitionsArg,
    /// With --repetitions rounds: the share of the fixed mode's work the rounds may spend
    /// (0 < SHARE <= 1; default 1)
    #[arg(long, value_name = "SHARE", allow_negative_numbers = true)]
    rounds_budget: Option<f64>,
    /// Results root.
    #[arg(long, value_name = "DIR", default_value = "results")]
    results: PathBuf,
    /// Plots root.
    #[arg(long, value_name = "DIR", default_value = "plots")]
    plots: PathBuf,
    /// A TOML or JSON file describing a custom sweep or overriding the named experiments.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Skip plots and reports.
    #[arg(long)]
    no_plots: bool,
    /// Run only shard I of N of each sweep and write its statistics for `mcbench merge`.
    #[arg(long, value_name = "I/N")]
    shard: Option<ShardSpec>,
    /// Wait for another run holding the output folders instead of refusing (exit 3).
    #[arg(long)]
    wait: bool,
    /// Plain progress lines on stderr even when it is not a terminal.
    #[arg(long)]
    progress: bool,
    /// Where stored references are read (default: `<results>/references`).
    #[arg(long, value_name = "DIR")]
    references: Option<PathBuf>,
    /// The per-integral file: gz (integrals.csv.gz), csv (plain integrals.csv) or none
    #[arg(long, value_name = "FORMAT", value_enum, default_value_t = IntegralsFormat::Gz, hide_possible_values = true)]
    integrals: IntegralsFormat,
    /// Only these estimators: ids or `*` globs, comma separated (`--estimators 'my_*,is0_cv0'`).
    #[arg(long, value_name = "LIST")]
    estimators: Option<String>,
    /// Only these test beds: ids or `*` globs, comma separated.
    #[arg(long, value_name = "LIST")]
    testbeds: Option<String>,
    /// Also copy the run's results to the baseline NAME (`<results>/baselines/NAME`).
    #[arg(long, value_name = "NAME")]
    save_baseline: Option<String>,
    /// Compare the run with the baseline NAME after it (`mcbench compare`; written to
    /// `<results>/compare/NAME-vs-latest`).
    #[arg(long, value_name = "NAME")]
    baseline: Option<String>,
    /// Print every experiment's tables (fits, tests, claims, skipped pairs) and the time per
    /// phase, not only its one-line summary.
    #[arg(long, short = 'v')]
    verbose: bool,
}

impl RunArgs {
    fn mode(&self) -> Mode {
        if self.full {
            Mode::Full
        } else {
            Mode::Quick
        }
    }
}

/// The whole command line over `registry`, on the process's arguments; returns the exit code. A
/// binary of your own is one line (see [`crate::registry`] for adding plug-ins):
///
/// ```no_run
/// // The whole body of `main`:
/// std::process::exit(mcbench::cli::main_with(mcbench::Registry::new().with_catalog(mcbench_papers::catalog())));
/// ```
pub fn main_with(registry: Registry) -> i32 {
    main_with_args(registry, std::env::args_os())
}

/// Runs the CLI over `registry` on `args` (the first is the program name) and returns the exit
/// code.
pub fn main_with_args(registry: Registry, args: impl IntoIterator<Item = impl Into<OsString> + Clone>) -> i32 {
    if let Err(e) = registry.check() {
        eprintln!("error: {e}");
        return crate::error::EXIT_BAD_INPUT;
    }
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind::*;
            return match e.kind() {
                DisplayHelp | DisplayVersion | DisplayHelpOnMissingArgumentOrSubcommand => {
                    let _ = e.print();
                    0
                }
                _ => {
                    let text = e.render().to_string();
                    eprintln!("{}", text.lines().next().unwrap_or("error: bad arguments"));
                    2
                }
            };
        }
    };
    match dispatch(cli, &registry) {
        Ok(()) => 0,
        Err(e) => {
            let text = e.to_string();
            eprintln!("error: {}", text.lines().next().unwrap_or("failed"));
            e.exit_code()
        }
    }
}

fn dispatch(cli: Cli, registry: &Registry) -> Result<()> {
    match cli.command {
        None => {
            let names: Vec<String> = registry.suite().map(|e| e.name.clone()).collect();
            if names.is_empty() {
                return Err(mcbench_core::error::ConfigError::invalid(
                    "experiment",
                    "(none)",
                    "this binary registers no named experiment: use `run --config FILE`",
                )
                .into());
            }
            let registry = with_references(registry, &cli.run.results, &cli.run.references);
            let registry = selected(&registry, &selection(&cli.run))?;
            run(&names, &cli.run, &registry)
        }
        Some(Command::Run { experiments, args }) => {
            let registry = with_references(registry, &args.results, &args.references);
            let registry = selected(&registry, &selection(&args))?;
            run(&experiments, &args, &registry)
        }
        Some(Command::List { what, params }) => {
            let what = what.map(|w| match w {
                ListWhat::Testbeds => crate::output::listing::What::TestBeds,
                ListWhat::Estimators => crate::output::listing::What::Estimators,
                ListWhat::Experiments => crate::output::listing::What::Experiments,
            });
            print!("{}", crate::output::listing::list(what, params, registry));
            Ok(())
        }
        Some(Command::Reference(args)) => reference(args, registry),
        Some(Command::Merge {
            dirs,
            results,
            plots,
            threads,
            no_plots,
            wait,
            progress,
            references,
            integrals,
            verbose,
        }) => {
            let registry = &with_references(registry, &results, &references);
            let progress = Progress::new(progress);
            let opts = ExecOptions {
                results_root: results,
                plots_root: plots,
                threads: threads.map(|t| t as usize),
                observer: &progress,
                plots: !no_plots,
                wait,
                registry,
                integrals,
            };
            let t0 = Instant::now();
            let out = crate::run::merge::merge(&dirs, &opts)?;
            let seconds = t0.elapsed().as_secs_f64();
            let tally = crate::output::console::print_experiment(&out.report, seconds, verbose, registry);
            let report = (!no_plots).then(|| out.plots_dir.join("index.html"));
            crate::output::console::print_totals(
                &[tally],
                seconds,
                crate::run::phases::process_seconds(),
                report.as_deref(),
            );
            println!("merged results: {}  plots: {}", out.results_dir.display(), out.plots_dir.display());
            Ok(())
        }
        Some(Command::Ingest { manifest, results, plots, no_plots, wait, references, integrals }) => {
            let registry = &with_references(registry, &results, &references);
            ingest(&manifest, results, plots, !no_plots, wait, integrals, registry)
        }
        Some(Command::Compare {
            a,
            b,
            results,
            out,
            margin,
            slope_margin,
            time_margin,
            fail_on_regression,
            two_sample,
        }) => {
            let margins = crate::compare::Margins { ratio: margin, slope: slope_margin, time: time_margin };
            let two_sample = two_sample.and_then(|v| Some((v.first()?.clone(), v.get(1)?.clone())));
            let args =
                crate::compare::command::CompareArgs { a, b, results, out, margins, fail_on_regression, two_sample };
            crate::compare::command::compare_command(&args)
        }
        Some(Command::Export(args)) => export(&args, registry),
        Some(Command::Plot { results_dir, plots, wait }) => plot(&results_dir, &plots, wait, registry),
        Some(Command::Conformance { estimators, estimator_list, testbeds, results, references }) => {
            let only = Selection::new(estimator_list.as_deref(), testbeds.as_deref()).with_estimator_ids(&estimators);
            let registry = selected(&with_references(registry, &results, &references), &only)?;
            conformance(&[], &registry)
        }
    }
}

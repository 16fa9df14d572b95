//! `mcbench run` and the default suite: the experiments prepared and checked before the first
//! writes, run one by one (or one shard), the console's lines, and the baselines.

use super::*;

pub(super) fn run(names: &[String], args: &RunArgs, registry: &Registry) -> Result<()> {
    let mode = args.mode();
    crate::run::phases::track();
    let file = args.config.as_deref().map(SweepFile::read).transpose()?;
    // A config's claims replace the experiment's: an error in one of them names the file too.
    let file_claims = file.as_ref().is_some_and(|f| f.claims.is_some());
    // Build every plan first: any bad name or value stops here, before a file is written.
    let mut plans = Vec::new();
    if names.is_empty() {
        let file = file.ok_or_else(|| {
            mcbench_core::error::ConfigError::invalid(
                "experiment",
                "(none)",
                format!("name one (valid: {}) or give --config", valid_experiments(registry)),
            )
        })?;
        plans.push((None, narrowed(args, file.apply(None, mode)?)));
    } else {
        for name in names {
            let def = registry.experiment(name)?;
            let sweep = def.sweep(registry, mode);
            let sweep = match &file {
                Some(f) => f.clone().apply(Some(sweep), mode)?,
                None => sweep,
            };
            plans.push((Some(def), narrowed(args, sweep)));
        }
    }
    let share = rounds_share(args)?;
    let (mut prepared, mut times) = (Vec::new(), Vec::new());
    for (def, mut sweep) in plans {
        if let Some(s) = args.seed {
            sweep.seed = s;
        }
        if let Some(r) = args.reps {
            sweep.reps = r as usize;
        }
        if args.repetitions == RepetitionsArg::Rounds {
            in_rounds(&mut sweep, args, share)?;
        }
        // A config that reshapes a named experiment without claims of its own keeps the
        // experiment's, judged `not measured` where the reshaped sweep lacks their cells.
        let plan = if def.is_some() && args.config.is_some() && !file_claims {
            execute::prepare_reshaped(sweep, registry)?
        } else {
            execute::prepare(sweep, registry).map_err(|e| in_config(e, args, file_claims))?
        };
        prepared.push((def, plan));
        times.push(crate::run::phases::take());
    }
    let progress = Progress::new(args.progress);
    let opts = ExecOptions {
        results_root: args.results.clone(),
        plots_root: args.plots.clone(),
        threads: args.threads.map(|t| t as usize),
        observer: &progress,
        plots: !args.no_plots,
        wait: args.wait,
        registry,
        integrals: args.integrals,
    };
    let baseline = baseline_checks(args)?;
    if let (Some(a), Some(name)) = (&baseline, &args.baseline) {
        for (_, plan) in &prepared {
            if let Some(e) = a.experiments.get(&plan.sweep.experiment) {
                let planned: Vec<_> = plan.beds.iter().map(crate::compare::fingerprint::BedPrint::of).collect();
                crate::compare::fingerprint::check_planned(name, e, &planned)?;
            }
        }
    }
    // Everything every experiment of the call will read is checked before the first one writes.
    let mut checked = Vec::new();
    for ((def, plan), t) in prepared.iter().zip(&mut times) {
        checked.push(match args.shard {
            Some(shard) => Checked::Shard(crate::run::shard::preflight(plan, shard, &args.results)?),
            None => Checked::Run(execute::preflight(plan, *def, &opts)?),
        });
        t.add(&crate::run::phases::take());
    }
    let mut written = Vec::new();
    let started = Instant::now();
    let mut tallies = Vec::new();
    for (((def, plan), checked), t) in prepared.iter().zip(checked).zip(&mut times) {
        let t0 = Instant::now();
        if let Checked::Shard(pre) = checked {
            let threads = args.threads.map(|t| t as usize);
            let out = crate::run::shard::run_shard(plan, *def, pre, threads, args.wait, &progress)?;
            progress.finish();
            println!(
                "{} shard {}: {} of {} units ({} resumed) in {:.1} s, written to {}",
                plan.sweep.experiment,
                args.shard.map(|s| s.to_string()).unwrap_or_default(),
                out.owned,
                out.units,
                out.resumed,
                t0.elapsed().as_secs_f64(),
                out.dir.display()
            );
            continue;
        }
        let Checked::Run(pre) = checked else { continue };
        let out = execute::execute_checked(plan, *def, &opts, pre)?;
        progress.finish();
        t.add(&crate::run::phases::take());
        tallies.push(crate::output::console::print_experiment(
            &out.report,
            t0.elapsed().as_secs_f64(),
            args.verbose,
            registry,
        ));
        if args.verbose {
            println!("results: {}  plots: {}", out.results_dir.display(), out.plots_dir.display());
            println!("time: {}", t.line());
        }
        written.push(out.results_dir.clone());
    }
    let wall = started.elapsed().as_secs_f64();
    if args.shard.is_some() {
        println!("\ntotal wall time {wall:.1} s");
        return Ok(());
    }
    if args.verbose {
        let names: Vec<&str> = prepared.iter().map(|(_, p)| p.sweep.experiment.as_str()).collect();
        print!("{}", crate::run::phases::table(&names, &times));
    }
    let cpu: f64 = times.iter().map(|t| t.total().1).sum();
    let report = (!args.no_plots).then(|| args.plots.join("index.html"));
    crate::output::console::print_totals(&tallies, wall, cpu, report.as_deref());
    println!("results: {}", args.results.display());
    if let Some(a) = &baseline {
        crate::compare::command::against_baseline(&args.results, a, &written, Default::default())?;
    }
    if let Some(name) = &args.save_baseline {
        let dir = crate::compare::baseline::save(&args.results, name, &written)?;
        println!("baseline {name} saved: {}", dir.display());
    }
    Ok(())
}

/// `--rounds-budget`: the share of the fixed mode's work the rounds may spend, in `(0, 1]`, only
/// with `--repetitions rounds`; 1 when not given.
fn rounds_share(args: &RunArgs) -> Result<f64> {
    let Some(share) = args.rounds_budget else { return Ok(1.0) };
    let refuse = |reason: &str| Err(mcbench_core::error::ConfigError::invalid("--rounds-budget", share, reason).into());
    if args.repetitions != RepetitionsArg::Rounds {
        return refuse("a budget of the rounds needs --repetitions rounds");
    }
    if !(share > 0.0 && share <= 1.0) {
        return refuse("must lie in (0, 1]: the share of the fixed mode's work the rounds may spend");
    }
    Ok(share)
}

/// `--repetitions rounds`: only `unbiasedness` runs in rounds (`calibration` measures its rule),
/// and not sharded (a shard cannot see which rows the others left open); the first part runs its
/// first round, the fixed-mode repetitions and the budget's `share` kept in the sweep's mode.
fn in_rounds(sweep: &mut crate::config::Sweep, args: &RunArgs, share: f64) -> Result<()> {
    let refuse = |reason: String| -> Result<()> {
        Err(mcbench_core::error::ConfigError::invalid("--repetitions", "rounds", reason).into())
    };
    if args.shard.is_some() {
        return refuse("a sharded run cannot follow the rounds (each round depends on every row's last look): run it without --shard".into());
    }
    sweep.repetitions = crate::config::Repetitions::Rounds { fixed_reps: sweep.reps, budget_share: share };
    if sweep.experiment == crate::calibration::NAME {
        // Calibration measures the rule of the rounds on its own seeds, every row free to take all
        // its looks: there is no shared budget to take a share of.
        if let Some(given) = args.rounds_budget {
            return Err(mcbench_core::error::ConfigError::invalid(
                "--rounds-budget",
                given,
                "calibration measures the rule of the rounds without a shared budget (a budget only stops rows earlier): run it without --rounds-budget",
            )
            .into());
        }
        return Ok(());
    }
    if sweep.experiment != crate::unbiasedness::NAME {
        return refuse(format!(
            "only the {} experiment runs in rounds (and {} measures them), not {}",
            crate::unbiasedness::NAME,
            crate::calibration::NAME,
            sweep.experiment
        ));
    }
    sweep.reps = crate::unbiasedness::rounds::first_round(sweep.reps);
    Ok(())
}

/// The checks of `--baseline` and `--save-baseline` before a run writes anything: the baseline
/// read, the name and folders usable, and no shard (a shard is not a finished run).
pub(super) fn baseline_checks(args: &RunArgs) -> Result<Option<crate::compare::load::Side>> {
    if args.shard.is_some() && (args.baseline.is_some() || args.save_baseline.is_some()) {
        let flag = if args.baseline.is_some() { "--baseline" } else { "--save-baseline" };
        return Err(mcbench_core::error::ConfigError::invalid(
            flag,
            "with --shard",
            "needs a whole run: compare or save after `mcbench merge`",
        )
        .into());
    }
    if let Some(name) = &args.save_baseline {
        crate::compare::baseline::check_save(&args.results, name)?;
    }
    args.baseline.as_deref().map(|n| crate::compare::command::check_baseline(&args.results, n)).transpose()
}

/// `e` naming the `--config` file when it is about a claim and the claims came from that file.
pub(super) fn in_config(e: HarnessError, args: &RunArgs, file_claims: bool) -> HarnessError {
    match (&e, args.config.as_deref()) {
        (HarnessError::Config(mcbench_core::error::ConfigError::InvalidValue { field, .. }), Some(path))
            if file_claims && field.starts_with("claims[") =>
        {
            HarnessError::bad_file(path, e)
        }
        _ => e,
    }
}

/// The `--estimators` and `--testbeds` of a run.
pub(super) fn selection(args: &RunArgs) -> Selection {
    Selection::new(args.estimators.as_deref(), args.testbeds.as_deref())
}

/// `sweep` narrowed to the run's selection, printing a note for each claim left out.
fn narrowed(args: &RunArgs, sweep: crate::config::Sweep) -> crate::config::Sweep {
    let only = selection(args);
    for n in only.claims_left_out(&sweep) {
        eprintln!("{n}");
    }
    only.filter_sweep(sweep)
}

/// `registry` narrowed to `only`, printing a note for each test bed left out.
pub(super) fn selected(registry: &Registry, only: &Selection) -> Result<Registry> {
    if only.is_all() {
        return Ok(registry.clone());
    }
    let (narrowed, notes) = only.apply(registry)?;
    for n in notes {
        eprintln!("{n}");
    }
    Ok(narrowed)
}

/// `registry` reading stored references from `references`, or `<results>/references`.
pub(super) fn with_references(
    registry: &Registry,
    results: &std::path::Path,
    references: &Option<PathBuf>,
) -> Registry {
    let dir = references.clone().unwrap_or_else(|| results.join("references"));
    registry.clone().with_references(crate::store::references::ReferenceDir::new(dir))
}

/// What was checked for one experiment of a `run` before anything was written.
pub(super) enum Checked {
    Run(execute::Preflight),
    Shard(crate::run::shard::ShardPreflight),
}

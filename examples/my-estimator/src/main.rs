//! A researcher's own crate on top of mcbench: an estimator ([`antithetic`]) with its baseline
//! and a biased control ([`uniform`]) and a test bed ([`tilted_patches`]) of its own, on the
//! harness alone (no estimator of the papers' crate), and the whole `mcbench`
//! command line for them: `cargo run -p my-estimator -- run --config my-sweep.toml` runs the sweep
//! (plots, tests and the claims it declares), `conformance antithetic_cosine` runs the checks every
//! estimator goes through, `list estimators --params` shows its parameters.

mod antithetic;
mod tilted_patches;
mod uniform;

fn main() {
    let registry = mcbench::Registry::new()
        .with_estimator(&antithetic::ENTRY)
        .with_estimator(&uniform::UNIFORM)
        .with_estimator(&uniform::CLAMPED)
        .with_test_bed(&tilted_patches::ENTRY);
    std::process::exit(mcbench::cli::main_with(registry));
}

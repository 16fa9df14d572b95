//! `mcbench`: the command-line front of the harness (SPEC §9). Exit codes: 0 success, 2 bad
//! input, 1 internal failure.

fn main() {
    std::process::exit(experiments::cli::main_with_args(std::env::args_os()));
}

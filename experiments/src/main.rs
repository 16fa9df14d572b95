//! `mcbench`: the command-line front of the harness over the paper suite (book: cli.md). Exit codes:
//! the table of `mcbench::error`.

fn main() {
    std::process::exit(mcbench::cli::main_with(experiments::registry()));
}

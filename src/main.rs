//! `grains` command line: parse, run, print the error, exit non-zero on failure.

mod cli;
mod commands;

use clap::Parser;

fn main() {
    let cli = cli::Cli::parse();
    if let Err(e) = commands::dispatch(cli) {
        // Every process of a run over several meets the same error; rank 0 says it.
        if grains::runner::is_root() {
            eprintln!("error: {e:#}");
        }
        std::process::exit(1);
    }
}

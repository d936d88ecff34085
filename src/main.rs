//! `grains` command line: parse, run, print the error, exit non-zero on failure.

mod cli;
mod commands;

use clap::Parser;

fn main() {
    let cli = cli::Cli::parse();
    if let Err(e) = commands::dispatch(cli) {
        // Every process of a run over several meets the same error; rank 0 says it, in one
        // write (mpirun forwards what each write gives, between its own lines), while the
        // others wait a moment before exiting: mpirun ends the whole job at the first process
        // that exits non-zero, before rank 0 has spoken if that one is not rank 0.
        if grains::runner::is_root() {
            let _ = std::io::Write::write_all(&mut std::io::stderr(), format!("error: {e:#}\n").as_bytes());
        } else {
            std::thread::sleep(std::time::Duration::from_secs(1));
        }
        std::process::exit(1);
    }
}

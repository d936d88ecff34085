//! Command-line interface: one subcommand per job.

use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

/// Granular dynamics (DEM) of spherical grains.
#[derive(Debug, Parser)]
#[command(name = "grains", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Floating-point precision of the CPU engine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Precision {
    /// Single precision (what the GPU uses).
    F32,
    /// Double precision (the reference).
    F64,
}

/// Which engine runs the kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Backend {
    /// The CPU engine (Rust twins of the kernels, multithreaded).
    Cpu,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene's stages and report.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Engine.
        #[arg(long, value_enum, default_value = "cpu")]
        backend: Backend,
        /// Precision of the CPU engine.
        #[arg(long, value_enum, default_value = "f64")]
        precision: Precision,
        /// Write summary.json, stats.csv, stages.csv and frames.mcap here.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print one JSON summary object on stdout (and nothing else).
        #[arg(long)]
        json: bool,
        /// Worker threads (default: all cores). Results do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Validate a scene and print what a run would do.
    Check {
        /// Scene file (TOML).
        scene: PathBuf,
    },
}

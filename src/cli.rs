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
    /// The CPU engine (Rust twins of the kernels, multithreaded; f64 by default).
    Cpu,
    /// The GPU engine (WGSL kernels through wgpu, f32); an error without an adapter.
    Gpu,
    /// The GPU when an adapter opens, else the CPU with a notice.
    Auto,
}

/// Backends `grains bench` measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BenchBackend {
    /// The CPU engine.
    Cpu,
    /// The GPU engine.
    Gpu,
    /// Both.
    All,
}

/// Whether the CPU engine renumbers the grains in cell order (`grains bench --reorder`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Reorder {
    /// Every `simulation.reorder_every` rebuilds (the scene's, else the default).
    On,
    /// Never: the grains stay in the order they were poured in.
    Off,
}

/// Parts of `grains bench`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BenchPart {
    /// Particle-steps per second, memory and time per phase on the dense bed.
    Throughput,
    /// Particle-steps per second and each rebuild's cost per grain on loose, agitated beds of
    /// one size, of a few grains ten times the others' diameter among many small, and of
    /// diameters spread over a factor of ten.
    Mixed,
    /// Wall time against error over a ladder of time steps.
    Ladder,
    /// Steps per second of small scenes (280, 1200 and 10^4 grains), dispatch-bound on a GPU.
    Small,
    /// Richefeu et al.'s isotropic compaction to 100 Pa by DEM and by contact dynamics
    /// (`--compaction-grains`): wall times, sweeps and contact updates per second.
    Compaction,
    /// Throughput, mixed sizes and ladder (not the small scenes or the compaction).
    All,
}

/// Formats of `grains export`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ExportFormat {
    /// LAMMPS data file, atom_style sphere (Atoms and Velocities sections).
    LammpsData,
    /// LAMMPS / LIGGGHTS dump custom text snapshot.
    LammpsDump,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene's stages and report.
    Run {
        /// Scene file (TOML); with --resume, the checkpoint's own scene by default.
        #[arg(required_unless_present = "resume")]
        scene: Option<PathBuf>,
        /// Continue the run whose --out directory this is, from its last checkpoint (written
        /// at every stage end and every output.checkpoint_interval inside a stage).
        #[arg(long, value_name = "DIR", conflicts_with = "out")]
        resume: Option<PathBuf>,
        /// Engine.
        #[arg(long, value_enum, default_value = "cpu")]
        backend: Backend,
        /// GPU adapter whose name contains this (case-insensitive); default: the best one.
        #[arg(long)]
        adapter: Option<String>,
        /// Precision: the CPU defaults to f64, the GPU computes in f32 only.
        #[arg(long, value_enum)]
        precision: Option<Precision>,
        /// Write summary.json, stats.csv, stages.csv and frames.mcap here.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print one JSON summary object on stdout (and nothing else).
        #[arg(long)]
        json: bool,
        /// Also write every frame as VTK files for ParaView into OUT/vtk (as
        /// `output.vtk = true` does): open OUT/vtk/grains.pvd.
        #[arg(long, requires = "out")]
        vtk: bool,
        /// Worker threads (default: all cores). Results do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Run even when the stages take more steps than a run can finish in practice.
        #[arg(long)]
        force: bool,
    },
    /// Validate a scene and print what a run would do.
    Check {
        /// Scene file (TOML).
        scene: PathBuf,
    },
    /// List the GPU adapters with their backend and limits.
    Devices,
    /// Write a finished run's last frame as a LAMMPS / LIGGGHTS file (SI units, `units si`):
    /// a data file of atom_style sphere for read_data, or a dump custom text snapshot. Atom id
    /// = grain id + 1, atom type = material index + 1 (the scene's [[material]] order).
    Export {
        /// The run's --out directory.
        run: PathBuf,
        /// File format.
        #[arg(long, value_enum)]
        format: ExportFormat,
        /// The file to write (default: RUN/grains.data or RUN/grains.dump).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Analyse the force transmission of a finished run's last frame (recorded with
    /// `output.contact_forces = true`): force and pressure PDFs with their exponential tails,
    /// bonds by sign, particle stresses, bi-percolation, fabric; writes analysis.json and
    /// pictures into the run's directory.
    Analyze {
        /// The run's --out directory.
        run: PathBuf,
        /// Another finished run (with contact forces) whose force PDF is drawn beside this
        /// run's, over this run's force scale (Richefeu et al.'s Fig. 7: wet and dry at 100 Pa):
        /// force_pdf_beside.png.
        #[arg(long, value_name = "RUN")]
        beside: Option<PathBuf>,
        /// Print the analysis as one JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Measure: throughput on the peers' dense bed (poured once and cached, tiled in x-y for
    /// larger sizes) on each backend and precision, and speed against error on fixed scenes.
    Bench {
        /// A scene whose grains are the bed instead of the pour, e.g. benches/bench_bed_lammps.toml
        /// (LAMMPS' settled bed, read by `[[read]]`).
        #[arg(long, value_name = "SCENE")]
        bed: Option<PathBuf>,
        /// Grain counts of the throughput runs (multiples of 10,000), comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [10_000usize, 100_000, 1_000_000])]
        sizes: Vec<usize>,
        /// Backends: cpu, gpu or all (gpu: every run on the adapter --adapter names, or the best).
        #[arg(long, value_enum, default_value = "cpu")]
        backend: BenchBackend,
        /// GPU adapter whose name contains this (case-insensitive).
        #[arg(long)]
        adapter: Option<String>,
        /// CPU precisions, comma-separated.
        #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Precision::F64, Precision::F32])]
        precision: Vec<Precision>,
        /// CPU thread counts, comma-separated (default: 1 and every core).
        #[arg(long, value_delimiter = ',')]
        threads: Vec<usize>,
        /// CPU runs with the grains renumbered in cell order every few rebuilds (on) and left in
        /// the pour's order (off), comma-separated: `--reorder on,off` compares the two.
        #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Reorder::On])]
        reorder: Vec<Reorder>,
        /// Busy threads computing beside each CPU throughput run, competing for the cores as
        /// other programs would, comma-separated: `--busy 0,1` measures each configuration quiet
        /// and beside one.
        #[arg(long, value_delimiter = ',', default_values_t = [0usize])]
        busy: Vec<usize>,
        /// Particle-steps per timed run (its steps are this over the grain count, at least 20).
        #[arg(long, default_value_t = 5e7)]
        work: f64,
        /// Timed runs per configuration, one after the other; the median is reported.
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..))]
        repeats: u64,
        /// Which parts to run.
        #[arg(long, value_enum, default_value = "all")]
        part: BenchPart,
        /// Grains of the compaction part (its box scaled to hold them as the 8,000-grain sample's
        /// does).
        #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u64).range(1..))]
        compaction_grains: u64,
        /// Folder of the cached bed (default: $XDG_CACHE_HOME/grains or ~/.cache/grains).
        #[arg(long)]
        cache: Option<PathBuf>,
        /// Write bench.json and the speed-against-error plots here.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print one JSON object on stdout (and nothing else).
        #[arg(long)]
        json: bool,
    },
    /// Run a scene over a grid of parameter values (resumable) and gather the table, the
    /// power law h_s = a eta^b and its plot.
    Sweep {
        /// Sweep file (TOML).
        sweep: PathBuf,
        /// Directory of the points (default: next to the sweep file, `<name>-runs`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run point K alone (0-based) and stop; a plain `grains sweep` gathers afterwards.
        #[arg(long, value_name = "K")]
        only: Option<usize>,
        /// Write an sbatch job-array script (one task per point) into the out directory.
        #[arg(long)]
        emit_slurm: bool,
        /// Run nothing: gather the points finished so far.
        #[arg(long, conflicts_with_all = ["only", "emit_slurm"])]
        gather: bool,
        /// Points run at once (default: all cores, one thread each).
        #[arg(long)]
        jobs: Option<usize>,
        /// Worker threads per point.
        #[arg(long)]
        threads: Option<usize>,
        /// CPU precision of the points.
        #[arg(long, value_enum, default_value = "f64")]
        precision: Precision,
        /// Print the gathered table as one JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Fit a law to measured points.
    Fit {
        /// Which law.
        #[command(subcommand)]
        law: FitLaw,
    },
    /// Run a scene on the GPU (f32) and on the CPU (f32 and f64) and report how they differ.
    Compare {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Steps to run.
        #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u64).range(1..))]
        steps: u64,
        /// Comparisons along the way.
        #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..))]
        checkpoints: u64,
        /// GPU adapter whose name contains this.
        #[arg(long)]
        adapter: Option<String>,
        /// Print one JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
}

/// How `grains fit bauer` treats e0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum E0Choice {
    /// Fitted with h_s and eta.
    Free,
    /// Held at this void ratio.
    Fixed(f64),
}

impl std::str::FromStr for E0Choice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "free" => Ok(E0Choice::Free),
            v => match v.parse::<f64>() {
                Ok(x) if x.is_finite() && x > 0.0 => Ok(E0Choice::Fixed(x)),
                _ => Err(format!("`{v}` is neither \"free\" nor a positive void ratio; fix: give e.g. --e0 free or --e0 0.93")),
            },
        }
    }
}

/// Laws `grains fit` knows.
#[derive(Debug, Subcommand)]
pub enum FitLaw {
    /// Bauer's compression law e = e0 exp(-(p/h_s)^eta) by Levenberg-Marquardt.
    Bauer {
        /// CSV with a header (e.g. compression.csv of an oedometer run).
        file: PathBuf,
        /// Column of the pressure (Pa).
        #[arg(long, default_value = "pressure_Pa")]
        p_column: String,
        /// Column of the void ratio.
        #[arg(long, default_value = "void_ratio")]
        e_column: String,
        /// Fit the mean-stress form e = e0 exp(-(3p/h_s)^eta) (the abstract's), with 3p the
        /// measured trace of the stress (column --trace-column), not 3 times the vertical stress.
        #[arg(long)]
        mean_stress: bool,
        /// Column of the stress trace 3p (Pa), for --mean-stress.
        #[arg(long, default_value = "stress_trace_Pa")]
        trace_column: String,
        /// e0: "free" to fit it, or a void ratio to hold it at (e.g. the measured one).
        #[arg(long, default_value = "free")]
        e0: E0Choice,
        /// Also fit with e0 held at a range of values and print how h_s and eta follow it.
        #[arg(long)]
        profile: bool,
        /// Print one JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
}

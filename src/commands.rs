//! The subcommands' bodies.

use crate::cli::{Backend, Cli, Command, Precision};
use anyhow::Context;
use grains::cpu::CpuEngine;
use grains::output::{RunRecorder, Summary};
use grains::real::Real;
use grains::scene::{self, Scene};
use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

/// Runs one command.
pub fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Run { scene, backend, precision, out, json, threads } => {
            let scene = scene::load(&scene)?;
            if !json {
                for w in &scene.warnings {
                    eprintln!("warning: {w}");
                }
            }
            let Backend::Cpu = backend;
            // The whole run happens on a worker of the pool, so that the kernels' parallel
            // loops split work among workers instead of waking them from outside every time.
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build().context("cannot start the worker threads")?;
            pool.install(|| match precision {
                Precision::F32 => run::<f32>(&scene, out.as_deref(), json),
                Precision::F64 => run::<f64>(&scene, out.as_deref(), json),
            })
        }
        Command::Check { scene } => {
            let scene = scene::load(&scene)?;
            print!("{}", grains::output::check_report(&scene));
            Ok(())
        }
    }
}

fn run<T: Real>(scene: &Scene, out: Option<&Path>, json: bool) -> anyhow::Result<()> {
    let mut engine = CpuEngine::<T>::new(scene)?;
    let progress = !json && std::io::stderr().is_terminal();
    let mut rec = RunRecorder::new(out, progress)?;
    let started = Instant::now();
    let result = grains::protocol::run(scene, &mut engine, &mut rec);
    let wall_seconds = started.elapsed().as_secs_f64();
    // Whatever happened, keep what was recorded.
    rec.finish()?;
    let stages = result?;
    let summary = Summary::new(scene, &engine, rayon::current_num_threads(), wall_seconds, stages);
    if let Some(dir) = out {
        let path = dir.join("summary.json");
        std::fs::write(&path, serde_json::to_string_pretty(&summary)?).with_context(|| format!("cannot write {}", path.display()))?;
    }
    if json {
        println!("{}", serde_json::to_string(&summary)?);
    } else {
        print!("{}", summary.human());
    }
    Ok(())
}

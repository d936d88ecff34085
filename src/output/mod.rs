//! What a run writes: `stats.csv` (every statistics read), `stages.csv` (one row per stage),
//! `frames.mcap` (see [`mcap`]), `summary.json` (the `--json` object), and a progress bar
//! on a terminal.

pub mod lammps;
pub mod mcap;
pub mod network;
pub mod plot;
mod summary;
pub mod vtk;

pub use summary::{check_report, Summary, ESTIMATE_PAIRS_PER_GRAIN, PROFILE_POINTS};

use crate::checkpoint::{CheckpointHeader, RunIdentity};
use crate::engine::{Engine, Frame, Stats};
use crate::protocol::{Progress, Recorder, StageResult};
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// The header of `stats.csv` and `stages.csv`, before the per-wall force columns.
const STATS_COLUMNS: &str = "stage,step,time_s,ke_translational_J,ke_rotational_J,elastic_energy_J,gravity_energy_J,external_work_J,contacts,wall_contacts,coordination,clamped,sliding,rolling,max_overlap,unbalanced_force,rebuilds,piston_z_m,piston_pressure_Pa,capillary_energy_J,bridges,liquid_in_bridges_m3,liquid_on_grains_m3";

fn stats_header(s: &Stats) -> String {
    let mut h = STATS_COLUMNS.to_string();
    for w in &s.walls {
        for a in ["x", "y", "z"] {
            h.push_str(&format!(",{}_f{a}_N", w.name));
        }
    }
    if s.solver.is_some() {
        h.push_str(SOLVER_COLUMNS);
    }
    // Scenes with inlets or outlets: the grains in play, and each one's running totals.
    if !s.flow.is_empty() {
        h.push_str(",grains_in_play");
        for f in &s.flow {
            h.push_str(&format!(",{0}_grains,{0}_mass_kg", f.name));
        }
    }
    h
}

/// Contact dynamics' columns of `stats.csv`, after the walls' (see [`crate::engine::SolverStats`]).
const SOLVER_COLUMNS: &str = ",cd_steps,cd_unconverged_steps,cd_max_iterations,cd_mean_iterations,cd_sweep_norm,cd_unbalanced,cd_contact_updates,cd_normal_residual,cd_tangential_residual,cd_quadratic_residual,cd_maximum_residual";

fn stats_row(stage: &str, s: &Stats) -> String {
    let (pz, pp) = s.piston.as_ref().map_or((String::new(), String::new()), |p| (format!("{:e}", p.z), format!("{:e}", p.pressure)));
    let mut row = format!(
        "{stage},{},{:e},{:e},{:e},{:e},{:e},{:e},{},{},{},{},{},{},{:e},{:e},{},{pz},{pp},{:e},{},{:e},{:e}",
        s.step,
        s.time,
        s.ke_translational,
        s.ke_rotational,
        s.elastic_energy,
        s.gravity_energy,
        s.external_work,
        s.contacts,
        s.wall_contacts,
        s.coordination,
        s.clamped,
        s.sliding,
        s.rolling,
        s.max_overlap,
        s.unbalanced_force,
        s.rebuilds,
        s.capillary_energy,
        s.bridges,
        s.liquid_in_bridges,
        s.liquid_on_grains
    );
    for w in &s.walls {
        row.push_str(&format!(",{:e},{:e},{:e}", w.force[0], w.force[1], w.force[2]));
    }
    if let Some(c) = &s.solver {
        let q = &c.residuals;
        row.push_str(&format!(",{},{},{},{:e},{:e},{:e},{},{:e},{:e},{:e},{:e}", c.steps, c.unconverged_steps, c.max_iterations, c.mean_iterations, c.sweep_norm, c.unbalanced, c.contact_updates, q.normal, q.tangential, q.quadratic, q.maximum));
    }
    if !s.flow.is_empty() {
        row.push_str(&format!(",{}", s.grains));
        for f in &s.flow {
            row.push_str(&format!(",{},{:e}", f.grains, f.mass));
        }
    }
    row
}

/// Wall seconds a written row may wait in memory: a long run's `stats.csv` can be followed
/// (`tail -f`) while it runs.
const FLUSH_SECONDS: u64 = 10;

/// A CSV file written row by row, flushed at every stage end and checkpoint and at least every
/// [`FLUSH_SECONDS`].
struct Csv {
    path: PathBuf,
    out: BufWriter<File>,
    header_written: bool,
    flushed: std::time::Instant,
}

impl Csv {
    fn create(path: PathBuf) -> anyhow::Result<Self> {
        let out = BufWriter::new(File::create(&path).with_context(|| format!("cannot create {}", path.display()))?);
        Ok(Csv { path, out, header_written: false, flushed: std::time::Instant::now() })
    }
    /// Opens an existing CSV to add rows after a resume.
    fn append(path: PathBuf) -> anyhow::Result<Self> {
        let header_written = path.exists();
        let file = std::fs::OpenOptions::new().create(true).append(true).open(&path).with_context(|| format!("cannot open {}", path.display()))?;
        Ok(Csv { path, out: BufWriter::new(file), header_written, flushed: std::time::Instant::now() })
    }
    fn row(&mut self, stage: &str, s: &Stats) -> anyhow::Result<()> {
        if !self.header_written {
            writeln!(self.out, "{}", stats_header(s))?;
            self.header_written = true;
        }
        writeln!(self.out, "{}", stats_row(stage, s)).with_context(|| format!("cannot write {}", self.path.display()))?;
        if self.flushed.elapsed().as_secs() >= FLUSH_SECONDS {
            self.flush()?;
        }
        Ok(())
    }
    fn flush(&mut self) -> anyhow::Result<()> {
        self.flushed = std::time::Instant::now();
        self.out.flush().with_context(|| format!("cannot write {}", self.path.display()))
    }
    /// Flushes and returns the file's name and length (bytes).
    fn flushed_length(&mut self) -> anyhow::Result<(String, u64)> {
        self.flush()?;
        let len = self.out.get_ref().metadata().with_context(|| format!("cannot read {}", self.path.display()))?.len();
        let name = self.path.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned());
        Ok((name, len))
    }
}

/// Records a run: files under `--out DIR` when given, a progress bar when asked for.
pub struct RunRecorder {
    stats: Option<Csv>,
    stages: Option<Csv>,
    frames: Option<mcap::McapRecorder>,
    /// Whether the MCAP frames keep the contacts the engine's frames carry.
    mcap_contacts: bool,
    vtk: Option<vtk::VtkRecorder>,
    bar: ProgressBar,
    bar_stage: String,
    /// Where checkpoints go and what they belong to.
    checkpoint: Option<(PathBuf, RunIdentity)>,
}

impl RunRecorder {
    /// Creates the output directory and files (when `out` is given); `progress` draws a bar
    /// on stderr.
    pub fn new(out: Option<&Path>, progress: bool) -> anyhow::Result<Self> {
        let bar = if progress { ProgressBar::new(0) } else { ProgressBar::hidden() };
        bar.set_style(ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} steps {per_sec} eta {eta}").expect("a valid template").progress_chars("=> "));
        let (stats, stages, frames) = match out {
            Some(dir) => {
                std::fs::create_dir_all(dir).with_context(|| format!("cannot create the output directory {}", dir.display()))?;
                (
                    Some(Csv::create(dir.join("stats.csv"))?),
                    Some(Csv::create(dir.join("stages.csv"))?),
                    Some(mcap::McapRecorder::create(&dir.join("frames.mcap"))?),
                )
            }
            None => (None, None, None),
        };
        Ok(RunRecorder { stats, stages, frames, mcap_contacts: true, vtk: None, bar, bar_stage: String::new(), checkpoint: None })
    }

    /// Continues the files of a run resumed from the checkpoint `header`: the CSV files are cut
    /// back to their length at the checkpoint and rows are appended; frames go to
    /// `frames-from-stage<S>.mcap` (resumed at the start of stage S) or
    /// `frames-from-stage<S>-step<N>.mcap` (inside it, at step N); the earlier recording is
    /// kept as it is.
    pub fn resume(dir: &Path, header: &CheckpointHeader, progress: bool) -> anyhow::Result<Self> {
        for (name, len) in &header.files {
            let path = dir.join(name);
            let file = std::fs::OpenOptions::new().write(true).open(&path).with_context(|| format!("cannot open {} to continue it", path.display()))?;
            file.set_len(*len).with_context(|| format!("cannot cut {} back to its length at the checkpoint", path.display()))?;
        }
        let p = &header.progress;
        let from = match &p.in_stage {
            Some(s) => format!("stage{}-step{}", p.next_stage, s.step0 + s.done),
            None => format!("stage{}", p.next_stage),
        };
        let mut r = RunRecorder::new(None, progress)?;
        r.stats = Some(Csv::append(dir.join("stats.csv"))?);
        r.stages = Some(Csv::append(dir.join("stages.csv"))?);
        r.frames = Some(mcap::McapRecorder::create(&dir.join(format!("frames-from-{from}.mcap")))?);
        Ok(r)
    }

    /// Also writes the frames of `scene` as VTK files under `dir/vtk` (continuing those of a run
    /// resumed at simulated time `resumed_at`, s), when the scene asks for them; MCAP frames
    /// keep contacts only when the scene asks for those.
    pub fn with_vtk(mut self, dir: &Path, scene: &crate::scene::Scene, resumed_at: Option<f64>) -> anyhow::Result<Self> {
        self.mcap_contacts = scene.output.contact_forces;
        if scene.output.vtk {
            self.vtk = Some(match resumed_at {
                Some(t) => vtk::VtkRecorder::resume(dir, scene, t)?,
                None => vtk::VtkRecorder::create(dir, scene)?,
            });
        }
        Ok(self)
    }

    /// Writes a checkpoint into `dir` whenever the host loop offers one.
    pub fn with_checkpoints(mut self, dir: &Path, identity: RunIdentity) -> Self {
        self.checkpoint = Some((dir.join(crate::checkpoint::FILE), identity));
        self
    }

    /// Flushes the CSV files and closes the MCAP recording (also what a failed run keeps).
    pub fn finish(self) -> anyhow::Result<()> {
        self.bar.finish_and_clear();
        for mut csv in [self.stats, self.stages].into_iter().flatten() {
            csv.flush()?;
        }
        if let Some(f) = self.frames {
            f.finish()?;
        }
        Ok(())
    }
}

impl Recorder for RunRecorder {
    fn stats(&mut self, stage: &str, s: &Stats) -> anyhow::Result<()> {
        if let Some(v) = &mut self.vtk {
            v.stats(s);
        }
        match &mut self.stats {
            Some(csv) => csv.row(stage, s),
            None => Ok(()),
        }
    }
    fn frame(&mut self, f: &Frame) -> anyhow::Result<()> {
        if let Some(v) = &mut self.vtk {
            v.write(f)?;
        }
        match &mut self.frames {
            Some(m) if !self.mcap_contacts && (f.contacts.is_some() || f.wall_contacts.is_some()) => {
                m.write(&Frame { contacts: None, wall_contacts: None, ..f.clone() })
            }
            Some(m) => m.write(f),
            None => Ok(()),
        }
    }
    fn stage_end(&mut self, r: &StageResult) -> anyhow::Result<()> {
        if let Some(csv) = &mut self.stages {
            csv.row(&r.name, &r.stats)?;
            csv.flush()?;
        }
        if let Some(csv) = &mut self.stats {
            csv.flush()?;
        }
        Ok(())
    }
    fn checkpoint(&mut self, progress: &Progress, engine: &dyn Engine) -> anyhow::Result<()> {
        let Some((path, identity)) = &self.checkpoint else { return Ok(()) };
        let state = engine.save()?;
        let files = [&mut self.stats, &mut self.stages].into_iter().flatten().map(Csv::flushed_length).collect::<anyhow::Result<_>>()?;
        let header = CheckpointHeader { identity: identity.clone(), progress: progress.clone(), files };
        crate::checkpoint::write(path, &header, &state)
    }

    fn progress(&mut self, stage: &str, done: u64, total: u64) {
        if self.bar_stage != stage {
            self.bar_stage = stage.to_string();
            self.bar.reset();
            self.bar.set_message(stage.to_string());
            self.bar.set_length(total);
        }
        self.bar.set_position(done);
    }
}

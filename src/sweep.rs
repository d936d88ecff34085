//! Parameter sweeps: one scene run over a grid (or list) of parameter values, each point in
//! its own directory, resumable, gathered into one table with the power law h_s = a eta^b
//! across the points (Oquendo et al.'s Figure 5) and, for scenes with the force-transmission
//! analysis (`output.analysis`), each figure's mean and spread over the points (a sweep over
//! `seed` gives independent samples).
//!
//! A sweep file:
//! ```toml
//! scene = "oedometer.toml"          # relative to the sweep file
//! mode = "grid"                     # "grid": every combination; "zip": the k-th values together
//! [parameters]
//! "material.sand.mu_s" = [0.1, 0.2, 0.4]
//! ```
//! A parameter is a dotted path into the scene: tables by key, arrays of tables (`material`,
//! `generate`, `wall`, `stage`, `grain`) by the `name` of an entry or by index.

use crate::analysis::ensemble::{self, Figure};
use crate::analysis::fit::{fit_power_law, Estimate, PowerLaw};
use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A sweep file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// The scene, relative to the sweep file.
    pub scene: PathBuf,
    /// "grid" (default) or "zip".
    #[serde(default)]
    pub mode: Option<String>,
    /// Dotted parameter path -> values.
    pub parameters: BTreeMap<String, Vec<toml::Value>>,
}

/// One point of a sweep: the values of every parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Point {
    /// Index in the sweep (0-based).
    pub index: usize,
    /// Parameter path -> value.
    pub values: BTreeMap<String, toml::Value>,
}

/// A loaded sweep.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The sweep file.
    pub file: PathBuf,
    /// The scene file.
    pub scene: PathBuf,
    /// The scene's text.
    pub scene_text: String,
    /// Every point.
    pub points: Vec<Point>,
}

/// Reads a sweep file and expands its points.
pub fn load(file: &Path) -> anyhow::Result<Sweep> {
    let text = std::fs::read_to_string(file).with_context(|| format!("{}: cannot read the sweep; fix: check the path", file.display()))?;
    let spec: SweepFile = toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}", crate::scene::SceneError::syntax(file, &text, &e)))?;
    let scene = file.parent().unwrap_or(Path::new(".")).join(&spec.scene);
    let scene_text = std::fs::read_to_string(&scene).with_context(|| format!("{}: scene = {:?}: cannot read {}; fix: give the scene's path relative to the sweep file", file.display(), spec.scene, scene.display()))?;
    if spec.parameters.is_empty() {
        bail!("{}: [parameters] is empty; fix: give at least one \"path\" = [values]", file.display());
    }
    let names: Vec<&String> = spec.parameters.keys().collect();
    let lists: Vec<&Vec<toml::Value>> = spec.parameters.values().collect();
    if let Some((n, _)) = spec.parameters.iter().find(|(_, v)| v.is_empty()) {
        bail!("{}: parameters.\"{n}\" = []: no values; fix: give at least one value", file.display());
    }
    let combos: Vec<Vec<toml::Value>> = match spec.mode.as_deref().unwrap_or("grid") {
        "grid" => lists.iter().fold(vec![vec![]], |acc, list| acc.into_iter().flat_map(|prefix| list.iter().map(move |v| [prefix.clone(), vec![v.clone()]].concat())).collect()),
        "zip" => {
            let n = lists[0].len();
            if let Some((k, l)) = lists.iter().enumerate().find(|(_, l)| l.len() != n) {
                bail!("{}: mode = \"zip\" needs lists of one length: \"{}\" has {} values, \"{}\" has {n}; fix: make them equal or use mode = \"grid\"", file.display(), names[k], l.len(), names[0]);
            }
            (0..n).map(|i| lists.iter().map(|l| l[i].clone()).collect()).collect()
        }
        other => bail!("{}: mode = \"{other}\": unknown; fix: use \"grid\" or \"zip\"", file.display()),
    };
    let points: Vec<Point> = combos.into_iter().enumerate().map(|(index, vals)| Point { index, values: names.iter().map(|n| n.to_string()).zip(vals).collect() }).collect();
    let sweep = Sweep { file: file.to_path_buf(), scene, scene_text, points };
    // Check every point's scene now, not hours into the sweep.
    for p in &sweep.points {
        sweep.scene_for(p)?;
    }
    Ok(sweep)
}

impl Sweep {
    /// The scene text of a point (the sweep's scene with the point's values set).
    pub fn scene_for(&self, p: &Point) -> anyhow::Result<String> {
        let mut doc: toml::Table = toml::from_str(&self.scene_text).with_context(|| format!("{}: not valid TOML", self.scene.display()))?;
        for (path, v) in &p.values {
            crate::scene::dotted::set(&mut doc, path, v.clone()).map_err(|e| anyhow::anyhow!("{}: parameters.\"{path}\": {e}; {}", self.file.display(), crate::scene::dotted::FIX))?;
        }
        let text = toml::to_string(&doc)?;
        crate::scene::parse(&self.scene, &text).map_err(|e| anyhow::anyhow!("{} point {}: {e}", self.file.display(), p.index))?;
        Ok(text)
    }

    /// The directory of a point under `out`.
    pub fn point_dir(out: &Path, p: &Point) -> PathBuf {
        out.join(format!("point-{:03}", p.index))
    }

    /// An sbatch job-array script whose task k runs point k with `grains sweep --only k`.
    pub fn slurm_script(&self, out: &Path, grains: &Path) -> String {
        format!(
            "#!/bin/bash\n# Job array for the sweep {file}: task k runs point k; afterwards `grains sweep {file} --out {out}` gathers.\n#SBATCH --job-name=grains-sweep\n#SBATCH --array=0-{last}\n#SBATCH --cpus-per-task=2\n#SBATCH --output={out}/slurm-%A_%a.log\nset -euo pipefail\n\"{grains}\" sweep \"{file}\" --out \"{out}\" --only \"$SLURM_ARRAY_TASK_ID\" --threads \"${{SLURM_CPUS_PER_TASK:-1}}\"\n",
            file = self.file.display(),
            out = out.display(),
            last = self.points.len().saturating_sub(1),
            grains = grains.display()
        )
    }
}

/// One row of the sweep table.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The point.
    pub point: Point,
    /// Void ratio before loading (or fitted).
    pub e0: Option<f64>,
    /// h_s (MPa).
    pub h_s: Option<Estimate>,
    /// eta.
    pub eta: Option<Estimate>,
    /// Why there is no fit, if there is none.
    pub note: Option<String>,
}

/// The gathered sweep.
#[derive(Clone, Debug, Serialize)]
pub struct Table {
    /// One row per point.
    pub rows: Vec<Row>,
    /// h_s = a eta^b (MPa) across the points with a fit, when at least 3 have one.
    pub power_law: Option<PowerLaw>,
    /// The force-transmission figures over the points with an `analysis.json` (empty when
    /// none has one).
    pub ensemble: Vec<Figure>,
}

impl Table {
    /// The table as CSV.
    pub fn csv(&self) -> String {
        let names: Vec<String> = self.rows.first().map(|r| r.point.values.keys().cloned().collect()).unwrap_or_default();
        let mut s = format!("point,{},e0,h_s_MPa,h_s_error_MPa,eta,eta_error,note\n", names.join(","));
        for r in &self.rows {
            let vals: Vec<String> = r.point.values.values().map(|v| v.to_string()).collect();
            let est = |e: &Option<Estimate>| e.map_or(",".to_string(), |e| format!("{},{}", e.value, e.error));
            s.push_str(&format!("{},{},{},{},{},{}\n", r.point.index, vals.join(","), r.e0.map_or(String::new(), |e| e.to_string()), est(&r.h_s), est(&r.eta), r.note.clone().unwrap_or_default()));
        }
        s
    }

    /// A few lines for a person.
    pub fn human(&self) -> String {
        let mut s = String::new();
        for r in &self.rows {
            let vals: Vec<String> = r.point.values.iter().map(|(k, v)| format!("{k} = {v}")).collect();
            match (&r.h_s, &r.eta) {
                (Some(h), Some(e)) => s.push_str(&format!("point {:>3}: {}: h_s = {} MPa, eta = {}\n", r.point.index, vals.join(", "), h.concise(), e.concise())),
                _ => s.push_str(&format!("point {:>3}: {}: {}\n", r.point.index, vals.join(", "), r.note.as_deref().unwrap_or("finished"))),
            }
        }
        if let Some(l) = &self.power_law {
            s.push_str(&format!("power law across the points: {} (Oquendo et al.: {})\n", l.line(), crate::analysis::oquendo::POWER_LAW.line()));
        }
        if !self.ensemble.is_empty() {
            s.push_str("force transmission over the points:\n");
            s.push_str(&ensemble::human(&self.ensemble));
        }
        s
    }
}

/// Reads every point's summary (and analysis, where there is one) under `out` into the table.
pub fn gather(sweep: &Sweep, out: &Path) -> anyhow::Result<Table> {
    let mut rows = Vec::new();
    let mut analysed = Vec::new();
    for p in &sweep.points {
        let path = Sweep::point_dir(out, p).join("summary.json");
        let row = match std::fs::read_to_string(&path) {
            Err(_) => {
                let note = match std::fs::read_to_string(Sweep::point_dir(out, p).join(ERROR_FILE)) {
                    Ok(e) => format!("failed: {}", e.lines().next().unwrap_or("")),
                    Err(_) => "not run yet".into(),
                };
                Row { point: p.clone(), e0: None, h_s: None, eta: None, note: Some(note) }
            }
            Ok(text) => {
                let v: serde_json::Value = serde_json::from_str(&text).with_context(|| format!("{}: unreadable summary", path.display()))?;
                let est = |key: &str, scale: f64| -> Option<Estimate> {
                    let b = &v["bauer"][key];
                    Some(Estimate { value: b["value"].as_f64()? / scale, error: b["error"].as_f64()? / scale })
                };
                let (h_s, eta) = (est("h_s", 1e6), est("eta", 1.0));
                // A scene that records no compression has no Bauer fit to miss.
                let compresses = v["compression"].as_array().is_some_and(|c| !c.is_empty());
                let note = if h_s.is_none() && compresses { Some(v["bauer_error"].as_str().unwrap_or("no Bauer fit").to_string()) } else { None };
                let analysis = Sweep::point_dir(out, p).join("analysis.json");
                if let Ok(a) = std::fs::read_to_string(&analysis) {
                    analysed.push((v.clone(), serde_json::from_str(&a).with_context(|| format!("{}: unreadable analysis", analysis.display()))?));
                }
                Row { point: p.clone(), e0: v["bauer"]["e0"]["value"].as_f64(), h_s, eta, note }
            }
        };
        rows.push(row);
    }
    let fitted: Vec<(f64, f64)> = rows.iter().filter_map(|r| Some((r.eta?.value, r.h_s?.value))).filter(|(x, y)| *x > 0.0 && *y > 0.0).collect();
    let power_law = if fitted.len() >= 3 { fit_power_law(&fitted).ok() } else { None };
    Ok(Table { rows, power_law, ensemble: ensemble::gather(&analysed) })
}

/// Whether a point has finished (its summary is written last, after every other output).
pub fn done(out: &Path, p: &Point) -> bool {
    Sweep::point_dir(out, p).join("summary.json").exists()
}

/// The file in a point's directory that holds why its last run failed (removed when it runs
/// again), so that the gathered table can say so.
pub const ERROR_FILE: &str = "error.txt";

/// Runs one point into its directory, recording a failure in [`ERROR_FILE`] there.
pub fn run_point(sweep: &Sweep, out: &Path, p: &Point, precision: &str) -> anyhow::Result<()> {
    if done(out, p) {
        return Ok(());
    }
    let dir = Sweep::point_dir(out, p);
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let error = dir.join(ERROR_FILE);
    let _ = std::fs::remove_file(&error);
    run_point_in(sweep, &dir, p, precision).inspect_err(|e| {
        let _ = std::fs::write(&error, format!("{e:#}\n"));
    })
}

/// [`run_point`] in its created directory: the point's scene is written there as
/// `scene.toml`; a point with a checkpoint and no summary resumes.
fn run_point_in(sweep: &Sweep, dir: &Path, p: &Point, precision: &str) -> anyhow::Result<()> {
    let scene_file = dir.join("scene.toml");
    let text = sweep.scene_for(p)?;
    let checkpoint = dir.join(crate::checkpoint::FILE);
    if checkpoint.exists() && std::fs::read_to_string(&scene_file).ok().as_deref() == Some(text.as_str()) {
        crate::runner::resume(dir, Some(&scene_file), Some(precision), None, false)?;
    } else {
        std::fs::write(&scene_file, &text).with_context(|| format!("cannot write {}", scene_file.display()))?;
        crate::runner::run_cpu(&scene_file, precision, Some(dir), false)?;
    }
    Ok(())
}

/// Runs the given points, `jobs` at a time, each on `threads` worker threads; returns the
/// failures as (point, error) in point order.
pub fn run_points(sweep: &Sweep, out: &Path, points: &[usize], precision: &str, jobs: usize, threads: usize) -> Vec<(usize, String)> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..jobs.max(1) {
            s.spawn(|| {
                let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build() {
                    Ok(p) => p,
                    Err(e) => {
                        failures.lock().expect("no poisoned lock").push((usize::MAX, e.to_string()));
                        return;
                    }
                };
                loop {
                    let k = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                    let Some(&index) = points.get(k) else { break };
                    let p = &sweep.points[index];
                    let started = std::time::Instant::now();
                    match pool.install(|| run_point(sweep, out, p, precision)) {
                        Ok(()) => eprintln!("point {index}: done in {:.1} s", started.elapsed().as_secs_f64()),
                        Err(e) => {
                            eprintln!("point {index}: failed: {e:#}");
                            failures.lock().expect("no poisoned lock").push((index, format!("{e:#}")));
                        }
                    }
                }
            });
        }
    });
    let mut f = failures.into_inner().expect("no poisoned lock");
    f.sort_by_key(|x| x.0);
    f
}

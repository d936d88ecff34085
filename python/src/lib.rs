//! `grains._grains`: the Python module's native layer over the `grains` library. Scenes are
//! TOML documents edited by dotted paths and validated by the library; a simulation is the
//! library's engine and host loop, stepped with the interpreter's lock released; state comes
//! back as NumPy arrays in SI units. What crosses as JSON (summaries, statistics, stage results,
//! analyses) is turned into dictionaries by the pure-Python package `grains`.

use grains::checkpoint::CheckpointHeader;
use grains::engine::{Engine, Frame};
use grains::periodic::Periodic;
use grains::protocol::Progress;
use grains::runner::{Run, Watch};
use grains::scene::dotted;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

create_exception!(_grains, GrainsError, PyException, "Any error grains reports.");
create_exception!(_grains, SceneError, GrainsError, "A scene that does not parse or validate: the message names the file, the key, the value and the fix, as the command line's does.");
create_exception!(_grains, SimulationError, GrainsError, "A run that cannot go on: an engine that cannot start, a run that went unstable, a checkpoint that does not fit.");

/// The library's error as a [`SimulationError`], with its causes, as `grains` prints it.
fn sim_err(e: impl Into<anyhow::Error>) -> PyErr {
    SimulationError::new_err(format!("{:#}", e.into()))
}

fn scene_err(e: impl std::fmt::Display) -> PyErr {
    SceneError::new_err(e.to_string())
}

/// A scene: its TOML document, where it came from, and whether it is still that file's text.
#[pyclass(module = "grains._grains")]
#[derive(Clone)]
struct Scene {
    /// The file it was read from, or the path given for a text (relative file names in the
    /// scene resolve against its folder; errors name it).
    path: PathBuf,
    doc: toml::Table,
    /// The file's own text while nothing has been set (a checkpoint's identity hashes it).
    original: Option<String>,
}

impl Scene {
    /// The scene's text as a run sees it.
    fn text(&self) -> String {
        self.original.clone().unwrap_or_else(|| toml::to_string(&self.doc).expect("a TOML table serialises"))
    }

    /// The validated scene.
    fn validated(&self) -> PyResult<grains::scene::Scene> {
        grains::scene::parse(&self.path, &self.text()).map_err(scene_err)
    }

    fn of_text(path: PathBuf, text: String, from_file: bool) -> PyResult<Scene> {
        grains::scene::parse(&path, &text).map_err(scene_err)?;
        let doc: toml::Table = toml::from_str(&text).map_err(|e| scene_err(format!("{}: {e}", path.display())))?;
        Ok(Scene { path, doc, original: from_file.then_some(text) })
    }
}

#[pymethods]
impl Scene {
    /// Reads and validates a scene file.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Scene> {
        let text = std::fs::read_to_string(&path).map_err(|reason| scene_err(grains::scene::SceneError::Read { file: path.clone(), reason }))?;
        Scene::of_text(path, text, true)
    }

    /// Validates a scene given as TOML text; `path` names it in errors and is where relative
    /// file names in it resolve from.
    #[staticmethod]
    #[pyo3(signature = (text, path = None))]
    fn from_toml(text: String, path: Option<PathBuf>) -> PyResult<Scene> {
        Scene::of_text(path.unwrap_or_else(|| PathBuf::from("scene.toml")), text, false)
    }

    /// The value at a dotted path (`material.sand.mu_s`, `stage.0.duration`); `None` where
    /// the scene leaves it to its default.
    fn __getitem__(&self, py: Python<'_>, key: &str) -> PyResult<Py<PyAny>> {
        match dotted::get(&self.doc, key).map_err(|e| key_error(key, &e))? {
            Some(v) => toml_to_py(py, &v),
            None => Ok(py.None()),
        }
    }

    /// Sets the value at a dotted path and validates the scene; an invalid value is not kept
    /// (the error is the command line's).
    fn __setitem__(&mut self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let value = py_to_toml(value).map_err(|e| PyValueError::new_err(format!("scene[{key:?}]: {e}")))?;
        self.update_with(&[(key.to_string(), value)])
    }

    /// Sets several dotted paths at once and validates once (for values that must change
    /// together); nothing is kept if the result is invalid.
    fn update(&mut self, values: &Bound<'_, PyDict>) -> PyResult<()> {
        let mut set = Vec::new();
        for (k, v) in values.iter() {
            let key: String = k.extract()?;
            let value = py_to_toml(&v).map_err(|e| PyValueError::new_err(format!("scene[{key:?}]: {e}")))?;
            set.push((key, value));
        }
        self.update_with(&set)
    }

    /// The scene as TOML text.
    fn to_toml(&self) -> String {
        self.text()
    }

    /// The scene's file (or the path given with its text).
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// Whether the scene is still its file's text (nothing set since `load`).
    #[getter]
    fn unchanged(&self) -> bool {
        self.original.is_some()
    }

    /// What a run would do: grains, masses, time step, laws, memory (`grains check`).
    fn check(&self) -> PyResult<String> {
        let scene = self.validated()?;
        scene.check_practical().map_err(scene_err)?;
        Ok(grains::output::check_report(&scene))
    }

    /// The scene's name, grain count and file.
    fn __repr__(&self) -> String {
        match self.validated() {
            Ok(s) => format!("Scene({:?}, {} grains, {})", s.name, s.grains.radius.len(), self.path.display()),
            Err(_) => format!("Scene({})", self.path.display()),
        }
    }
}

impl Scene {
    fn update_with(&mut self, values: &[(String, toml::Value)]) -> PyResult<()> {
        let mut doc = self.doc.clone();
        for (key, value) in values {
            dotted::set(&mut doc, key, value.clone()).map_err(|e| key_error(key, &e))?;
        }
        let text = toml::to_string(&doc).expect("a TOML table serialises");
        grains::scene::parse(&self.path, &text).map_err(scene_err)?;
        self.doc = doc;
        self.original = None;
        Ok(())
    }
}

/// The `KeyError` for a dotted path `key` that names nothing (`e` says which part).
fn key_error(key: &str, e: &str) -> PyErr {
    pyo3::exceptions::PyKeyError::new_err(format!("{key}: {e}; {}", dotted::FIX))
}

fn toml_to_py(py: Python<'_>, v: &toml::Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        toml::Value::String(s) => s.into_pyobject(py)?.into_any().unbind(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any().unbind(),
        toml::Value::Float(f) => f.into_pyobject(py)?.into_any().unbind(),
        toml::Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any().unbind(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any().unbind(),
        toml::Value::Array(a) => PyList::new(py, a.iter().map(|x| toml_to_py(py, x)).collect::<PyResult<Vec<_>>>()?)?.into_any().unbind(),
        toml::Value::Table(t) => {
            let d = PyDict::new(py);
            for (k, x) in t {
                d.set_item(k, toml_to_py(py, x)?)?;
            }
            d.into_any().unbind()
        }
    })
}

fn py_to_toml(v: &Bound<'_, PyAny>) -> Result<toml::Value, String> {
    if v.is_instance_of::<PyBool>() {
        return v.extract::<bool>().map(toml::Value::Boolean).map_err(|e| e.to_string());
    }
    if v.is_instance_of::<PyInt>() {
        return v.extract::<i64>().map(toml::Value::Integer).map_err(|e| e.to_string());
    }
    if v.is_instance_of::<PyFloat>() {
        return v.extract::<f64>().map(toml::Value::Float).map_err(|e| e.to_string());
    }
    if v.is_instance_of::<PyString>() {
        return v.extract::<String>().map(toml::Value::String).map_err(|e| e.to_string());
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            t.insert(k.extract::<String>().map_err(|_| "table keys must be strings".to_string())?, py_to_toml(&x)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        return v.try_iter().map_err(|e| e.to_string())?.map(|x| py_to_toml(&x.map_err(|e| e.to_string())?)).collect::<Result<Vec<_>, _>>().map(toml::Value::Array);
    }
    // NumPy scalars and anything else that behaves as a number.
    if let Ok(i) = v.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(f) = v.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    Err(format!("a {} has no TOML form; fix: give a bool, int, float, str, list or dict", v.get_type().name().map_or("value".into(), |n| n.to_string())))
}

/// A simulation: an engine on the scene, the host loop's progress, and the outputs.
#[pyclass(module = "grains._grains")]
struct Simulation {
    /// One caller at a time; `advance` steps with the interpreter's lock released.
    inner: Mutex<Sim>,
}

struct Sim {
    scene: grains::scene::Scene,
    engine: Box<dyn Engine + Send>,
    /// The worker threads every engine call runs on, as `grains run --threads` does.
    pool: rayon::ThreadPool,
    /// The run with its outputs, until its last stage has finished (then `None`).
    run: Option<Run>,
    /// The stability guard for steps taken outside the stages.
    guard: Progress,
    /// The scene's file as a checkpoint names it, and its text.
    scene_file: PathBuf,
    scene_text: String,
    /// The output directory.
    out: Option<PathBuf>,
    /// `summary.json`'s content once the last stage has finished.
    summary: Option<String>,
    /// Why the run stopped early (an interrupt or an error), when it did.
    stopped: Option<String>,
    /// Told of each statistics read inside a stage, as `on_progress(stage, done, total)`.
    on_progress: Option<Py<PyAny>>,
}

/// A pool of `threads` workers (0: one per core).
fn pool(threads: usize) -> PyResult<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(sim_err)
}

/// Where the scene's text lives for a checkpoint, and that text: its own file while
/// unchanged, else `scene.toml` written into `dir`, its files (meshes, grains read) named by
/// absolute paths so that they resolve from there as they did from the scene's own folder.
fn scene_file_for(scene: &Scene, dir: Option<&Path>) -> PyResult<(PathBuf, String)> {
    match (&scene.original, dir) {
        (Some(text), _) => Ok((scene.path.clone(), text.clone())),
        (None, Some(dir)) => {
            std::fs::create_dir_all(dir).map_err(|e| sim_err(anyhow::anyhow!("cannot create {}: {e}", dir.display())))?;
            let file = dir.join("scene.toml");
            let folder = std::path::absolute(&scene.path).map_err(sim_err)?.parent().map(Path::to_path_buf).unwrap_or_default();
            let text = toml::to_string(&with_files_from(&scene.doc, &folder)).expect("a TOML table serialises");
            std::fs::write(&file, &text).map_err(|e| sim_err(anyhow::anyhow!("cannot write {}: {e}", file.display())))?;
            Ok((file, text))
        }
        (None, None) => Ok((scene.path.clone(), scene.text())),
    }
}

/// `doc` with the relative `file` of each `[[wall]]` and `[[read]]` table made absolute from
/// `folder`, the scene's own.
fn with_files_from(doc: &toml::Table, folder: &Path) -> toml::Table {
    let mut doc = doc.clone();
    for table in ["wall", "read"] {
        let Some(toml::Value::Array(items)) = doc.get_mut(table) else { continue };
        for item in items.iter_mut() {
            if let Some(toml::Value::String(f)) = item.get_mut("file") {
                if Path::new(f.as_str()).is_relative() {
                    *f = folder.join(&*f).display().to_string();
                }
            }
        }
    }
    doc
}

#[pymethods]
impl Simulation {
    /// An engine on `scene` (`backend` "cpu" or "gpu"; `precision` "f32" or "f64", the CPU's
    /// default f64 and the GPU's f32) on `threads` worker threads (None: one per core),
    /// recording into `out` as `grains run --out` does. `progress` draws the command line's
    /// bar on a terminal; `on_progress(stage, done, total)` is called at every statistics
    /// read inside a stage. `force` skips the practicality checks `grains run --force` skips.
    #[new]
    #[pyo3(signature = (scene, backend = "cpu", precision = None, threads = None, out = None, progress = false, adapter = None, force = false, on_progress = None))]
    fn new(py: Python<'_>, scene: &Scene, backend: &str, precision: Option<&str>, threads: Option<usize>, out: Option<PathBuf>, progress: bool, adapter: Option<String>, force: bool, on_progress: Option<Py<PyAny>>) -> PyResult<Simulation> {
        let validated = scene.validated()?;
        if !force {
            validated.check_practical().map_err(scene_err)?;
        }
        let (scene_file, scene_text) = scene_file_for(scene, out.as_deref())?;
        let pool = pool(threads.unwrap_or(0))?;
        let (backend, precision) = (backend.to_string(), precision.map(str::to_string));
        let sim = py.detach(|| {
            pool.install(|| -> anyhow::Result<_> {
                let mut engine = match (backend.as_str(), precision.as_deref()) {
                    ("cpu", p) => grains::runner::local_cpu_engine(&validated, p.unwrap_or("f64"))?,
                    ("gpu", None | Some("f32")) => grains::runner::gpu_engine(grains::gpu::open(adapter.as_deref())?, &validated)?,
                    ("gpu", Some(p)) => anyhow::bail!("precision {p:?}: the GPU computes in f32; fix: give precision=\"f32\" or leave it out"),
                    (b, _) => anyhow::bail!("backend {b:?}: unknown; fix: give \"cpu\" or \"gpu\""),
                };
                let start = Progress::start(&validated, engine.as_mut())?;
                let id = grains::runner::identity_of(&scene_file, scene_text.as_bytes(), engine.as_ref());
                let run = Run::start(&validated, engine.as_ref(), out.as_deref(), start.clone(), id, None, progress)?;
                Ok((validated, engine, run, start))
            })
        });
        let (scene, engine, run, guard) = sim.map_err(sim_err)?;
        Ok(Simulation { inner: Mutex::new(Sim { scene, engine, pool, run: Some(run), guard, scene_file, scene_text, out, summary: None, stopped: None, on_progress }) })
    }

    /// Continues the run in `dir` from its checkpoint, on the backend and precision that wrote
    /// it, recording into `dir` as `grains run --resume` does.
    #[staticmethod]
    #[pyo3(signature = (dir, threads = None, progress = false, adapter = None, on_progress = None))]
    fn resume(py: Python<'_>, dir: PathBuf, threads: Option<usize>, progress: bool, adapter: Option<String>, on_progress: Option<Py<PyAny>>) -> PyResult<Simulation> {
        let pool = pool(threads.unwrap_or(0))?;
        let sim = py.detach(|| {
            pool.install(|| -> anyhow::Result<_> {
                let r = grains::runner::open_checkpoint(&dir, None, None, |scene, id| grains::runner::local_engine_of(scene, id, adapter.as_deref()))?;
                let run = Run::start(&r.scene, r.engine.as_ref(), Some(&dir), r.header.progress.clone(), r.identity, Some(&r.header), progress)?;
                Ok((r.scene, r.engine, run, r.header.progress, r.scene_file, r.scene_text))
            })
        });
        let (scene, engine, run, guard, scene_file, scene_text) = sim.map_err(sim_err)?;
        Ok(Simulation { inner: Mutex::new(Sim { scene, engine, pool, run: Some(run), guard, scene_file, scene_text, out: Some(dir), summary: None, stopped: None, on_progress }) })
    }

    /// Runs the next stage (recording into `out`); its result as JSON, or None when every
    /// stage has run. After the last stage the run's summary is written. Ctrl-C stops the
    /// stage at its next statistics read, keeping what was recorded.
    fn run_stage(&self, py: Python<'_>) -> PyResult<Option<String>> {
        let mut sim = self.lock()?;
        sim.next_stage(py)
    }

    /// Runs every stage left; the summary as JSON (`summary.json`'s content).
    fn run(&self, py: Python<'_>) -> PyResult<String> {
        let mut sim = self.lock()?;
        while sim.next_stage(py)?.is_some() {}
        Ok(sim.summary.clone().unwrap_or_default())
    }

    /// Advances `steps` time steps with the interpreter's lock released, in chunks that end
    /// on the scene's statistics interval (counted in the engine's steps): at each such end the
    /// run is checked for instability as inside a stage, and after every chunk Ctrl-C stops it
    /// (a whole number of steps taken). Nothing is recorded.
    fn advance_steps(&self, py: Python<'_>, steps: u64) -> PyResult<()> {
        let mut sim = self.lock()?;
        let interval = sim.scene.stats_interval.max(1);
        let mut done = 0;
        while done < steps {
            let Sim { engine, pool, guard, scene, .. } = &mut *sim;
            let n = (interval - engine.steps() % interval).min(steps - done);
            let engine = &mut **engine;
            let scene = &*scene;
            py.detach(move || pool.install(move || -> anyhow::Result<()> {
                // The scene's inlets and outlets act at their steps on the way.
                guard.advance(scene, engine, n)?;
                if engine.steps() % interval == 0 {
                    guard.check_stable(&guard.stats(engine)?)?;
                }
                Ok(())
            }))
            .map_err(sim_err)?;
            done += n;
            py.check_signals()?;
        }
        Ok(())
    }

    /// Steps between statistics reads: where `advance` checks the run and Ctrl-C stops it.
    #[getter]
    fn stats_interval(&self) -> PyResult<u64> {
        Ok(self.lock()?.scene.stats_interval)
    }

    /// The time step (s).
    #[getter]
    fn dt(&self) -> PyResult<f64> {
        Ok(self.lock()?.scene.time_step.dt)
    }

    /// Simulated time (s).
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.lock()?.engine.time())
    }

    /// Steps taken.
    #[getter]
    fn steps(&self) -> PyResult<u64> {
        Ok(self.lock()?.engine.steps())
    }

    /// "cpu" or "gpu".
    #[getter]
    fn backend(&self) -> PyResult<&'static str> {
        Ok(self.lock()?.engine.backend())
    }

    /// "f32" or "f64".
    #[getter]
    fn precision(&self) -> PyResult<&'static str> {
        Ok(self.lock()?.engine.precision())
    }

    /// The stages' names, in order, and how many have run.
    fn stages(&self) -> PyResult<(Vec<String>, usize)> {
        let sim = self.lock()?;
        let done = sim.run.as_ref().map_or(sim.scene.stages.len(), |r| r.progress().next_stage);
        Ok((sim.scene.stages.iter().map(|s| s.name.clone()).collect(), done))
    }

    /// Sets the piston's target pressure (Pa); no effect without a piston.
    fn set_piston_pressure(&self, pressure: f64) -> PyResult<()> {
        self.lock()?.engine.set_piston_pressure(pressure);
        Ok(())
    }

    /// Sets wall `name` (a plane or a cylinder by its name, a box by its name for every face)
    /// moving at `velocity` (m/s) and spinning at `angular_velocity` (rad/s) about its axis from
    /// now on, checked as a stage's `walls` are.
    #[pyo3(signature = (name, velocity = [0.0; 3], angular_velocity = [0.0; 3]))]
    fn set_wall_motion(&self, name: &str, velocity: [f64; 3], angular_velocity: [f64; 3]) -> PyResult<()> {
        let mut sim = self.lock()?;
        let drives = sim.scene.wall_drives("set_wall_motion", name, velocity.into(), angular_velocity.into()).map_err(scene_err)?;
        for (wall, drive) in &drives {
            sim.engine.set_wall_drive(*wall, drive);
        }
        Ok(())
    }

    /// Takes the walls `name` names away (`present` false: grains pass through them) or adds
    /// them back, as a stage's `remove_walls` and `add_walls` do.
    fn set_wall_present(&self, name: &str, present: bool) -> PyResult<()> {
        let mut sim = self.lock()?;
        let walls = sim.scene.walls_to_add_or_remove("set_wall_present", name).map_err(scene_err)?;
        let sim = &mut *sim;
        for w in walls {
            grains::protocol::set_wall_present(&sim.scene, sim.engine.as_mut(), w, present, "set_wall_present").map_err(sim_err)?;
        }
        Ok(())
    }

    /// Sets the servo walls' target pressure (Pa, when given) and the z walls' strain rate
    /// (1/s, positive closing; None: back to pressure control).
    #[pyo3(signature = (pressure = None, axial_strain_rate = None))]
    fn set_servo(&self, pressure: Option<f64>, axial_strain_rate: Option<f64>) -> PyResult<()> {
        self.lock()?.engine.set_servo(pressure, axial_strain_rate);
        Ok(())
    }

    /// The statistics now, as JSON (the fields of `stats.csv`).
    fn stats_json(&self, py: Python<'_>) -> PyResult<String> {
        let mut sim = self.lock()?;
        let Sim { engine, pool, guard, .. } = &mut *sim;
        let stats = py.detach(|| pool.install(|| guard.stats(engine.as_mut()))).map_err(sim_err)?;
        serde_json::to_string(&stats).map_err(sim_err)
    }

    /// The grains' state: a dict of arrays in id order (`ids`, `radii`, `materials`,
    /// `positions`, `velocities`, `angular_velocities`, `forces`, and `orientations` where the
    /// scene tracks them).
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mut sim = self.lock()?;
        let frame = sim.frame(py, true)?;
        let d = grain_arrays(py, &frame)?;
        let material: Vec<u16> = frame.id.iter().map(|&i| sim.scene.grains.material[i as usize]).collect();
        d.set_item("materials", PyArray1::from_vec(py, material))?;
        d.set_item("forces", rows(py, &grains::analysis::contact_forces(&frame))?)?;
        if let Some(q) = &frame.orientation {
            d.set_item("orientations", PyArray1::from_vec(py, q.iter().flat_map(|q| [q.w, q.x, q.y, q.z]).collect::<Vec<f64>>()).reshape([q.len(), 4])?)?;
        }
        Ok(d)
    }

    /// The touching pairs: a dict of arrays, one row per pair (`i`, `j`, `normal` from j to
    /// i, `normal_force` compressive positive, `tangential_force` on i, `force` on i,
    /// `force_j` on j, `overlap`, `bridge_volume`).
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mut sim = self.lock()?;
        let frame = sim.frame(py, true)?;
        let periodic = Periodic::of(&sim.scene.periodic);
        let c = frame.contacts.as_deref().unwrap_or(&[]);
        let normal: Vec<glam::DVec3> = c.iter().map(|r| grains::analysis::contact_normal(&frame, &periodic, r).f64()).collect();
        let tangential: Vec<glam::DVec3> = c.iter().zip(&normal).map(|(r, n)| r.force - r.force.dot(*n) * *n).collect();
        let d = PyDict::new(py);
        d.set_item("i", PyArray1::from_vec(py, c.iter().map(|r| r.i).collect::<Vec<u32>>()))?;
        d.set_item("j", PyArray1::from_vec(py, c.iter().map(|r| r.j).collect::<Vec<u32>>()))?;
        d.set_item("normal", rows(py, &normal)?)?;
        d.set_item("normal_force", PyArray1::from_vec(py, c.iter().map(|r| r.normal_force).collect::<Vec<f64>>()))?;
        d.set_item("tangential_force", rows(py, &tangential)?)?;
        d.set_item("force", rows(py, &c.iter().map(|r| r.force).collect::<Vec<_>>())?)?;
        d.set_item("force_j", rows(py, &c.iter().map(|r| r.force_j).collect::<Vec<_>>())?)?;
        d.set_item("overlap", PyArray1::from_vec(py, c.iter().map(|r| r.overlap).collect::<Vec<f64>>()))?;
        d.set_item("bridge_volume", PyArray1::from_vec(py, c.iter().map(|r| r.bridge_volume).collect::<Vec<f64>>()))?;
        Ok(d)
    }

    /// The force-transmission analysis of the state now (what `analysis.json` holds), as JSON.
    fn analysis_json(&self, py: Python<'_>) -> PyResult<String> {
        let mut sim = self.lock()?;
        let frame = sim.frame(py, true)?;
        let Sim { engine, pool, scene, .. } = &mut *sim;
        let stats = py.detach(|| pool.install(|| engine.stats())).map_err(sim_err)?;
        let a = grains::output::network::analyze_scene(scene, &frame, &stats);
        serde_json::to_string(&a).map_err(sim_err)
    }

    /// The oedometric sample measured now (the piston's pressure and height, the void ratio
    /// between floor and piston, the particle stress, the coordination) as JSON, with
    /// `settled` recorded as given; an error without a piston.
    #[pyo3(signature = (settled = false))]
    fn compression_point_json(&self, py: Python<'_>, settled: bool) -> PyResult<String> {
        let mut sim = self.lock()?;
        let Sim { engine, pool, scene, .. } = &mut *sim;
        let engine = &mut **engine;
        let point = py.detach(move || pool.install(move || -> anyhow::Result<_> {
            let stats = engine.stats()?;
            if stats.piston.is_none() {
                anyhow::bail!("the scene has no piston, so no compression point; fix: add a [[wall]] of type = \"piston\"");
            }
            Ok(grains::protocol::compression_point(scene, engine, &stats, settled)?)
        }))
        .map_err(sim_err)?;
        serde_json::to_string(&point).map_err(sim_err)
    }

    /// Writes a checkpoint of the run as it stands into `dir` (default: the output
    /// directory), which `grains run --resume DIR` and `Simulation.resume(dir)` continue; a
    /// scene that is not its file's text is written beside it as `scene.toml`.
    #[pyo3(signature = (dir = None))]
    fn save_checkpoint(&self, py: Python<'_>, dir: Option<PathBuf>) -> PyResult<PathBuf> {
        let mut sim = self.lock()?;
        let dir = match dir.or_else(|| sim.out.clone()) {
            Some(d) => d,
            None => return Err(PyValueError::new_err("no directory: the simulation has no `out`; fix: give save_checkpoint(dir)")),
        };
        let Sim { engine, pool, run, guard, scene_file, scene_text, out, .. } = &mut *sim;
        let (engine, dir_ref) = (&mut **engine, &dir);
        py.detach(move || pool.install(move || -> anyhow::Result<()> {
            let dir = dir_ref;
            let progress = run.as_ref().map_or(&*guard, |r| r.progress()).clone();
            if out.as_deref() == Some(dir.as_path()) && let Some(run) = run.as_mut() {
                return run.checkpoint(engine);
            }
            std::fs::create_dir_all(dir)?;
            // The scene's file while it still holds the run's text, else a copy beside the checkpoint.
            let file = if std::fs::read_to_string(&scene_file).ok().as_deref() == Some(scene_text.as_str()) {
                scene_file.clone()
            } else {
                let f = dir.join("scene.toml");
                std::fs::write(&f, &scene_text)?;
                f
            };
            let header = CheckpointHeader { identity: grains::runner::identity_of(&file, scene_text.as_bytes(), engine), progress, files: Vec::new() };
            grains::checkpoint::write(&dir.join(grains::checkpoint::FILE), &header, &engine.save()?)
        }))
        .map_err(sim_err)?;
        Ok(dir.join(grains::checkpoint::FILE))
    }

    /// The summary of the finished run as JSON, once its last stage has run.
    fn summary_json(&self) -> PyResult<Option<String>> {
        Ok(self.lock()?.summary.clone())
    }
}

impl Simulation {
    /// The simulation, or an error while a call is running it: waiting would hold the
    /// interpreter's lock that the running call needs for its progress callback and Ctrl-C.
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, Sim>> {
        self.inner.try_lock().map_err(|e| match e {
            std::sync::TryLockError::WouldBlock => SimulationError::new_err("the simulation is running a call already (this one came from its progress callback or another thread); fix: call it once that call has returned"),
            std::sync::TryLockError::Poisoned(_) => SimulationError::new_err("an earlier call panicked inside the engine; fix: start a new Simulation"),
        })
    }
}

impl Sim {
    /// The grains now, with their contacts when `contacts`.
    fn frame(&mut self, py: Python<'_>, contacts: bool) -> PyResult<Frame> {
        let Sim { engine, pool, .. } = self;
        let engine = &mut **engine;
        py.detach(move || pool.install(move || engine.frame(contacts))).map_err(sim_err)
    }

    /// The next stage (see [`Simulation::run_stage`]).
    fn next_stage(&mut self, py: Python<'_>) -> PyResult<Option<String>> {
        if let Some(why) = &self.stopped {
            return Err(SimulationError::new_err(format!("the run stopped: {why}; fix: continue it with Simulation.resume(out) from its last checkpoint, or start a new Simulation")));
        }
        let Some(run) = self.run.as_mut() else { return Ok(None) };
        let Sim { engine, pool, scene, on_progress, .. } = self;
        let interrupt = AtomicBool::new(false);
        let mut watch = PyWatch { on_progress: on_progress.as_ref(), interrupt: &interrupt, failed: None };
        // The stage runs on the pool while this (the main) thread waits, looking for Ctrl-C:
        // Python runs its signal handlers on the main thread alone.
        let mut signal = None;
        let result = py.detach(|| {
            let (tx, rx) = std::sync::mpsc::channel();
            pool.in_place_scope(|s| {
                s.spawn(|_| {
                    let r = run.next_stage_watched(scene, engine.as_mut(), &mut watch).map(|r| r.map(serde_json::to_string));
                    // The receiver waits below until this arrives.
                    let _ = tx.send(r);
                });
                loop {
                    match rx.recv_timeout(SIGNAL_CHECK) {
                        Ok(r) => return r,
                        Err(_) if signal.is_none() => {
                            signal = Python::attach(|py| py.check_signals()).err();
                            interrupt.store(signal.is_some(), Ordering::Relaxed);
                        }
                        Err(_) => {}
                    }
                }
            })
        });
        let interrupted = signal.or(watch.failed);
        match result {
            Ok(Some(json)) => json.map(Some).map_err(sim_err),
            Ok(None) => {
                let run = self.run.take().expect("the run is open");
                let Sim { engine, pool, scene, .. } = self;
                let summary = py.detach(|| pool.install(|| run.finish(scene, engine.as_mut()))).map_err(sim_err)?;
                self.summary = Some(serde_json::to_string(&summary).map_err(sim_err)?);
                Ok(None)
            }
            Err(e) => {
                let run = self.run.take().expect("the run is open");
                self.stopped = Some(format!("{e:#}"));
                run.close().map_err(sim_err)?;
                Err(interrupted.unwrap_or_else(|| sim_err(e)))
            }
        }
    }
}

/// How often the main thread looks for Ctrl-C while a stage runs on the pool.
const SIGNAL_CHECK: std::time::Duration = std::time::Duration::from_millis(50);

/// Ctrl-C and the caller's progress callback, at every statistics read of a stage.
struct PyWatch<'a> {
    /// Called as `on_progress(stage, done, total)`.
    on_progress: Option<&'a Py<PyAny>>,
    /// Set by the main thread on Ctrl-C.
    interrupt: &'a AtomicBool,
    /// What the callback raised.
    failed: Option<PyErr>,
}

impl Watch for PyWatch<'_> {
    fn go_on(&mut self) -> anyhow::Result<()> {
        if self.interrupt.load(Ordering::Relaxed) {
            anyhow::bail!("interrupted (Ctrl-C)");
        }
        match &self.failed {
            Some(e) => anyhow::bail!("stopped by the progress callback: {e}"),
            None => Ok(()),
        }
    }
    fn progress(&mut self, stage: &str, done: u64, total: u64) {
        if let (Some(f), None) = (self.on_progress, &self.failed) {
            self.failed = Python::attach(|py| f.call1(py, (stage, done, total)).map(drop)).err();
        }
    }
}

/// Vectors as an (n, 3) array.
fn rows<'py>(py: Python<'py>, v: &[glam::DVec3]) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    PyArray1::from_vec(py, v.iter().flat_map(|p| p.to_array()).collect::<Vec<f64>>()).reshape([v.len(), 3])
}

/// A frame's per-grain arrays, in id order: `ids`, `radii`, `positions`, `velocities`,
/// `angular_velocities`.
fn grain_arrays<'py>(py: Python<'py>, frame: &Frame) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("ids", PyArray1::from_slice(py, &frame.id))?;
    d.set_item("radii", PyArray1::from_slice(py, &frame.radius))?;
    d.set_item("positions", rows(py, &frame.position)?)?;
    d.set_item("velocities", rows(py, &frame.velocity)?)?;
    d.set_item("angular_velocities", rows(py, &frame.angular_velocity)?)?;
    Ok(d)
}

/// The last frame of an MCAP recording (`frames.mcap`): a dict of arrays as
/// `Simulation.state` gives (without `materials` and `forces`), and `time`.
#[pyfunction]
fn last_frame<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let frame = grains::output::mcap::last_frame(&path).map_err(sim_err)?;
    let d = grain_arrays(py, &frame)?;
    d.set_item("time", frame.time)?;
    Ok(d)
}

/// The force-transmission analysis of a finished run's last frame (recorded with contact
/// forces: `output.contact_forces = true`), as `grains analyze RUN --json` prints it, as JSON;
/// no file is written.
#[pyfunction]
fn analyze_run_json(py: Python<'_>, run: PathBuf) -> PyResult<String> {
    let a = py.detach(|| -> anyhow::Result<_> {
        let (summary, scene, frame) = grains::runner::read_finished_run_with_contacts(&run)?;
        Ok(grains::output::network::analyze_scene(&scene, &frame, &grains::runner::last_stage_stats(&summary)?))
    });
    serde_json::to_string(&a.map_err(sim_err)?).map_err(sim_err)
}

/// Bauer's law fitted to compression points (`pressure` Pa, `void_ratio`), with e0 held at
/// `e0` when given: the fit as JSON (`grains fit bauer --json`'s `fit`).
#[pyfunction]
#[pyo3(signature = (pressure, void_ratio, e0 = None))]
fn fit_bauer_json(pressure: Vec<f64>, void_ratio: Vec<f64>, e0: Option<f64>) -> PyResult<String> {
    if pressure.len() != void_ratio.len() {
        return Err(PyValueError::new_err(format!("{} pressures against {} void ratios; fix: give one of each per point", pressure.len(), void_ratio.len())));
    }
    let points: Vec<(f64, f64)> = pressure.into_iter().zip(void_ratio).collect();
    let fit = grains::analysis::fit::fit_bauer(&points, e0, 1.0).map_err(|e| PyValueError::new_err(e.to_string()))?;
    serde_json::to_string(&fit).map_err(sim_err)
}

/// The native layer of the `grains` package.
#[pymodule]
fn _grains(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("GrainsError", py.get_type::<GrainsError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add_class::<Scene>()?;
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(last_frame, m)?)?;
    m.add_function(wrap_pyfunction!(fit_bauer_json, m)?)?;
    m.add_function(wrap_pyfunction!(analyze_run_json, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

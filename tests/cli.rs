//! The `grains` command line: every shipped scene checks, the short ones run with physics
//! checked from the JSON summary, outputs are complete, and bad scenes get a one-line error.

mod common;

use std::path::Path;
use std::process::{Command, Output};

/// Energy change allowed over an elastic two-sphere collision (dt = t_c/50: about 1e-4).
const ELASTIC_ENERGY_TOLERANCE: f64 = 1e-3;
/// Slide-to-roll speed ratio tolerance (see tests/sliding.rs).
const ROLLING_TOLERANCE: f64 = 0.01;

fn grains(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grains")).args(args).env("RUST_BACKTRACE", "0").output().expect("grains runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn shipped_scenes() -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        // Sweep files name a scene; they are not scenes themselves.
        .filter(|p| !p.to_string_lossy().ends_with("_sweep.toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_shipped_scene_checks_with_a_time_step_below_the_safe_limit() {
    let scenes = shipped_scenes();
    assert!(scenes.len() >= 5, "{scenes:?}");
    for p in scenes {
        let o = grains(&["check", p.to_str().unwrap()]);
        assert!(o.status.success(), "{}: {}", p.display(), stderr(&o));
        let scene = common::shipped(p.file_name().unwrap().to_str().unwrap());
        let ts = scene.time_step;
        // Rigid grains (contact dynamics) have no contact time to resolve.
        let rigid = matches!(scene.method, grains::scene::Method::ContactDynamics(_));
        assert!(rigid || ts.dt <= ts.safe_limit(), "{}: dt {} above {}", p.display(), ts.dt, ts.safe_limit());
        let time_scale = if rigid { "rigid grains: no contact time bounds it" } else { "Rayleigh time" };
        assert!(stdout(&o).contains(time_scale) && stdout(&o).contains("memory estimate"), "{}", stdout(&o));
    }
}

fn run_json(scene: &str, extra: &[&str]) -> serde_json::Value {
    let path = common::scene_path(scene);
    let mut args = vec!["run", path.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let o = grains(&args);
    assert!(o.status.success(), "{scene}: {}", stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap_or_else(|e| panic!("{scene}: stdout is not one JSON object ({e}): {}", stdout(&o)))
}

#[test]
fn two_spheres_run_conserves_energy_in_both_precisions() {
    let scene = common::shipped("two_spheres.toml");
    let ke0: f64 = (0..2).map(|i| 0.5 * scene.grains.mass[i] * scene.grains.velocity[i][0].powi(2)).sum();
    for precision in ["f64", "f32"] {
        let j = run_json("two_spheres.toml", &["--precision", precision]);
        for key in ["scene", "backend", "precision", "grains", "steps", "dt", "wall_seconds", "particle_steps_per_second", "stages", "final"] {
            assert!(j.get(key).is_some(), "summary lacks {key}: {j}");
        }
        assert_eq!(j["precision"], precision);
        let ke = j["final"]["kinetic_energy"].as_f64().unwrap();
        println!("{precision}: KE after the collision / before = {:.6}", ke / ke0);
        assert!((ke / ke0 - 1.0).abs() < ELASTIC_ENERGY_TOLERANCE);
    }
}

#[test]
fn sphere_on_plane_run_ends_rolling_at_five_sevenths() {
    let j = run_json("sphere_on_plane.toml", &[]);
    let ke = j["stages"][0]["stats"]["ke_translational"].as_f64().unwrap();
    let m = common::shipped("sphere_on_plane.toml").grains.mass[0];
    let ratio = (2.0 * ke / m).sqrt() / 0.5;
    assert!((ratio / (5.0 / 7.0) - 1.0).abs() < ROLLING_TOLERANCE, "v/v0 = {ratio}");
}

#[test]
fn out_dir_holds_summary_stats_and_frames_that_match_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::scene_path("elastic_gas.toml");
    let o = grains(&["run", path.to_str().unwrap(), "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    let stats = std::fs::read_to_string(dir.path().join("stats.csv")).unwrap();
    let rows: Vec<&str> = stats.lines().collect();
    let steps = summary["steps"].as_u64().unwrap();
    let interval = common::shipped("elastic_gas.toml").stats_interval;
    assert_eq!(rows.len() as u64 - 1, steps.div_ceil(interval), "one row per statistics read");
    // The elastic gas conserves energy: the CSV's first and last rows agree.
    let energy = |row: &str| -> f64 { row.split(',').skip(3).take(3).map(|x| x.parse::<f64>().unwrap()).sum() };
    let (e0, e1) = (energy(rows[1]), energy(rows[rows.len() - 1]));
    assert!((e1 / e0 - 1.0).abs() < ELASTIC_ENERGY_TOLERANCE, "{e0} -> {e1}");
    // The MCAP's last /grains frame holds the final positions; count its messages.
    let bytes = std::fs::read(dir.path().join("frames.mcap")).unwrap();
    let mut frames = 0;
    let mut last = None;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic == "/grains" {
            frames += 1;
            last = Some(serde_json::from_slice::<serde_json::Value>(&m.data).unwrap());
        }
    }
    let last = last.expect("at least one frame");
    assert_eq!(frames, 1, "frame_interval = 0 records one frame per stage");
    assert_eq!(last["position"].as_array().unwrap().len(), 50);
    assert!((last["time"].as_f64().unwrap() - summary["simulated_time"].as_f64().unwrap()).abs() < 1e-12);
}

/// Writes `text` as a scene, checks it, and returns the one line of stderr.
fn refused(name: &str, text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    for cmd in ["check", "run"] {
        let o = grains(&[cmd, path.to_str().unwrap()]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{cmd} {name}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.starts_with("error: ") && err.contains("fix: "), "{err}");
        assert!(err.contains(name), "names the file: {err}");
    }
    let o = grains(&["check", path.to_str().unwrap()]);
    stderr(&o)
}

fn oedometer() -> String {
    std::fs::read_to_string(common::scene_path("oedometer.toml")).unwrap()
}

/// A glass `[[wall]]` table with `keys`, followed by `[model]`.
fn wall(keys: &str) -> String {
    format!("[[wall]]\nmaterial = \"glass\"\n{keys}\n\n[model]")
}

/// A `[[pair]]` table of `materials` (TOML array items) with `keys`, followed by `[model]`.
fn pair(materials: &str, keys: &str) -> String {
    format!("[[pair]]\nmaterials = [{materials}]\n{keys}\n\n[model]")
}

fn two_spheres() -> String {
    std::fs::read_to_string(common::scene_path("two_spheres.toml")).unwrap()
}

#[test]
fn malformed_scenes_get_one_line_naming_the_key_and_the_fix() {
    let base = two_spheres();
    let cases: Vec<(&str, String, &str)> = vec![
        ("unknown_key.toml", base.replace("poisson_ratio = 0.3", "poisson_ratio = 0.3\nfrictoin = 0.5"), "frictoin"),
        ("negative_radius.toml", base.replacen("radius = 5.0e-4", "radius = -5.0e-4", 1), "grain[0].radius"),
        ("missing_material.toml", base.replacen("material = \"glass\"\nradius", "material = \"steel\"\nradius", 1), "grain[0].material"),
        ("dt_above_limit.toml", base.replace("dt = \"auto\"", "dt = 1.0e-4"), "simulation.dt"),
        (
            "grain_in_wall.toml",
            base.replace("[model]", "[[wall]]\ntype = \"plane\"\nmaterial = \"glass\"\npoint = [0.0, 0.0, 1.0e-4]\nnormal = [0.0, 0.0, 1.0]\n\n[model]"),
            "overlaps wall[0]",
        ),
        ("wrong_type.toml", base.replace("duration = 2.5e-3", "duration = \"long\""), "duration"),
        ("unused_parameter.toml", base.replace("damping = \"none\"", "damping = \"none\"\nc_n = 1.0"), "model.c_n"),
        ("speed_threshold.toml", base.replace("[model]", "[model]\nv_slip = 1.0e-3"), "model.v_slip = 0.001: is no longer used"),
        ("seating_above_p0.toml", oedometer().replace("seating_pressure = 1.0e3", "seating_pressure = 2.0e4"), "seating_pressure = 20000: is not below p0"),
        ("two_ke_criteria.toml", oedometer().replace("ke_ratio = 1.0e-3", "ke_ratio = 1.0e-3\nke_per_grain = 1.0e-12"), "ke_ratio"),
        ("plastic_impact.toml", base.replace("poisson_ratio = 0.3", "poisson_ratio = 0.3\nrestitution = 0.0"), "material[0].restitution = 0: must lie in (0, 1]: no dashpot"),
        (
            "tiny_restitution.toml",
            base.replace("poisson_ratio = 0.3", "poisson_ratio = 0.3\nrestitution = 0.0005").replace("damping = \"none\"", "damping = \"restitution\""),
            "material[0].restitution = 0.0005: is below 0.001",
        ),
        ("clamp_without_damping.toml", base.replace("damping = \"none\"", "damping = \"none\"\nlimit_damping = false"), "model.limit_damping"),
        ("plane_spin_nan.toml", base.replace("[model]", &wall("type = \"plane\"\npoint = [0.0, 0.0, -1.0e-3]\nnormal = [0.0, 0.0, 1.0]\nangular_velocity = [1.0, nan, 0.0]")), "wall[0].angular_velocity"),
        ("cylinder_tumbling.toml", base.replace("[model]", &wall("type = \"cylinder\"\ncenter = [0.0, 0.0]\nradius = 0.01\nangular_velocity = [0.0, 2.0, 0.0]")), "wall[0].angular_velocity = [0.0, 2.0, 0.0]: is not along the cylinder's axis (z)"),
        ("box_spinning.toml", base.replace("[model]", &wall("type = \"box\"\nmin = [-0.01, -0.01, -0.01]\nmax = [0.01, 0.01, 0.01]\nangular_velocity = [0.0, 0.0, 1.0]")), "angular_velocity"),
        ("wall_velocity_nan.toml", base.replace("[model]", &wall("type = \"plane\"\npoint = [0.0, 0.0, -1.0e-3]\nnormal = [0.0, 0.0, 1.0]\nvelocity = [nan, 0.0, 0.0]")), "wall[0].velocity"),
        ("wall_name_dotted.toml", base.replace("[model]", &wall("name = \"a.b\"\ntype = \"plane\"\npoint = [0.0, 0.0, -1.0e-3]\nnormal = [0.0, 0.0, 1.0]")), "wall[0].name = \"a.b\": must be a word"),
        ("stage_unknown_wall.toml", base.replace("kind = \"run\"", "kind = \"run\"\nwalls = { gate = { velocity = [0.0, 0.0, 1.0] } }"), "stage[0].walls = \"gate\": names no wall"),
        (
            "stage_moves_piston.toml",
            oedometer().replacen("[[stage]]\n", "[[stage]]\nwalls = { \"wall[2]\" = { velocity = [0.0, 0.0, 1.0] } }\n", 1),
            "stage[0].walls = \"wall[2]\": wall[2] is moved by its controller",
        ),
        (
            "stage_spins_box.toml",
            base.replace("[model]", &wall("name = \"bin\"\ntype = \"box\"\nmin = [-0.01, -0.01, -0.01]\nmax = [0.01, 0.01, 0.01]")).replace("kind = \"run\"", "kind = \"run\"\nwalls = { bin = { angular_velocity = [0.0, 0.0, 1.0] } }"),
            "stage[0].walls.bin.angular_velocity = [0.0, 0.0, 1.0]: is given to a box",
        ),
        ("pair_unknown_material.toml", base.replace("[model]", &pair("\"glass\", \"steel\"", "mu_s = 0.1")), "pair[0].materials = \"steel\": names no [[material]]"),
        ("pair_twice.toml", base.replace("[model]", &pair("\"glass\", \"glass\"", "mu_s = 0.1")).replacen("[model]", &pair("\"glass\", \"glass\"", "mu_s = 0.2"), 1), "names the same pair as pair[0]"),
        ("pair_empty.toml", base.replace("[model]", &pair("\"glass\", \"glass\"", "")), "pair[0] = [\"glass\", \"glass\"]: gives no coefficient"),
        ("pair_restitution.toml", base.replace("[model]", &pair("\"glass\", \"glass\"", "restitution = 1.5")), "pair[0].restitution = 1.5"),
        ("pair_friction.toml", base.replace("[model]", &pair("\"glass\", \"glass\"", "mu_s = -0.1")), "pair[0].mu_s = -0.1"),
        (
            "pair_mu_k_under_mindlin.toml",
            base.replace("[model]", &pair("\"glass\", \"glass\"", "mu_s = 0.3\nmu_k = 0.2")).replace("damping = \"none\"", "damping = \"none\"\ntangential = \"mindlin\""),
            "pair[0].mu_k = 0.2: the Hertz-Mindlin law has one friction coefficient",
        ),
    ];
    for (name, text, key) in cases {
        let err = refused(name, &text);
        println!("{err}");
        assert!(err.contains(key), "{name}: must name {key}: {err}");
    }
}

#[test]
fn a_missing_file_is_one_line_too() {
    let o = grains(&["check", "no/such/scene.toml"]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("no/such/scene.toml") && err.contains("fix: "), "{err}");
}

fn grains_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_grains"));
    c.args(args).env("RUST_BACKTRACE", "0").env("NODEVICE_SELECT", "1");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("grains runs")
}

/// With no Vulkan driver visible (the loader pointed at no ICD), `--backend gpu` is a one-line
/// error saying how to get one, and `--backend auto` runs on the CPU with a notice.
#[test]
fn without_an_adapter_gpu_is_a_clear_error_and_auto_falls_back() {
    let scene = common::scene_path("two_spheres.toml");
    let no_driver = [("VK_ICD_FILENAMES", "/nonexistent.json"), ("VK_DRIVER_FILES", "/nonexistent.json")];
    let o = grains_env(&["run", scene.to_str().unwrap(), "--backend", "gpu"], &no_driver);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let last = err.trim_end().lines().last().unwrap_or("");
    assert!(last.starts_with("error: no GPU adapter") && last.contains("mesa-vulkan-drivers") && last.contains("--backend cpu"), "{err}");
    let o = grains_env(&["run", scene.to_str().unwrap(), "--backend", "auto", "--json"], &no_driver);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).is_empty() || !stderr(&o).contains("error:"), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(j["backend"], "cpu");
    let o = grains_env(&["run", scene.to_str().unwrap(), "--backend", "auto"], &no_driver);
    assert!(stderr(&o).contains("notice: no GPU adapter") && stderr(&o).contains("running on the CPU"), "{}", stderr(&o));
}

#[test]
fn gpu_run_and_compare_from_the_command_line() {
    if common::gpu().is_none() {
        return;
    }
    let scene = common::shipped("two_spheres.toml");
    let ke0: f64 = (0..2).map(|i| 0.5 * scene.grains.mass[i] * scene.grains.velocity[i][0].powi(2)).sum();
    let j = run_json("two_spheres.toml", &["--backend", "gpu"]);
    assert_eq!((j["backend"].as_str(), j["precision"].as_str()), (Some("gpu"), Some("f32")));
    let ke = j["final"]["kinetic_energy"].as_f64().unwrap();
    println!("gpu: KE after the collision / before = {:.6}", ke / ke0);
    assert!((ke / ke0 - 1.0).abs() < ELASTIC_ENERGY_TOLERANCE);
    let path = common::scene_path("elastic_gas.toml");
    let o = grains_env(&["compare", path.to_str().unwrap(), "--steps", "1000", "--checkpoints", "5", "--json"], &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let c: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(c["checkpoints"].as_array().unwrap().len(), 5);
    assert_eq!((c["short_horizon_pass"].as_bool(), c["long_horizon_pass"].as_bool()), (Some(true), Some(true)));
    let o = grains_env(&["run", path.to_str().unwrap(), "--backend", "gpu", "--precision", "f64"], &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("computes in f32"), "{}", stderr(&o));
}

/// A step that makes the run impossibly long is refused by `check` and `run`, naming the step
/// count and the fix; `run --force` is the way past it.
#[test]
fn a_run_that_could_never_finish_is_refused_with_its_step_count() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(common::scene_path("two_spheres.toml")).unwrap();
    let path = dir.path().join("slow.toml");
    std::fs::write(&path, common::edit(&text, &[("dt = \"auto\"", "dt = 1.0e-15")])).unwrap();
    let path = path.to_str().unwrap();
    for args in [vec!["check", path], vec!["run", path]] {
        let o = grains(&args);
        let err = stderr(&o);
        println!("{}: {err}", args[0]);
        assert_eq!(o.status.code(), Some(1), "{}", args[0]);
        assert!(err.contains("simulation.dt = 1e-15") && err.contains("steps") && err.contains("--force") && err.contains("fix:"), "{err}");
    }
    let steps = grains::scene::load(std::path::Path::new(path)).unwrap().max_steps();
    assert!(steps > grains::scene::PRACTICAL_STEPS, "{steps} steps");
}

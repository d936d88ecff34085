//! Sweeps: points run separately (`--only K`, as a cluster's job array would) are gathered by
//! `--gather` as they stand and by a plain `grains sweep`, which runs only what is missing; the table holds each point's
//! parameters and fit; the Slurm script names one task per point.

mod common;

use std::process::Command;

/// A tiny oedometer of the shipped scene's grains and laws (50 grains, four steps).
fn tiny_oedometer() -> String {
    common::edit(
        &std::fs::read_to_string(common::scene_path("oedometer.toml")).unwrap(),
        &[
            ("count = 280", "count = 50"),
            ("radius = 3.75e-3, z_min = 0.0, z_max = 12.0e-3", "radius = 2.5e-3, z_min = 0.0, z_max = 9.0e-3"),
            ("radius = 3.75e-3\n", "radius = 2.5e-3\n"),
            ("z = 13.0e-3", "z = 10.0e-3"),
            ("p_max = 1.6e6", "p_max = 100.0e3"),
            ("duration = 0.1 ", "duration = 0.02 "),
        ],
    )
}

fn grains(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_grains")).args(args).env("RUST_BACKTRACE", "0").output().unwrap()
}

#[test]
fn points_run_apart_are_gathered_and_only_the_missing_one_runs() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), tiny_oedometer()).unwrap();
    let sweep = dir.path().join("mu.toml");
    std::fs::write(&sweep, "scene = \"tiny.toml\"\n[parameters]\n\"material.sand.mu_s\" = [0.2, 0.4, 0.6]\n").unwrap();
    let out = dir.path().join("runs");
    let (s, o) = (sweep.to_str().unwrap(), out.to_str().unwrap());

    let slurm = grains(&["sweep", s, "--out", o, "--emit-slurm"]);
    assert!(slurm.status.success(), "{}", String::from_utf8_lossy(&slurm.stderr));
    let script = std::fs::read_to_string(out.join("sweep.sbatch")).unwrap();
    assert!(script.contains("#SBATCH --array=0-2") && script.contains("--only \"$SLURM_ARRAY_TASK_ID\""), "{script}");

    for k in ["0", "2"] {
        let r = grains(&["sweep", s, "--out", o, "--only", k]);
        assert!(r.status.success(), "point {k}: {}", String::from_utf8_lossy(&r.stderr));
    }
    assert!(!out.join("sweep.csv").exists(), "--only runs one point and gathers nothing");
    let stamp = |k: usize| std::fs::metadata(out.join(format!("point-{k:03}/summary.json"))).unwrap().modified().unwrap();
    let (t0, t2) = (stamp(0), stamp(2));

    let only_gather = grains(&["sweep", s, "--out", o, "--gather", "--json"]);
    assert!(only_gather.status.success(), "{}", String::from_utf8_lossy(&only_gather.stderr));
    let partial: serde_json::Value = serde_json::from_slice(&only_gather.stdout).unwrap();
    assert_eq!(partial["rows"][1]["note"].as_str(), Some("not run yet"), "--gather runs nothing: {}", partial["rows"][1]);
    assert!(partial["rows"][0]["eta"]["value"].as_f64().is_some() && !out.join("point-001/summary.json").exists());

    let g = grains(&["sweep", s, "--out", o, "--json"]);
    assert!(g.status.success(), "{}", String::from_utf8_lossy(&g.stderr));
    let err = String::from_utf8_lossy(&g.stderr);
    assert!(err.contains("point 1: done") && !err.contains("point 0: done") && !err.contains("point 2: done"), "only point 1 runs: {err}");
    assert_eq!((stamp(0), stamp(2)), (t0, t2), "finished points are left alone");
    let table: serde_json::Value = serde_json::from_slice(&g.stdout).unwrap();
    let rows = table["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    for (k, mu) in [0.2, 0.4, 0.6].iter().enumerate() {
        assert_eq!(rows[k]["point"]["values"]["material.sand.mu_s"].as_f64(), Some(*mu));
        println!("mu_s = {mu}: e0 = {}, h_s = {} MPa, eta = {}", rows[k]["e0"], rows[k]["h_s"], rows[k]["eta"]);
        assert!(rows[k]["eta"]["value"].as_f64().is_some(), "point {k} has a Bauer fit: {}", rows[k]);
    }
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    println!("power law: {}", table["power_law"]);
    assert!(table["power_law"]["b"]["value"].as_f64().is_some());
}

#[test]
fn a_bad_parameter_path_is_refused_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), tiny_oedometer()).unwrap();
    let sweep = dir.path().join("bad.toml");
    std::fs::write(&sweep, "scene = \"tiny.toml\"\n[parameters]\n\"material.clay.mu_s\" = [0.2]\n").unwrap();
    let r = grains(&["sweep", sweep.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1));
    assert!(err.contains("material.clay.mu_s") && err.contains("fix:"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

#[test]
fn a_failed_point_is_gathered_with_its_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(common::scene_path("two_spheres.toml"), dir.path().join("two.toml")).unwrap();
    let sweep = dir.path().join("dt.toml");
    // The second point stops as unstable once the spheres touch (any overlap is too much).
    std::fs::write(&sweep, "scene = \"two.toml\"\n[parameters]\n\"simulation.max_overlap\" = [0.2, 1.0e-9]\n").unwrap();
    let out = dir.path().join("runs");
    let g = grains(&["sweep", sweep.to_str().unwrap(), "--out", out.to_str().unwrap(), "--json"]);
    assert_eq!(g.status.code(), Some(1), "a failed point fails the sweep");
    let table: serde_json::Value = serde_json::from_slice(&g.stdout).unwrap();
    let note = table["rows"][1]["note"].as_str().unwrap();
    println!("point 1: {note}");
    assert!(note.starts_with("failed:") && note.contains("simulation.max_overlap"), "{note}");
    assert_ne!(table["rows"][0]["note"].as_str(), Some("not run yet"), "point 0 ran");
}

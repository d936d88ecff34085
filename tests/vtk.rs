//! The VTK files of `grains run --vtk`, read back with VTK's own XML reader (Debian's
//! python3-vtk9, through tests/readers/vtk_read_back.py): every file of every collection
//! opens, the collections' times are the frames' times, and the last frame's points, cells
//! and arrays hold the recorded frame's values to f32 rounding, the grains' summed forces
//! balance the walls' (Newton's third law) and the walls stand where the run put them.

mod common;

use grains::engine::Frame;
use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// Debian's Python, where python3-vtk9 puts VTK (a pyenv or venv `python3` on PATH lacks it).
const DEBIAN_PYTHON: &str = "/usr/bin/python3";

/// Relative rounding of the files' Float32 arrays, with an absolute floor for values near 0.
const F32_ROUNDING: f64 = 1.2e-7;

/// 80 grains poured into a cylinder on a floor, then pressed by the piston: every wall kind,
/// orientation tracked, particle pressures (analysis on) and contacts in the MCAP frames for
/// the comparison.
const SCENE: &str = concat!(r#"
name = "vtk_cylinder"
seed = 3
"#, include_str!("fixtures/sand.toml"), r#"mu_s = 0.5
restitution = 0.5
[[generate]]
material = "sand"
count = 80
diameter = { min = 0.85e-3, max = 1.15e-3 }
region = { shape = "cylinder", center = [0.0, 0.0], radius = 2.5e-3, z_min = 0.0, z_max = 12.0e-3 }
[[wall]]
type = "plane"
material = "sand"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[wall]]
type = "cylinder"
material = "sand"
center = [0.0, 0.0]
radius = 2.5e-3
[[wall]]
type = "piston"
material = "sand"
z = 13.0e-3
[model]
normal = "hertz"
damping = "restitution"
tangential = "mindlin"
[simulation]
gravity = [0.0, 0.0, -9.81]
dt = "auto"
track_orientation = true
[[stage]]
name = "fill"
kind = "fill"
duration = 0.03
[[stage]]
name = "press"
kind = "run"
duration = 0.01
piston_pressure = 50.0
[output]
frame_interval = 2.0e-3
analysis = true
contact_forces = true
"#);

fn frames(path: &Path) -> Vec<Frame> {
    let bytes = std::fs::read(path).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.channel.topic == "/grains")
        .map(|m| serde_json::from_slice(&m.data).unwrap())
        .collect()
}

fn close(vtk: f64, ours: f64, what: &str) {
    assert!((vtk - ours).abs() <= F32_ROUNDING * ours.abs().max(1e-30) + f64::from(f32::MIN_POSITIVE), "{what}: VTK read {vtk:e}, the frame holds {ours:e}");
}

fn tuples(a: &Value) -> Vec<Vec<f64>> {
    a["values"].as_array().unwrap().iter().map(|t| t.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()).collect()
}

#[test]
fn vtk_reads_back_every_frame_and_the_values_written() {
    if !common::reader(DEBIAN_PYTHON, &["-c", "import vtk"], "python3-vtk9") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene_file = dir.path().join("vtk_cylinder.toml");
    std::fs::write(&scene_file, SCENE).unwrap();
    let out = dir.path().join("run");
    let o = Command::new(env!("CARGO_BIN_EXE_grains")).args(["run", scene_file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--vtk"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let vtk = out.join("vtk");
    let pvds: Vec<String> = ["grains", "contacts", "walls"].iter().map(|k| vtk.join(format!("{k}.pvd")).display().to_string()).collect();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/readers/vtk_read_back.py");
    let o = Command::new(DEBIAN_PYTHON).arg(&script).args(&pvds).output().unwrap();
    assert!(o.status.success(), "VTK could not read the files back: {}", String::from_utf8_lossy(&o.stderr));
    let back: Value = serde_json::from_slice(&o.stdout).unwrap();

    // Every frame is in every collection, at its simulated time.
    let recorded = frames(&out.join("frames.mcap"));
    assert!(recorded.len() >= 10, "{} frames", recorded.len());
    for kind in ["grains", "contacts", "walls"] {
        let entries = back[kind]["entries"].as_array().unwrap();
        assert_eq!(entries.len(), recorded.len(), "{kind}.pvd lists {} frames, the run recorded {}", entries.len(), recorded.len());
        for (e, f) in entries.iter().zip(&recorded) {
            assert_eq!(e[0].as_f64().unwrap(), f.time, "{kind}.pvd: a time differs from the frame's");
        }
    }

    let f = recorded.last().unwrap();
    let n = f.position.len();
    let g = &back["grains"]["last"];
    let points = g["points"].as_array().unwrap();
    assert_eq!(points.len(), n);
    assert_eq!(g["verts"].as_array().unwrap().len(), n, "one vertex cell per grain");
    for (p, q) in points.iter().zip(&f.position) {
        for a in 0..3 {
            close(p[a].as_f64().unwrap(), q[a], "position");
        }
    }
    let pd = &g["point_data"];
    assert_eq!(pd["id"]["type"], "int");
    for (k, v) in tuples(&pd["id"]).iter().enumerate() {
        assert_eq!(v[0] as u32, f.id[k]);
    }
    let per_grain = |name: &str, ours: &dyn Fn(usize) -> Vec<f64>| {
        let t = tuples(&pd[name]);
        assert_eq!(t.len(), n, "{name}");
        for (i, v) in t.iter().enumerate() {
            for (x, y) in v.iter().zip(ours(i)) {
                close(*x, y, name);
            }
        }
    };
    per_grain("radius", &|i| vec![f.radius[i]]);
    per_grain("velocity", &|i| f.velocity[i].to_array().to_vec());
    per_grain("angular_velocity", &|i| f.angular_velocity[i].to_array().to_vec());
    per_grain("orientation", &|i| {
        let q = f.orientation.as_ref().unwrap()[i];
        vec![q.w, q.x, q.y, q.z]
    });
    let contacts = f.contacts.as_deref().unwrap();
    per_grain("coordination", &|i| vec![contacts.iter().filter(|c| c.overlap > 0.0 && (c.i as usize == i || c.j as usize == i)).count() as f64]);
    let scene = grains::scene::load(&scene_file).unwrap();
    let bounds = grains::analysis::sample_bounds(&scene, &grains::engine::Stats::default(), f);
    let stresses = grains::analysis::network::particle_stresses(f, &grains::periodic::Periodic::default(), bounds);
    per_grain("particle_pressure", &|i| vec![stresses.pressures[i]]);

    // The contacts: one line per recorded contact, from i's centre to j's.
    let c = &back["contacts"]["last"];
    let lines = c["lines"].as_array().unwrap();
    assert!(contacts.len() >= 10, "{} contacts", contacts.len());
    assert_eq!(lines.len(), contacts.len());
    let cd = &c["cell_data"];
    let cpoints = c["points"].as_array().unwrap();
    for (k, r) in contacts.iter().enumerate() {
        assert_eq!((tuples(&cd["id_i"])[k][0] as u32, tuples(&cd["id_j"])[k][0] as u32), (r.i, r.j));
        close(tuples(&cd["normal_force"])[k][0], r.normal_force, "normal_force");
        close(tuples(&cd["overlap"])[k][0], r.overlap, "overlap");
        let ends: Vec<usize> = lines[k].as_array().unwrap().iter().map(|x| x.as_u64().unwrap() as usize).collect();
        for (end, grain) in ends.iter().zip([r.i, r.j]) {
            for (p, q) in cpoints[*end].as_array().unwrap().iter().zip(f.position[grain as usize].to_array()) {
                close(p.as_f64().unwrap(), q, "contact line end");
            }
        }
        // The tangential force lies across the line and completes the normal part to the force.
        let t = &tuples(&cd["tangential_force"])[k];
        let d: Vec<f64> = (0..3).map(|a| f.position[r.j as usize][a] - f.position[r.i as usize][a]).collect();
        let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        let fmag = r.force.to_array().iter().map(|x| x * x).sum::<f64>().sqrt();
        let along: f64 = (0..3).map(|a| t[a] * d[a] / len).sum();
        assert!(along.abs() <= 1e-5 * fmag, "tangential force along the line: {along:e} N of {fmag:e} N");
        let normal_part: f64 = (0..3).map(|a| r.force[a] * d[a] / len).sum();
        for a in 0..3 {
            let sum = t[a] + normal_part * d[a] / len;
            assert!((sum - r.force[a]).abs() <= 4.0 * F32_ROUNDING * fmag, "normal + tangential: {sum:e} N, the force {:e} N", r.force[a]);
        }
    }

    // Newton's third law: the summed forces on the grains balance the forces on the walls.
    let w = &back["walls"]["last"];
    let wall_of: Vec<usize> = tuples(&w["cell_data"]["wall"]).iter().map(|v| v[0] as usize).collect();
    let wall_force = tuples(&w["cell_data"]["force"]);
    let mut on_walls = [0.0f64; 3];
    for k in 0..3 {
        let polygon = wall_of.iter().position(|&x| x == k).expect("every wall drawn");
        for a in 0..3 {
            on_walls[a] += wall_force[polygon][a];
        }
    }
    let on_grains: Vec<f64> = (0..3).map(|a| tuples(&pd["force"]).iter().map(|v| v[a]).sum()).collect();
    let weight = 9.81 * scene.grains.mass.iter().sum::<f64>();
    assert!(on_walls[2].abs() > 0.1 * weight, "the walls carry {:e} N of the {weight:e} N weight", on_walls[2]);
    for a in 0..3 {
        assert!((on_grains[a] + on_walls[a]).abs() <= 1e-5 * weight, "axis {a}: grains {:e} N, walls {:e} N", on_grains[a], on_walls[a]);
    }

    // The walls where they stand: the floor at z = 0, the cylinder's corners on its radius, the
    // piston at the height stats.csv gives at that step.
    let wpoints: Vec<Vec<f64>> = w["points"].as_array().unwrap().iter().map(|p| p.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()).collect();
    let polys = w["polys"].as_array().unwrap();
    let stats = std::fs::read_to_string(out.join("stats.csv")).unwrap();
    let header: Vec<&str> = stats.lines().next().unwrap().split(',').collect();
    let (tc, zc) = (header.iter().position(|h| *h == "time_s").unwrap(), header.iter().position(|h| *h == "piston_z_m").unwrap());
    let piston_z: f64 = stats.lines().skip(1).map(|l| l.split(',').collect::<Vec<_>>()).find(|c| c[tc].parse::<f64>().unwrap() == f.time).map(|c| c[zc].parse().unwrap()).expect("a stats row at the frame's time");
    for (poly, &k) in polys.iter().zip(&wall_of) {
        for p in poly.as_array().unwrap().iter().map(|x| &wpoints[x.as_u64().unwrap() as usize]) {
            match k {
                0 => close(p[2], 0.0, "floor"),
                1 => close((p[0] * p[0] + p[1] * p[1]).sqrt(), 2.5e-3, "cylinder radius"),
                _ => close(p[2], piston_z, "piston height"),
            }
        }
    }
}

//! LAMMPS files in and out, checked with LAMMPS itself (Debian's `lammps`, /usr/bin/lmp):
//! * LAMMPS writes a data file and a dump of the same atoms; grains reads each as a scene's
//!   grains (`[[read]]`) and both give the same grains, to the bit, with types mapped to
//!   materials by the scene's table.
//! * grains exports a run (`grains export`) as a data file and a dump; LAMMPS reads them
//!   (`read_data`, then `read_dump` over displaced atoms) and writes what it holds
//!   (`write_data`), which equals the frame to the bit.
//! * LIGGGHTS (Debian's `liggghts`) reads the exported data file and its dump reads back as
//!   the frame's grains, to the bit.
//! * Malformed files get one line naming the file, the line and the column.

mod common;

use grains::scene::{self, Scene};
use std::path::Path;
use std::process::Command;

/// Relative difference allowed between a mass grains computes from a data file's density and
/// the mass LAMMPS computed from the same density (one rounding each way of `4/3 pi r^3 rho`).
const MASS_ROUNDING: f64 = 4.0 * f64::EPSILON;

fn lmp(dir: &Path, input: &str) {
    std::fs::write(dir.join("in.lmp"), input).unwrap();
    let o = Command::new("lmp").args(["-in", "in.lmp", "-log", "log.lammps", "-screen", "none"]).current_dir(dir).output().unwrap();
    let log = std::fs::read_to_string(dir.join("log.lammps")).unwrap_or_default();
    assert!(o.status.success() && !log.contains("ERROR"), "LAMMPS failed:\n{}", log.lines().rev().take(5).collect::<Vec<_>>().join("\n"));
}

fn has_lammps() -> bool {
    common::reader("lmp", &["-h"], "lammps")
}

/// A scene that reads `file` in `format`, types 1 and 2 as sand and steel, in a box periodic
/// in x and y with a floor.
fn reading(dir: &Path, name: &str, file: &str, format: &str) -> Scene {
    let text = format!(
        concat!(r#"
"#, include_str!("fixtures/sand.toml"), r#"restitution = 0.5
[[material]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11
poisson_ratio = 0.3
restitution = 0.5
[[read]]
file = "{file}"
format = "{format}"
types = {{ 1 = "sand", 2 = "steel" }}
[periodic]
x = [0.0, 0.01]
y = [0.0, 0.01]
[[wall]]
type = "plane"
material = "steel"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[model]
normal = "hertz"
damping = "restitution"
[simulation]
dt = 1.0e-7
[[stage]]
kind = "run"
duration = 1.0e-6
"#), file = file, format = format
    );
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn lammps_data_and_dump_of_the_same_atoms_read_as_the_same_grains() {
    if !has_lammps() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // 256 atoms of two types on a jittered lattice, moving and spinning.
    lmp(
        dir.path(),
        "units si\natom_style sphere\natom_modify map array\nboundary p p f\nregion box block 0 0.01 0 0.01 0 0.01\ncreate_box 2 box\n\
         lattice sc 1.25e-3\nregion inside block 0 0.01 0 0.01 0.001 0.006 units box\ncreate_atoms 1 region inside\n\
         set type 1 type/fraction 2 0.4 2357\ndisplace_atoms all random 1.0e-4 1.0e-4 1.0e-4 9135 units box\n\
         set type 1 diameter 1.0e-3\nset type 2 diameter 0.8e-3\nset type 1 density 2650\nset type 2 density 7800\n\
         velocity all create 1.0e16 482748 dist gaussian\nset group all omega 1.5 -2.5 3.5\nwrite_data lmp.data\n\
         write_dump all custom lmp.dump id type x y z radius mass vx vy vz omegax omegay omegaz modify format float %.17g\n",
    );
    let from_data = reading(dir.path(), "data.toml", "lmp.data", "lammps-data");
    let from_dump = reading(dir.path(), "dump.toml", "lmp.dump", "lammps-dump");
    let (a, b) = (&from_data.grains, &from_dump.grains);
    assert_eq!(a.len(), 256);
    assert_eq!(a.position, b.position, "positions");
    assert_eq!(a.velocity, b.velocity, "velocities");
    assert_eq!(a.angular_velocity, b.angular_velocity, "angular velocities");
    assert_eq!(a.radius, b.radius, "radii");
    assert_eq!(a.material, b.material, "materials");
    assert!(a.angular_velocity.iter().all(|w| *w == glam::DVec3::new(1.5, -2.5, 3.5)), "LAMMPS set every omega to (1.5, -2.5, 3.5)");
    let steel = a.material.iter().filter(|&&m| m == 1).count();
    assert!((80..130).contains(&steel), "{steel} of 256 atoms are type 2 (steel), LAMMPS was asked for 40%");
    for i in 0..a.len() {
        // Type 2 is the steel of diameter 0.8 mm.
        assert_eq!(a.radius[i], if a.material[i] == 1 { 0.4e-3 } else { 0.5e-3 });
        assert!(((a.mass[i] - b.mass[i]) / b.mass[i]).abs() <= MASS_ROUNDING, "grain {i}: mass {:e} from the density, LAMMPS' {:e}", a.mass[i], b.mass[i]);
    }
}

const RUN: &str = concat!(r#"
"#, include_str!("fixtures/sand.toml"), r#"mu_s = 0.5
restitution = 0.5
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 7.0e7
poisson_ratio = 0.3
mu_s = 0.5
restitution = 0.5
[[generate]]
material = "sand"
count = 40
diameter = { min = 0.85e-3, max = 1.15e-3 }
region = { shape = "box", min = [0.0, 0.0, 0.0], max = [6.0e-3, 6.0e-3, 6.0e-3] }
[[generate]]
material = "glass"
count = 20
diameter = { min = 0.85e-3, max = 1.15e-3 }
region = { shape = "box", min = [0.0, 0.0, 6.0e-3], max = [6.0e-3, 6.0e-3, 10.0e-3] }
[periodic]
x = [0.0, 6.0e-3]
y = [0.0, 6.0e-3]
[[wall]]
type = "plane"
material = "sand"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[model]
normal = "hertz"
damping = "restitution"
tangential = "mindlin"
[simulation]
gravity = [0.0, 0.0, -9.81]
dt = "auto"
[[stage]]
kind = "run"
duration = 0.03
"#);

/// The atoms of a data file LAMMPS wrote, read by grains' reader.
fn lammps_wrote(path: &Path) -> grains::lammps::Atoms {
    grains::lammps::data::read(path).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs [`RUN`] in `d` and exports its last frame as `ours.data` and `ours.dump`.
fn exported_run(d: &Path) -> (Scene, grains::engine::Frame) {
    std::fs::write(d.join("run.toml"), RUN).unwrap();
    let grains = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_grains")).args(args).current_dir(d).output().unwrap();
        assert!(o.status.success(), "grains {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    };
    grains(&["run", "run.toml", "--out", "out"]);
    grains(&["export", "out", "--format", "lammps-data", "--out", "ours.data"]);
    grains(&["export", "out", "--format", "lammps-dump", "--out", "ours.dump"]);
    let frame = grains::output::mcap::last_frame(&d.join("out/frames.mcap")).unwrap();
    assert!(frame.velocity.iter().any(|v| *v != glam::DVec3::ZERO), "the frame holds motion to compare");
    (scene::load(&d.join("run.toml")).unwrap(), frame)
}

#[test]
fn lammps_reads_back_the_data_file_and_the_dump_grains_exports() {
    if !has_lammps() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (scene, frame) = exported_run(d);
    let step = (frame.time / scene.time_step.dt).round() as u64;
    // LAMMPS reads our data file and writes what it holds; then, with every atom moved and
    // stopped, reads our dump's positions and velocities back over them and writes again.
    lmp(
        d,
        &format!(
            "units si\natom_style sphere\natom_modify map array\nboundary p p f\nread_data ours.data\nwrite_data from_data.data\n\
             displace_atoms all move 1.0e-4 2.0e-4 3.0e-4 units box\nvelocity all set 0 0 0\n\
             read_dump ours.dump {step} x y z vx vy vz box no\nwrite_data from_dump.data\n"
        ),
    );
    let (a, b) = (lammps_wrote(&d.join("from_data.data")), lammps_wrote(&d.join("from_dump.data")));
    let n = frame.position.len();
    assert_eq!(a.len(), n);
    // LAMMPS writes its atoms in its own order; match them by id (grain id + 1).
    let index = |atoms: &grains::lammps::Atoms| {
        let mut at = vec![usize::MAX; n];
        for (k, &id) in atoms.id.iter().enumerate() {
            at[(id - 1) as usize] = k;
        }
        at
    };
    let (ia, ib) = (index(&a), index(&b));
    for (i, &grain) in frame.id.iter().enumerate() {
        let g = grain as usize;
        let (ka, kb) = (ia[g], ib[g]);
        assert_eq!(a.position[ka], frame.position[i].to_array(), "grain {g}: position after read_data");
        assert_eq!(a.velocity[ka], frame.velocity[i].to_array(), "grain {g}: velocity after read_data");
        assert_eq!(a.angular_velocity[ka], frame.angular_velocity[i].to_array(), "grain {g}: angular velocity after read_data");
        assert_eq!(a.radius[ka], frame.radius[i], "grain {g}: radius");
        assert_eq!(a.kind[ka], u32::from(scene.grains.material[g]) + 1, "grain {g}: type = material + 1");
        let mass = a.density.as_ref().unwrap()[ka] * 4.0 / 3.0 * std::f64::consts::PI * a.radius[ka].powi(3);
        assert!(((mass - scene.grains.mass[g]) / scene.grains.mass[g]).abs() <= MASS_ROUNDING, "grain {g}: LAMMPS' density gives {mass:e} kg, the scene's mass {:e} kg", scene.grains.mass[g]);
        assert_eq!(b.position[kb], frame.position[i].to_array(), "grain {g}: position after read_dump");
        assert_eq!(b.velocity[kb], frame.velocity[i].to_array(), "grain {g}: velocity after read_dump");
    }
}

/// LIGGGHTS (Debian's `liggghts`) reads the data file grains exports as `atom_style
/// granular` and dumps it (`dump custom`, 17 digits); grains reads that dump back as the
/// frame's grains, to the bit.
#[test]
fn liggghts_reads_our_data_file_and_its_dump_reads_back_as_our_grains() {
    if !common::reader("liggghts", &["-in", "/dev/null", "-log", "none", "-screen", "none"], "liggghts") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (scene, frame) = exported_run(d);
    std::fs::write(
        d.join("in.liggghts"),
        "atom_style granular\natom_modify map array sort 0 0.0\nboundary p p f\nnewton off\ncommunicate single vel yes\nunits si\nread_data ours.data\n\
         dump d all custom 1 theirs.dump id type x y z radius mass vx vy vz omegax omegay omegaz\n\
         dump_modify d format \"%d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\"\nrun 0\n",
    )
    .unwrap();
    let o = Command::new("liggghts").args(["-in", "in.liggghts", "-log", "log.liggghts", "-screen", "none"]).current_dir(d).output().unwrap();
    let log = std::fs::read_to_string(d.join("log.liggghts")).unwrap_or_default();
    assert!(o.status.success() && !log.contains("ERROR"), "LIGGGHTS failed:\n{}", log.lines().rev().take(5).collect::<Vec<_>>().join("\n"));
    let back = reading(d, "theirs.toml", "theirs.dump", "lammps-dump");
    let g = &back.grains;
    for (i, &grain) in frame.id.iter().enumerate() {
        let k = grain as usize;
        assert_eq!(g.position[k], frame.position[i], "grain {k}: position");
        assert_eq!(g.velocity[k], frame.velocity[i], "grain {k}: velocity");
        assert_eq!(g.angular_velocity[k], frame.angular_velocity[i], "grain {k}: angular velocity");
        assert_eq!(g.radius[k], frame.radius[i], "grain {k}: radius");
        assert!(((g.mass[k] - scene.grains.mass[k]) / scene.grains.mass[k]).abs() <= MASS_ROUNDING, "grain {k}: LIGGGHTS' mass {:e} kg, ours {:e} kg", g.mass[k], scene.grains.mass[k]);
    }
}

/// The scene error `text`'s grain file gives, as one line.
fn refusal(file_text: &str, format: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bed.txt"), file_text).unwrap();
    let scene = format!(
        "[[material]]\nname = \"sand\"\ndensity = 2650.0\nyoungs_modulus = 7.0e7\npoisson_ratio = 0.3\n[[read]]\nfile = \"bed.txt\"\nformat = \"{format}\"\ntypes = {{ 1 = \"sand\" }}\n[[stage]]\nkind = \"run\"\nduration = 1.0e-6\n"
    );
    let path = dir.path().join("s.toml");
    std::fs::write(&path, scene).unwrap();
    let e = scene::load(&path).expect_err("the file is malformed").to_string();
    assert_eq!(e.lines().count(), 1, "one line: {e}");
    assert!(e.contains("bed.txt") && e.contains("read[0].") && e.contains("fix:"), "names the files, the key and the fix: {e}");
    e
}

#[test]
fn malformed_lammps_files_get_one_line_naming_the_line_and_the_column() {
    let data = "title\n\n2 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms # sphere\n\n1 1 0.001 2650 0.5 0.5 0.5\n2 1 0.001 2650 0.2 zero 0.5\n";
    let e = refusal(data, "lammps-data");
    assert!(e.contains("line 12, column 6 (y)") && e.contains("`zero` is not a number"), "{e}");
    let e = refusal(&data.replace("Atoms # sphere", "Atoms # atomic"), "lammps-data");
    assert!(e.contains("line 9") && e.contains("atom_style atomic"), "{e}");
    let e = refusal(&data.replace("2 atoms", "3 atoms").replace("zero", "0.5"), "lammps-data");
    assert!(e.contains("3 atoms") && e.contains("holds 2"), "{e}");
    let e = refusal(&data.replace("2 1 0.001", "2 1 0.0").replace("zero", "0.5"), "lammps-data");
    assert!(e.contains("line 12, column 3 (diameter)"), "{e}");
    let e = refusal(&data.replace("2 1 0.001 2650 0.2 zero", "2 2 0.001 2650 0.2 0.5"), "lammps-data");
    assert!(e.contains("atom type 2") && e.contains("add `2 = "), "{e}");

    let dump = "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp ff\n0 1\n0 1\n0 1\nITEM: ATOMS id type x y z radius\n1 1 0.5 0.5 0.5 0.0005\n2 1 0.2 0.5 0.5 5e-4x\n";
    let e = refusal(dump, "lammps-dump");
    assert!(e.contains("line 11, column 6 (radius)") && e.contains("`5e-4x`"), "{e}");
    let e = refusal(&dump.replace(" radius", " mass").replace("5e-4x", "5e-4"), "lammps-dump");
    assert!(e.contains("line 9") && e.contains("no `radius` or `diameter` column"), "{e}");
    let e = refusal(&dump.replace("ITEM: NUMBER OF ATOMS\n2", "ITEM: NUMBER OF ATOMS\n3").replace("5e-4x", "5e-4"), "lammps-dump");
    assert!(e.contains("fewer than its 3 atoms"), "{e}");
}

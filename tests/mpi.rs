//! One run over several processes (`mpirun -np K grains run`, feature `mpi`) against the same
//! run on one process, bit for bit: statistics, frames (with every contact's force and
//! springs) and the final checkpoint, on a pour, an oedometer stage and a gas periodic along
//! every axis (dry and wet), on 2 and 3 processes (the gas on 4: a 2 x 2 grid), f64 and f32; a loaded spring kept through
//! the migration of its grain; liquid moved between grains of different processes in
//! canonical order; bad process counts refused in one line.
//!
//! Run with `cargo test --release --features mpi --test mpi` (needs `mpirun`: Debian
//! openmpi-bin).
#![cfg(feature = "mpi")]

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::cpu::ranks::{Grid, Slabs};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The files of a run that must be equal, byte for byte, on any number of processes (the
/// checkpoint holds the same state, but numbered as the engine that wrote it numbered its
/// grains: [`same_checkpoint`] compares what it restores).
const SAME_FILES: [&str; 3] = ["stats.csv", "stages.csv", "frames.mcap"];

/// The one-process engine restored from each run's checkpoint: the same frame (every grain,
/// contact and spring) and statistics, bit for bit. So a checkpoint written on K processes
/// resumes on one (and on any number: they start from the whole state).
fn same_checkpoint<T: grains::real::Real>(scene: &Path, a: &Path, b: &Path) {
    let scene = grains::scene::load(scene).unwrap();
    let restored = |dir: &Path| {
        let (_, state): (serde_json::Value, _) = grains::checkpoint::read(&dir.join("checkpoint.grains")).unwrap();
        let mut e = CpuEngine::<T>::new(&scene).unwrap();
        e.restore(&state).unwrap();
        let stats = serde_json::to_string(&e.stats().unwrap()).unwrap();
        (e.frame(true).unwrap(), stats)
    };
    let (ra, rb) = (restored(a), restored(b));
    assert!(ra.0 == rb.0, "the checkpoints restore different frames");
    assert_eq!(ra.1, rb.1, "the checkpoints restore different statistics");
}

/// `grains run SCENE --out OUT --precision P` on `ranks` processes (see [`grains`]).
fn run(ranks: usize, scene: &Path, out: &Path, precision: &str) -> Output {
    grains(ranks, &["run", scene.to_str().unwrap(), "--out", out.to_str().unwrap(), "--precision", precision])
}

/// `grains ARGS --threads 1` on `ranks` processes under mpirun (oversubscribed: this machine
/// may have fewer cores); 1 runs it alone.
fn grains(ranks: usize, args: &[&str]) -> Output {
    let grains = env!("CARGO_BIN_EXE_grains");
    let mut cmd = if ranks == 1 {
        Command::new(grains)
    } else {
        let mut c = Command::new("mpirun");
        c.args(["--oversubscribe", "-np", &ranks.to_string(), grains]);
        c
    };
    // CI runs as root, which OpenMPI refuses unless told.
    cmd.args(args).args(["--threads", "1"]).env("OMPI_ALLOW_RUN_AS_ROOT", "1").env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
    cmd.output().expect("mpirun runs (Debian package openmpi-bin)")
}

/// Runs `scene` alone and on each of `ranks` processes, and checks every run's files against
/// the lone run's, byte for byte; returns the lone run's `stats.csv`.
fn same_bits_on(ranks: &[usize], scene: &Path, precision: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let out = |k: usize| dir.path().join(format!("np{k}"));
    let alone = run(1, scene, &out(1), precision);
    assert!(alone.status.success(), "{}", String::from_utf8_lossy(&alone.stderr));
    for &k in ranks {
        let o = run(k, scene, &out(k), precision);
        assert!(o.status.success(), "{k} processes: {}", String::from_utf8_lossy(&o.stderr));
        for f in SAME_FILES {
            let (a, b) = (std::fs::read(out(1).join(f)).unwrap(), std::fs::read(out(k).join(f)).unwrap());
            println!("{} {precision}, {k} processes: {f} {} bytes, {}", scene.file_name().unwrap().to_string_lossy(), b.len(), if a == b { "equal" } else { "DIFFERENT" });
            assert!(a == b, "{f} differs between 1 and {k} processes");
        }
        match precision {
            "f32" => same_checkpoint::<f32>(scene, &out(1), &out(k)),
            _ => same_checkpoint::<f64>(scene, &out(1), &out(k)),
        }
        println!("{precision}, {k} processes: the checkpoints restore the same frame and statistics");
        let summary = |k: usize| -> serde_json::Value { serde_json::from_str(&std::fs::read_to_string(out(k).join("summary.json")).unwrap()).unwrap() };
        assert_eq!(summary(1)["final"], summary(k)["final"], "the summaries' final states differ on {k} processes");
    }
    std::fs::read_to_string(out(1).join("stats.csv")).unwrap()
}

/// The quickstart's pour, shortened, with contact forces in its frames.
fn pour(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(common::scene_path("quickstart.toml")).unwrap();
    let text = common::edit(&text, &[("duration = 0.3 ", "duration = 0.06 "), ("frame_interval = 5.0e-3", "frame_interval = 5.0e-3\ncontact_forces = true")]);
    let path = dir.join("pour.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Oquendo et al.'s oedometer, small and short: 150 grains poured for 20 ms, the piston lowered
/// onto them and one pressure step of 5 ms at 12.5 kPa.
fn oedometer(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(common::scene_path("oedometer.toml")).unwrap();
    let text = common::edit(
        &text,
        &[("count = 280", "count = 150"), ("duration = 0.3", "duration = 0.02"), ("p_max = 1.6e6", "p_max = 12.5e3"), ("seating_pressure = 1.0e3", "# no seating load"), ("duration = 0.1 ", "duration = 0.005 ")],
    );
    let path = dir.join("oedometer.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_pour_gives_the_same_bits_on_one_two_and_three_processes() {
    let dir = tempfile::tempdir().unwrap();
    same_bits_on(&[2, 3], &pour(dir.path()), "f64");
}

#[test]
fn a_pour_in_f32_gives_the_same_bits_on_two_processes() {
    let dir = tempfile::tempdir().unwrap();
    same_bits_on(&[2], &pour(dir.path()), "f32");
}

/// The pour in a box that moves along x at 0.05 m/s (a driven wall): its walls move alike on
/// every process and its work sums over all of them.
#[test]
fn a_pour_in_a_moving_box_gives_the_same_bits_on_two_processes() {
    let dir = tempfile::tempdir().unwrap();
    let path = pour(dir.path());
    let text = common::edit(&std::fs::read_to_string(&path).unwrap(), &[("open_top = true", "open_top = true\nvelocity = [0.05, 0.0, 0.0]")]);
    std::fs::write(&path, text).unwrap();
    let stats = same_bits_on(&[2], &path, "f64");
    let work: f64 = stats.lines().last().unwrap().split(',').nth(7).unwrap().parse().unwrap();
    println!("the moving box's work on the grains: {work:e} J");
    assert!(work != 0.0, "the box pushes the grains");
}

#[test]
fn an_oedometer_stage_gives_the_same_bits_on_one_two_and_three_processes() {
    let dir = tempfile::tempdir().unwrap();
    same_bits_on(&[2, 3], &oedometer(dir.path()), "f64");
}

/// The quickstart's box stretched along x with gravity tilted towards +x: the bed flows
/// across the cut between two processes (along x) while its contacts hold.
fn tilted_pour(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(common::scene_path("quickstart.toml")).unwrap();
    let text = common::edit(
        &text,
        &[
            ("max = [10.0e-3, 10.0e-3, 18.0e-3]", "max = [20.0e-3, 5.0e-3, 18.0e-3]"),
            ("max = [10.0e-3, 10.0e-3, 30.0e-3]", "max = [20.0e-3, 5.0e-3, 30.0e-3]"),
            ("gravity = [0.0, 0.0, -9.81]", "gravity = [4.0, 0.0, -9.81]"),
            ("duration = 0.3 ", "duration = 0.15 "),
            ("frame_interval = 5.0e-3", "frame_interval = 5.0e-3\ncontact_forces = true"),
        ],
    );
    let path = dir.join("tilted.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// The tilted pour on two processes moves grains across the cut while their contacts hold a
/// loaded tangential spring: counted here on one process, frame by frame (every 500
/// steps), as contacts with a spring in two frames in a row whose grain changed slab in
/// between. The two-process run's frames, springs included, are the lone run's.
#[test]
fn grains_migrate_with_loaded_springs_and_keep_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let path = tilted_pour(dir.path());
    let scene = grains::scene::load(&path).unwrap();
    let grid = Grid::new(&scene, 2).unwrap();
    assert_eq!(grid.axes.clone().map(|s| s.count()), [2, 1, 1], "the cut runs across x");
    let mut e = CpuEngine::<f64>::new(&scene).unwrap();
    let side = |f: &grains::engine::Frame, i: u32| grid.owner(f.position[i as usize].to_array());
    let springs = |f: &grains::engine::Frame| -> std::collections::BTreeSet<(u32, u32)> {
        f.contacts.as_ref().unwrap().iter().filter(|c| c.tangential_spring != glam::DVec3::ZERO).map(|c| (c.i, c.j)).collect()
    };
    let mut before = e.frame(true).unwrap();
    let mut migrated = 0;
    for _ in 0..300 {
        e.advance(500).unwrap();
        let after = e.frame(true).unwrap();
        let now = springs(&after);
        migrated += springs(&before).iter().filter(|k| now.contains(k) && [k.0, k.1].iter().any(|&i| side(&before, i) != side(&after, i))).count();
        before = after;
    }
    println!("contacts with a loaded spring through a grain's change of slab: {migrated}");
    /// Far fewer than the bed carries (11 here, the same every run), but enough that a spring
    /// lost in a migration would show in the frames compared below.
    const MIN_MIGRATED: usize = 5;
    assert!(migrated >= MIN_MIGRATED, "the bed must carry loaded contacts across the cut");
    same_bits_on(&[2], &path, "f64");
}

/// A run stopped at a checkpoint inside the oedometer's pressure step on one process (the
/// library, checkpointing at every statistics read) and resumed on two processes ends where
/// the uninterrupted run on one does: the same `stats.csv`, row for row, and final state.
#[test]
fn a_checkpoint_written_on_one_process_resumes_on_two() {
    let dir = tempfile::tempdir().unwrap();
    let path = oedometer(dir.path());
    let text = format!("{}\ncheckpoint_interval = 1.0e-9\n", std::fs::read_to_string(&path).unwrap());
    std::fs::write(&path, &text).unwrap();
    let whole = dir.path().join("whole");
    assert!(run(1, &path, &whole, "f64").status.success());

    let cut = dir.path().join("cut");
    let scene = grains::scene::load(&path).unwrap();
    let mut e = CpuEngine::<f64>::new(&scene).unwrap();
    let id = grains::checkpoint::RunIdentity { scene_file: path.display().to_string(), scene_hash: grains::checkpoint::fnv1a(text.as_bytes()), backend: "cpu".into(), precision: "f64".into() };
    let mut stopper = common::StopAt::new(grains::output::RunRecorder::new(Some(&cut), false).unwrap().with_checkpoints(&cut, id), 250);
    let err = grains::protocol::run(&scene, &mut e, &mut stopper).unwrap_err();
    assert!(err.to_string().contains("stage 1, inside it: true"), "{err}");
    stopper.inner.finish().unwrap();

    let o = grains(2, &["run", "--resume", cut.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = |d: &Path| std::fs::read_to_string(d.join("stats.csv")).unwrap();
    println!("stopped at step {}, resumed on 2 processes: {} rows", e.steps(), rows(&cut).lines().count());
    assert_eq!(rows(&whole), rows(&cut), "the resumed run's statistics are the uninterrupted run's");
    let summary = |d: &Path| -> serde_json::Value { serde_json::from_str(&std::fs::read_to_string(d.join("summary.json")).unwrap()).unwrap() };
    assert_eq!(summary(&whole)["final"], summary(&cut)["final"]);
}

#[test]
fn slabs_narrower_than_the_reach_are_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    // 17 processes: a prime, so slabs along one axis, all too narrow for the reach.
    let o = run(17, &pour(dir.path()), &dir.path().join("out"), "f64");
    let err = String::from_utf8_lossy(&o.stderr);
    let line = err.lines().find(|l| l.starts_with("error: ")).expect("an error line");
    println!("{line}");
    assert!(!o.status.success());
    assert!(line.contains("17 processes cut the grains into slabs along z as narrow as") && line.ends_with("fix: run on fewer processes"), "{line}");
}

#[test]
fn too_many_processes_for_the_slabs_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(common::scene_path("two_spheres.toml")).unwrap();
    let path = dir.path().join("two.toml");
    std::fs::write(&path, text).unwrap();
    let o = run(3, &path, &dir.path().join("out"), "f64");
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{err}");
    assert!(!o.status.success());
    let line = err.lines().find(|l| l.starts_with("error: ")).expect("an error line");
    assert!(line.contains("fix: run on at most 2 processes"), "{line}");
    assert_eq!(err.lines().filter(|l| l.starts_with("error: ")).count(), 1, "rank 0 alone says it");
}

#[test]
fn a_grain_is_held_by_its_owner_and_the_slabs_within_reach() {
    let s = Slabs { axis: 0, cuts: vec![0.0, 1.0], reach: 0.25, skin: 0.05, period: None };
    assert_eq!(s.holders(-1.0), vec![0]);
    assert_eq!(s.holders(-0.1), vec![0, 1]);
    assert_eq!(s.holders(0.0), vec![1, 0]);
    assert_eq!(s.holders(0.5), vec![1]);
    assert_eq!(s.holders(0.9), vec![1, 2]);
    assert_eq!(s.holders(1.2), vec![2, 1]);
    assert_eq!(s.holders(1.3), vec![2]);
}

#[test]
fn cuts_move_to_the_quantiles_unless_a_slab_would_be_too_narrow() {
    let mut s = Slabs { axis: 0, cuts: vec![0.0, 1.0], reach: 0.25, skin: 0.05, period: None };
    let x: Vec<f64> = (0..90).map(|i| i as f64 / 30.0).collect();
    // Midway between the 30th and 31st, the 60th and 61st positions, to round-off.
    let expect = [29.5 / 30.0, 59.5 / 30.0];
    let near = |cuts: &[f64]| cuts.len() == 2 && cuts.iter().zip(expect).all(|(c, e)| (c - e).abs() < 1e-12);
    assert_eq!(s.cut_at_quantiles(x.clone(), 3), Ok(()));
    assert!(near(&s.cuts), "{:?}", s.cuts);
    let crowded: Vec<f64> = x.iter().map(|v| v / 10.0).collect();
    assert!(s.cut_at_quantiles(crowded, 3).is_err_and(|w| (w - 0.1).abs() < 1e-12));
    assert!(near(&s.cuts), "the cuts stay where they were");
}

/// A jostling gas periodic along every axis (Hertz-Mindlin, 1,300 grains in a 14 mm cube,
/// contacts with their forces and springs in the frames): the slabs of 2 or 3 processes form a
/// ring along z, the first of its equally wide axes.
fn periodic_gas(dir: &Path) -> PathBuf {
    let path = dir.join("periodic_gas.toml");
    std::fs::write(&path, periodic_gas_text()).unwrap();
    path
}

/// [`periodic_gas`]'s text: the shared periodic gas, run for 4 ms with frames of its contacts.
fn periodic_gas_text() -> String {
    common::edit(include_str!("fixtures/periodic_gas.toml"), &[("duration = 1.0e-3\n", "duration = 4.0e-3\n\n[output]\nframe_interval = 5.0e-4\ncontact_forces = true\n")])
}

/// Along a wrapping axis the last slab borders the first: grains cross from one to the other
/// through the period's ends, and contacts straddle them, computed with a ghost across the
/// period (counted here on one process); 2 and 3 processes give the lone run's bits.
#[test]
fn slabs_round_a_periodic_axis_give_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let path = periodic_gas(dir.path());
    let scene = grains::scene::load(&path).unwrap();
    let grid = Grid::new(&scene, 3).unwrap();
    let a = (0..3).find(|&a| grid.axes[a].count() == 3).expect("three slabs along one axis");
    let slabs = &grid.axes[a];
    assert_eq!(slabs.period, Some([0.0, 14.0e-3]), "the slabs cut a wrapping axis");
    let last = 2;
    let mut e = CpuEngine::<f64>::new(&scene).unwrap();
    let (mut crossed, mut straddling) = (0, 0);
    let mut before = e.frame(true).unwrap();
    for _ in 0..40 {
        e.advance(50).unwrap();
        let after = e.frame(true).unwrap();
        let side = |f: &grains::engine::Frame, i: usize| slabs.owner(f.position[i][a]);
        crossed += (0..after.position.len()).filter(|&i| [side(&before, i), side(&after, i)] == [0, last] || [side(&before, i), side(&after, i)] == [last, 0]).count();
        straddling += after.contacts.as_ref().unwrap().iter().filter(|c| c.tangential_spring != glam::DVec3::ZERO && (after.position[c.i as usize][a] - after.position[c.j as usize][a]).abs() > 7.0e-3).count();
        before = after;
    }
    println!("grains crossing between the last slab and the first: {crossed}; loaded contacts across the period's ends, summed over 40 frames: {straddling}");
    assert!(crossed > 0 && straddling > 0, "the gas must cross and touch across the period's ends");
    same_bits_on(&[2, 3], &path, "f64");
    let grid = Grid::new(&scene, 4).unwrap();
    assert_eq!(grid.axes.clone().map(|s| s.count()).iter().filter(|&&c| c == 2).count(), 2, "four processes cut the cube into 2 x 2 columns");
    same_bits_on(&[4], &path, "f64");
}

#[test]
fn a_ring_of_slabs_holds_ghosts_across_the_period() {
    let s = Slabs { axis: 0, cuts: vec![1.0, 2.0], reach: 0.25, skin: 0.05, period: Some([0.0, 3.0]) };
    assert_eq!(s.holders(0.1), vec![0, 2], "the last slab borders the first");
    assert_eq!(s.holders(2.9), vec![2, 0]);
    assert_eq!(s.holders(-0.1), vec![2, 0], "positions are taken within the period");
    assert_eq!(s.holders(3.5), vec![0]);
    assert_eq!(s.holders(1.1), vec![1, 0]);
    let two = Slabs { cuts: vec![1.5], ..s.clone() };
    assert_eq!(two.holders(0.1), vec![0, 1], "two slabs border each other twice; a ghost is held once");
    let mut s = s;
    let x: Vec<f64> = (0..90).map(|i| i as f64 / 30.0).collect();
    assert_eq!(s.cut_at_quantiles(x.iter().map(|v| v + 3.0).collect(), 3), Ok(()), "positions a period away cut alike");
    assert!(s.cuts.iter().zip([29.5 / 30.0, 59.5 / 30.0]).all(|(c, e)| (c - e).abs() < 1e-12), "{:?}", s.cuts);
    // A third of the grains below 0.1, a third in [0.15, 0.2): the first slab, [0, 0.123), is
    // too narrow in a ring, where it has a neighbour below; on a line it reaches to -infinity.
    let crowded: Vec<f64> = (0..30).map(|i| i as f64 / 300.0).chain((0..30).map(|i| 0.15 + i as f64 / 600.0)).chain((0..30).map(|i| 1.0 + i as f64 / 15.0)).collect();
    assert!(s.cut_at_quantiles(crowded.clone(), 3).is_err_and(|w| (w - 0.1234).abs() < 1e-3), "the first slab is a slab too in a ring");
    let mut line = Slabs { period: None, ..s };
    assert_eq!(line.cut_at_quantiles(crowded, 3), Ok(()));
}

/// [`periodic_gas`] wetted at its start (w = 0.007) with capillary cohesion: bridges form at
/// new contacts and rupture as the gas jostles, their liquid moving between grains of
/// different processes.
fn wet_periodic_gas(dir: &Path) -> PathBuf {
    let text = common::edit(&periodic_gas_text(), &[("[[stage]]\nkind = \"run\"", "[[stage]]\nkind = \"run\"\nwater_content = 0.007"), ("tangential_damping_ratio = 0.9075", "tangential_damping_ratio = 0.9075\ncohesion = \"capillary\"")]);
    let path = dir.join("wet_periodic_gas.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Liquid bridges that form and rupture between grains of different processes (counted here
/// on one process, frame to frame) move their liquid with the bits of one process: 2 and 3
/// processes give the lone run's statistics (liquid on grains and in bridges among them) and
/// frames (every bridge's volume), byte for byte.
#[test]
fn liquid_bridges_across_the_cuts_give_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let path = wet_periodic_gas(dir.path());
    let scene = grains::scene::load(&path).unwrap();
    let grid = Grid::new(&scene, 3).unwrap();
    let mut e = CpuEngine::<f64>::new(&scene).unwrap();
    e.wet(scene.stages[0].wet_volume.unwrap()).unwrap();
    let bridges = |f: &grains::engine::Frame| -> std::collections::BTreeSet<(u32, u32)> {
        let side = |i: u32| grid.owner(f.position[i as usize].to_array());
        f.contacts.as_ref().unwrap().iter().filter(|c| c.bridge_volume > 0.0 && side(c.i) != side(c.j)).map(|c| (c.i, c.j)).collect()
    };
    let (mut formed, mut ruptured) = (0, 0);
    let mut before = bridges(&e.frame(true).unwrap());
    for _ in 0..40 {
        e.advance(50).unwrap();
        let after = bridges(&e.frame(true).unwrap());
        formed += after.difference(&before).count();
        ruptured += before.difference(&after).count();
        before = after;
    }
    println!("bridges across a cut between 3 slabs, frame to frame over 40 frames: {formed} formed, {ruptured} ruptured");
    assert!(formed > 0 && ruptured > 0, "bridges must form and rupture across the cuts");
    same_bits_on(&[2, 3], &path, "f64");
}

/// Two grains hit a wet third one from both sides in the same step
/// ([`common::three_wet_grains`], as in `tests/reorder.rs`), the left one on process 0, the
/// middle and right ones on process 1, the right one beyond process 0's reach: both bridges form in one step from the middle
/// grain's liquid, the first (by ids: right and middle) found on process 1, the second on
/// process 0, which must take what the first left. On two processes: the lone run's bytes,
/// both bridges and the liquid left on the grains included.
#[test]
fn two_bridges_formed_in_one_step_on_two_processes_take_their_liquid_in_id_order() {
    let text = common::three_wet_grains(6.0e-4) + "[output]\nframe_interval = 1.0e-5\ncontact_forces = true\n";
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("three.toml");
    std::fs::write(&path, text).unwrap();
    let scene = grains::scene::load(&path).unwrap();
    let grid = Grid::new(&scene, 2).unwrap();
    let owners: Vec<usize> = scene.grains.position.iter().map(|p| grid.owner(p.to_array())).collect();
    assert_eq!(owners, vec![1, 0, 1], "the left grain alone on process 0");
    let stats = same_bits_on(&[2], &path, "f64");
    let bridges = |row: &str| row.split(',').nth(20).unwrap().parse::<u32>().unwrap();
    println!("bridges at the end: {}", bridges(stats.lines().last().unwrap()));
    assert!(stats.lines().skip(1).any(|r| bridges(r) == 2), "both bridges must form");
}

#[test]
fn a_grid_of_boxes_holds_ghosts_in_the_boxes_around_the_owner() {
    let axis = |a: usize, cuts: Vec<f64>| Slabs { axis: a, cuts, reach: 0.25, skin: 0.05, period: None };
    let grid = Grid { axes: [axis(0, vec![1.0]), axis(1, vec![1.0]), axis(2, vec![])] };
    assert_eq!(grid.ranks(), 4);
    // Boxes: 0 = (x < 1, y < 1), 1 = (x >= 1, y < 1), 2 = (x < 1, y >= 1), 3 = (x >= 1, y >= 1).
    assert_eq!(grid.owner([0.5, 1.5, 7.0]), 2);
    assert_eq!(grid.holders([0.5, 0.5, 0.0]), vec![0], "inside its box, beyond the reach of the others");
    assert_eq!(grid.holders([0.9, 0.5, 0.0]), vec![0, 1], "near one face");
    assert_eq!(grid.holders([0.9, 1.1, 0.0]), vec![2, 0, 1, 3], "near an edge: the diagonal box too");
    assert!(grid.near([0.9, 1.1, 0.0], 1) && !grid.near([0.5, 1.1, 0.0], 1));
}

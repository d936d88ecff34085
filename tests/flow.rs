//! Inlets and outlets (`grains::flow`): an inlet puts in its rate times the time it has been
//! open within one grain, an outlet counts each grain it takes once, the mass balances, the
//! GPU does what its CPU f32 twin does, and a run resumes bitwise across insertions and
//! removals.

mod common;

use grains::engine::{Engine, Stats};
use grains::output::RunRecorder;
use grains::protocol::{self, Progress};
use grains::scene::Scene;

/// Glass beads (d in [1.8, 2.2] mm) poured from an inlet 30-40 mm up inside a tube of radius
/// 10 mm onto a floor, at `rate` kg/s up to `mass` kg, and taken away by an outlet over the
/// floor's lowest 3 mm (`drain`: whether there is one) every 10 ms; one run stage of
/// `duration` s.
fn rain(rate: f64, mass: f64, drain: bool, duration: f64) -> String {
    let outlet = if drain { "[[outlet]]\nname = \"drain\"\nregion = { shape = \"box\", min = [-0.02, -0.02, -0.01], max = [0.02, 0.02, 3.0e-3] }\ninterval = 0.01\n" } else { "" };
    format!(
        r#"
seed = 7
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
mu_s = 0.5
restitution = 0.5
[[wall]]
name = "floor"
type = "plane"
material = "glass"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[wall]]
name = "tube"
type = "cylinder"
material = "glass"
center = [0.0, 0.0]
radius = 10.0e-3
[[inlet]]
name = "feed"
material = "glass"
diameter = {{ min = 1.8e-3, max = 2.2e-3 }}
region = {{ shape = "cylinder", center = [0.0, 0.0], radius = 8.0e-3, z_min = 30.0e-3, z_max = 40.0e-3 }}
mass_rate = {rate:e}
mass = {mass:e}
velocity = [0.0, 0.0, -0.2]
interval = 0.01
{outlet}
[model]
normal = "hertz"
damping = "restitution"
tangential = "mindlin"
[simulation]
gravity = [0.0, 0.0, -9.81]
dt = "auto"
expected_speed = 1.0
[[stage]]
kind = "run"
duration = {duration:e}
[output]
checkpoint_interval = 1.0e-9
"#
    )
}

/// The heaviest grain an inlet of `rain` can put in (kg): d = 2.2 mm glass.
fn heaviest() -> f64 {
    grains::scene::sphere_mass(1.1e-3, 2500.0)
}

/// Runs `scene` on `engine` a statistics read at a time, handing each read to `each`.
fn each_read(scene: &Scene, engine: &mut dyn Engine, mut each: impl FnMut(&Stats, &dyn Engine)) {
    let mut progress = Progress::start(scene, engine).unwrap();
    let total = scene.max_steps();
    while engine.steps() < total {
        let n = scene.stats_interval.min(total - engine.steps());
        progress.advance(scene, engine, n).unwrap();
        let s = progress.stats(engine).unwrap();
        each(&s, &*engine);
    }
}

/// At every read the inlet has put in `rate x (time open at its last insertion)` less at most
/// one grain (it waits for a whole grain), never more; the grains in play weigh what it put in.
#[test]
fn an_inlet_puts_in_its_rate_times_time_within_one_grain() {
    let rate = 0.01;
    let s = common::parse(&rain(rate, 0.0015, false, 0.2));
    let inlet = &s.inlets[0];
    let mut e: grains::cpu::CpuEngine<f64> = common::engine(&s);
    let (mut reads, mut short) = (0, 0.0f64);
    each_read(&s, &mut e, |st, e| {
        let last = e.steps() / inlet.every * inlet.every;
        let target = rate * last.saturating_sub(inlet.start_step) as f64 * s.time_step.dt;
        let feed = &st.flow[0];
        let exhausted = feed.grains as usize == inlet.grains.len();
        assert!(feed.mass <= target + 1e-15, "t = {}: {} kg in, above the {target} kg due", st.time, feed.mass);
        assert!(exhausted || target - feed.mass < heaviest(), "t = {}: {} kg in, more than a grain short of the {target} kg due", st.time, feed.mass);
        if !exhausted {
            short = short.max(target - feed.mass);
        }
        let f = e.frame(false).unwrap();
        let in_play: f64 = f.id.iter().map(|&i| s.grains.mass[i as usize]).sum();
        assert!((in_play - feed.mass).abs() <= 1e-12 * feed.mass.max(1e-12), "in play {in_play} kg, put in {} kg", feed.mass);
        assert_eq!(f.id.len() as u64, st.grains);
        reads += 1;
    });
    let last = e.stats().unwrap();
    println!("{reads} reads; at most {short:.4e} kg short of rate x time (a grain: up to {:.4e} kg); the reservoir's {} grains ({} kg) all in", heaviest(), s.inlets[0].grains.len(), s.inlets[0].grains.clone().map(|i| s.grains.mass[i as usize]).sum::<f64>());
    let frame = e.frame(false).unwrap();
    assert_eq!(frame.id.len(), s.inlets[0].grains.len(), "after 0.2 s at 0.01 kg/s the 1.5 g reservoir is in");
    assert_eq!(last.grains as usize, frame.id.len());
}

/// Every grain the inlet put in is in play or counted once by the outlet, and the masses
/// balance; no grain the outlet counted is in play.
#[test]
fn an_outlet_counts_each_grain_once() {
    let s = common::parse(&rain(0.02, 0.002, true, 0.35));
    let mut e: grains::cpu::CpuEngine<f64> = common::engine(&s);
    let mut last = None;
    each_read(&s, &mut e, |st, e| {
        let (feed, drain) = (&st.flow[0], &st.flow[1]);
        assert_eq!(feed.grains, drain.grains + st.grains, "t = {}: in {} = out {} + in play {}", st.time, feed.grains, drain.grains, st.grains);
        let f = e.frame(false).unwrap();
        let in_play: f64 = f.id.iter().map(|&i| s.grains.mass[i as usize]).sum();
        assert!((feed.mass - drain.mass - in_play).abs() <= 1e-12 * feed.mass, "t = {}: in {} kg, out {} kg, in play {in_play} kg", st.time, feed.mass, drain.mass);
        last = Some(st.clone());
    });
    let st = last.unwrap();
    println!("in {} ({} kg), out {} ({} kg), in play {}", st.flow[0].grains, st.flow[0].mass, st.flow[1].grains, st.flow[1].mass, st.grains);
    assert!(st.flow[1].grains > st.flow[0].grains / 2, "most of the grains poured reached the floor and left");
    let f = e.frame(false).unwrap();
    assert!(f.position.iter().all(|p| p.z > 3.0e-3), "no grain in play lies in the outlet");
}

/// A flow scene's particle-steps (the summary's speed) count each grain from its insertion to
/// its removal: the grains in play summed over the steps, read a step at a time.
#[test]
fn particle_steps_count_the_grains_in_play() {
    let s = common::parse(&rain(0.02, 0.002, true, 0.35));
    let mut e: grains::cpu::CpuEngine<f64> = common::engine(&s);
    let mut progress = Progress::start(&s, &mut e).unwrap();
    let (mut sum, total) = (0u64, s.max_steps());
    while e.steps() < total {
        sum += e.frame(false).unwrap().id.len() as u64;
        progress.advance(&s, &mut e, 1).unwrap();
    }
    println!("{} grain-steps in play over {total} steps of {} slots", progress.flow.grain_steps, s.grains.len());
    assert!(progress.flow.counts[1].grains > 0, "the outlet must have taken grains out");
    assert_eq!(progress.flow.grain_steps, sum);
}

/// The GPU puts the same grains in at the same places and takes the same ones out as its CPU
/// f32 twin: bitwise on a software adapter.
#[test]
fn inlets_and_outlets_run_on_the_gpu_as_on_the_cpu() {
    let s = common::parse(&rain(0.02, 0.002, true, 0.12));
    let Some(mut g) = common::gpu_engine(&s) else { return };
    let exact = g.adapter().device_type == wgpu::DeviceType::Cpu;
    let mut c: grains::cpu::CpuEngine<f32> = common::engine(&s);
    let (mut sg, mut sc) = (Vec::new(), Vec::new());
    // The counts of each read (the energies are summed in another order on each backend).
    let counts = |st: &Stats| (st.flow.clone(), st.grains, st.contacts, st.wall_contacts, st.rattlers, st.rebuilds);
    each_read(&s, &mut g, |st, _| sg.push(counts(st)));
    each_read(&s, &mut c, |st, _| sc.push(counts(st)));
    let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
    println!("gpu {} grains in play, cpu {}; last counts {:?}", fg.id.len(), fc.id.len(), sc.last().map(|s| &s.0));
    assert_eq!(fg.id, fc.id, "the same grains in play");
    if exact {
        for (k, (a, b)) in sg.iter().zip(&sc).enumerate() {
            assert_eq!(a, b, "read {k}: the same grains in and out, in play, contacts, rattlers and rebuilds");
        }
        assert_eq!((&fg.position, &fg.velocity, &fg.angular_velocity), (&fc.position, &fc.velocity, &fc.angular_velocity));
    } else {
        for (a, b) in fg.position.iter().zip(&fc.position) {
            assert!((*a - *b).length() < 1e-6, "gpu {a} cpu {b}");
        }
    }
}

/// A run stopped at a checkpoint after grains have gone in and out, then resumed, ends on
/// the uninterrupted run's bits and counts (CPU f64, and the GPU where an adapter opens).
#[test]
fn a_run_resumes_bitwise_across_insertions_and_removals() {
    // The inlet pours for 0.2 s: it goes on after the stop at 0.11 s.
    let s = common::parse(&rain(0.02, 0.004, true, 0.14));
    for (name, make) in common::resumable_engines() {
        let mut whole = make(&s).unwrap();
        protocol::run(&s, whole.as_mut(), &mut RunRecorder::new(None, false).unwrap()).unwrap();
        let mut first = make(&s).unwrap();
        // Checkpoints at every read (500 steps): the 60th comes after insertions and removals.
        let mut stopper = common::StopAt::new(RunRecorder::new(None, false).unwrap(), 60);
        protocol::run(&s, first.as_mut(), &mut stopper).unwrap_err();
        let (progress, state) = stopper.saved.unwrap();
        assert!(progress.flow.counts[1].grains > 0 && progress.flow.counts[0].grains > progress.flow.counts[1].grains, "{name}: {:?}", progress.flow);
        println!("{name}: stopped at step {} with {} grains in, {} out", progress.flow.through_step, progress.flow.counts[0].grains, progress.flow.counts[1].grains);
        assert!(progress.flow.counts[0].grains < s.inlets[0].grains.len() as u64, "{name}: the inlet is still pouring");
        let mut resumed = make(&s).unwrap();
        resumed.restore(&state).unwrap();
        protocol::run_from(&s, resumed.as_mut(), &mut RunRecorder::new(None, false).unwrap(), progress).unwrap();
        let (a, b) = (whole.frame(false).unwrap(), resumed.frame(false).unwrap());
        assert_eq!(a.id, b.id, "{name}");
        assert_eq!((&a.position, &a.velocity, &a.angular_velocity), (&b.position, &b.velocity, &b.angular_velocity), "{name}");
        assert_eq!(whole.stats().unwrap(), resumed.stats().unwrap(), "{name}");
        println!("{name}: both end with {} grains in play", a.id.len());
    }
}

/// Inlets and outlets that cannot work are refused in one line naming the key and the fix.
#[test]
fn bad_inlets_and_outlets_are_refused_in_one_line() {
    let base = rain(0.02, 0.002, true, 0.1);
    let cases = [
        (common::edit(&base, &[("mass = 2e-3", "mass = 1e-6")]), "inlet[0].mass"),
        (common::edit(&base, &[("name = \"drain\"", "name = \"feed\"")]), "outlet[0].name"),
        (common::edit(&base, &[("mass_rate = 2e-2", "mass_rate = -1.0")]), "inlet[0].mass_rate"),
        (common::edit(&base, &[("radius = 8.0e-3, z_min", "radius = 0.5e-3, z_min")]), "inlet[0].region"),
        (common::edit(&base, &[("material = \"glass\"\ndiameter", "material = \"steel\"\ndiameter")]), "inlet[0].material"),
        (common::edit(&base, &[("interval = 0.01\n\n", "interval = 0.0\n\n")]), "outlet[0].interval"),
        (format!("{base}\n[contact_dynamics]\n").replace("dt = \"auto\"", "method = \"contact_dynamics\"\ndt = 1.0e-4"), "simulation.method"),
    ];
    for (text, key) in cases {
        let err = grains::scene::parse(std::path::Path::new("rain.toml"), &text).expect_err(key).to_string();
        println!("{err}");
        assert!(err.contains(key) && err.contains("fix") && !err.contains('\n'), "{key}: {err}");
    }
}

//! DMT adhesion (`normal = "dmt"`, src/model/normal/dmt.rs) against LAMMPS' `pair granular`
//! normal model `dmt` on the same two-sphere approach and separation (Debian's `lammps`,
//! /usr/bin/lmp), against the law's own equilibrium, and on the GPU against the CPU f32 twin.

mod common;

use grains::compare::largest_component_difference;
use grains::cpu::CpuEngine;
use grains::engine::Engine;
use std::path::Path;
use std::process::Command;

/// The pair: glass spheres of R = 0.5 mm (R_eff = 0.25 mm), E = 70 MPa, nu = 0.3, meeting at
/// 0.1 m/s from a gap of 4 um, surface energy 0.5 J/m^2: a pull-off of
/// 4 pi gamma R_eff = 1.571e-3 N, about a third of the largest push.
const R: f64 = 5.0e-4;
const RHO: f64 = 2650.0;
const E: f64 = 7.0e7;
const NU: f64 = 0.3;
const GAMMA: f64 = 0.5;
const X0: f64 = 5.02e-4;
const V0: f64 = 0.05;
const DT: f64 = 1.0e-7;
const STEPS: usize = 3000;

/// Force on the left sphere at each step, grains against LAMMPS, as a fraction of the pull-off:
/// the same velocity Verlet on the same law leaves f64 round-off and the digits LAMMPS prints
/// (15 significant) over the contact's 870 steps (4e-15 seen).
const FORCE_TOLERANCE: f64 = 1e-9;
/// The force against the law's curve `4/3 V_eff sqrt(R_eff) h^(3/2) - 4 pi gamma R_eff` at
/// the overlap each code reached, relative to the pull-off: f64 round-off.
const CURVE_TOLERANCE: f64 = 1e-9;

fn pull_off() -> f64 {
    4.0 * std::f64::consts::PI * GAMMA * R / 2.0
}

/// The law's force on the left sphere (N, +x: towards its partner) at overlap `h` (m).
fn law_force_on_left(h: f64) -> f64 {
    let v_eff = E / (1.0 - NU * NU) / 2.0;
    -(4.0 / 3.0 * v_eff * (R / 2.0).sqrt() * h.powf(1.5) - pull_off())
}

/// One sample per step: the overlap (m) and the force on the left sphere along x (N).
type Curve = Vec<(f64, f64)>;

fn two_spheres(model: &str) -> String {
    format!(
        r#"
[[material]]
name = "glass"
density = {RHO}
youngs_modulus = {E}
poisson_ratio = {NU}
[[grain]]
material = "glass"
radius = {R}
position = [-{X0}, 0.0, 0.0]
velocity = [{V0}, 0.0, 0.0]
[[grain]]
material = "glass"
radius = {R}
position = [{X0}, 0.0, 0.0]
velocity = [-{V0}, 0.0, 0.0]
[model]
{model}
[simulation]
gravity = [0.0, 0.0, 0.0]
dt = {DT:e}
[[stage]]
kind = "run"
duration = {:e}
"#,
        DT * STEPS as f64
    )
}

fn grains_curve() -> Curve {
    let scene = common::parse(&two_spheres(&format!("normal = \"dmt\"\nsurface_energy = {GAMMA}\ndamping = \"none\"")));
    let mut e: CpuEngine<f64> = common::engine(&scene);
    (0..STEPS)
        .map(|_| {
            e.step().unwrap();
            let b = e.bodies();
            let h = 2.0 * R - (b[1].pos - b[0].pos).norm();
            let f = e.frame(true).unwrap().contacts.unwrap().first().map_or(0.0, |c| c.force[0]);
            (h, f)
        })
        .collect()
}

/// The same approach in LAMMPS: `pair_coeff * * dmt E eta_n0 nu gamma` with no damping
/// (`eta_n0 = 0`) and no friction, velocity Verlet (`fix nve/sphere`), one line per step.
fn lammps_curve(dir: &Path) -> Curve {
    let input = format!(
        "units si\natom_style sphere\natom_modify map array\nboundary f f f\ncomm_modify vel yes\n\
         region box block -0.002 0.002 -0.002 0.002 -0.002 0.002\ncreate_box 1 box\n\
         create_atoms 1 single -{X0} 0 0\ncreate_atoms 1 single {X0} 0 0\n\
         set atom * diameter {}\nset atom * density {RHO}\nvelocity all set 0 0 0\nset atom 1 vx {V0}\nset atom 2 vx -{V0}\n\
         pair_style granular\npair_coeff * * dmt {E} 0.0 {NU} {GAMMA} tangential linear_nohistory 0.0 0.0\n\
         neighbor 1.0e-4 bin\nfix 1 all nve/sphere\ntimestep {DT:e}\n\
         variable x1 equal x[1]\nvariable x2 equal x[2]\nvariable f1 equal fx[1]\n\
         fix p all print 1 \"${{x1}} ${{x2}} ${{f1}}\" file curve.txt screen no\nthermo 1000000\nrun {STEPS}\n",
        2.0 * R
    );
    std::fs::write(dir.join("in.lmp"), input).unwrap();
    let o = Command::new("lmp").args(["-in", "in.lmp", "-log", "log.lammps", "-screen", "none"]).current_dir(dir).output().unwrap();
    assert!(o.status.success(), "lmp failed: {}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(dir.join("curve.txt")).unwrap();
    // The first line is the header, the second the state before the first step.
    text.lines()
        .skip(2)
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            (2.0 * R - (v[1] - v[0]), v[2])
        })
        .collect()
}

/// The largest departure of a curve's forces in contact from the law's, over the pull-off.
fn off_the_law(curve: &Curve) -> f64 {
    curve.iter().filter(|(h, _)| *h > 0.0).map(|&(h, f)| (f - law_force_on_left(h)).abs() / pull_off()).fold(0.0, f64::max)
}

/// The most tensile pull on the left sphere over the run (N, positive towards its partner).
fn strongest_pull(curve: &Curve) -> f64 {
    curve.iter().map(|c| c.1).fold(0.0, f64::max)
}

/// The pair meets, is pulled in, pushes back and parts: grains' force-distance curve is
/// LAMMPS', step by step and at every overlap, and both pull off at 4 pi gamma R_eff.
#[test]
fn dmt_approach_and_separation_follow_lammps_pair_granular_dmt() {
    if !common::reader("lmp", &["-h"], "lammps") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (ours, theirs) = (grains_curve(), lammps_curve(dir.path()));
    assert_eq!(ours.len(), theirs.len());
    let worst_step = ours.iter().zip(&theirs).map(|(a, b)| (a.1 - b.1).abs() / pull_off()).fold(0.0, f64::max);
    let in_contact = ours.iter().filter(|c| c.0 > 0.0).count();
    let (pull_ours, pull_theirs) = (strongest_pull(&ours), strongest_pull(&theirs));
    let push = -ours.iter().map(|c| c.1).fold(0.0, f64::min);
    println!(
        "{in_contact} steps in contact; force per step differs from LAMMPS by {worst_step:.2e} of the pull-off; off the law: grains {:.2e}, LAMMPS {:.2e}; strongest pull {pull_ours:.6e} N (LAMMPS {pull_theirs:.6e}, 4 pi gamma R_eff {:.6e}); strongest push {push:.4e} N",
        off_the_law(&ours),
        off_the_law(&theirs),
        pull_off()
    );
    assert!(in_contact > 500 && ours.last().unwrap().0 < 0.0, "the pair meets and parts");
    assert!(worst_step < FORCE_TOLERANCE, "grains and LAMMPS part ways: {worst_step:e}");
    assert!(off_the_law(&ours) < CURVE_TOLERANCE && off_the_law(&theirs) < CURVE_TOLERANCE);
    // The strongest pull is the pull-off less Hertz's push at the shallowest overlap sampled.
    for pull in [pull_ours, pull_theirs] {
        assert!((pull / pull_off() - 1.0).abs() < 1e-3, "pull-off {pull:e} N");
    }
    assert!((pull_ours / pull_theirs - 1.0).abs() < FORCE_TOLERANCE);
}

/// Damped, the pair comes to rest where Hertz's push balances the pull-off:
/// `4/3 V_eff sqrt(R_eff) h^(3/2) = 4 pi gamma R_eff`, with the no-pull clamp on (the default)
/// and off: the clamp holds the Hertz and dashpot force, not the adhesion.
#[test]
fn a_damped_dmt_pair_rests_where_hertz_balances_the_pull_off() {
    /// The overlap at rest against the balance: the dashpot's decay over 5 ms of a 0.15 ms
    /// oscillation leaves round-off.
    const REST_TOLERANCE: f64 = 1e-9;
    let v_eff = E / (1.0 - NU * NU) / 2.0;
    let h_eq = (pull_off() / (4.0 / 3.0 * v_eff * (R / 2.0).sqrt())).powf(2.0 / 3.0);
    for clamp in [true, false] {
        let model = format!("normal = \"dmt\"\nsurface_energy = {GAMMA}\ndamping = \"viscous\"\nc_n = 0.04\nlimit_damping = {clamp}");
        // 2 nm apart, closing at 2 mm/s (the dashpot 0.6 of critical at rest).
        let text = common::edit(&two_spheres(&model), &[(&format!("{X0}"), &format!("{}", R + 1.0e-9)), (&format!("velocity = [{V0}"), "velocity = [1.0e-3"), (&format!("velocity = [-{V0}"), "velocity = [-1.0e-3"), (&format!("dt = {DT:e}"), "dt = \"auto\""), (&format!("duration = {:e}", DT * STEPS as f64), "duration = 5.0e-3")]);
        let scene = common::parse(&text);
        let mut e: CpuEngine<f64> = common::engine(&scene);
        e.advance(scene.max_steps()).unwrap();
        let b = e.bodies();
        let h = 2.0 * R - (b[1].pos - b[0].pos).norm();
        println!("clamp {clamp}: at rest with overlap {h:.9e} m, the balance {h_eq:.9e} m ({:.1e} off)", h / h_eq - 1.0);
        assert!((h / h_eq - 1.0).abs() < REST_TOLERANCE, "clamp {clamp}");
    }
}

/// A dense adhesive gas with Hertz-Mindlin friction and the restitution dashpot in a box, on
/// the GPU against the CPU f32 twin for 300 steps: the pull-off, its friction limit and its
/// energy, contact by contact.
#[test]
fn dmt_runs_on_the_gpu_as_on_the_cpu() {
    /// Positions after 300 steps of a colliding gas, as a fraction of the mean diameter: each
    /// backend's own sqrt, amplified by collisions (tests/gpu.rs's tolerance).
    const F32_POSITION_TOLERANCE: f64 = 1e-5;
    /// The elastic energies' relative difference: f32 sums in another order.
    const F32_ENERGY_TOLERANCE: f64 = 1e-4;
    let pulled = |f: &grains::engine::Frame| f.contacts.as_ref().unwrap().iter().filter(|c| c.overlap > 0.0 && c.normal_force < 0.0).count();
    let scene = common::parse(&common::edit(
        &common::box_gas(1500, 16.0e-3),
        &[
            ("mu_k = 0.4", "mu_k = 0.5\nrestitution = 0.5"),
            ("damping = \"papers\"\ntangential = \"oquendo\"\ntwisting = \"oquendo\"", "normal = \"dmt\"\nsurface_energy = 2.0\ndamping = \"restitution\"\ntangential = \"mindlin\""),
        ],
    ));
    let Some(mut g) = common::gpu_engine(&scene) else { return };
    let mut c: CpuEngine<f32> = common::engine(&scene);
    g.advance(300).unwrap();
    c.advance(300).unwrap();
    let (fg, fc) = (g.frame(true).unwrap(), c.frame(true).unwrap());
    let worst = largest_component_difference(&fg.position, &fc.position);
    let (sg, sc) = (g.stats().unwrap(), c.stats().unwrap());
    println!(
        "positions differ by {:.2e} of a diameter; contacts {} / {}, pulled {} / {}, sliding {} / {}; elastic energy {:.6e} / {:.6e} J",
        worst / 1.0e-3,
        sg.contacts,
        sc.contacts,
        pulled(&fg),
        pulled(&fc),
        sg.sliding,
        sc.sliding,
        sg.elastic_energy,
        sc.elastic_energy
    );
    assert!(sc.contacts > 0 && sc.sliding > 0 && pulled(&fc) > 0, "the gas collides, slides and sticks");
    assert_eq!(pulled(&fg), pulled(&fc));
    assert!(worst / 1.0e-3 < F32_POSITION_TOLERANCE);
    assert_eq!((sg.contacts, sg.sliding), (sc.contacts, sc.sliding));
    assert!((sg.elastic_energy / sc.elastic_energy - 1.0).abs() < F32_ENERGY_TOLERANCE);
}

/// The registry's refusals name the file, the key, the value and the fix: a missing surface
/// energy, one set under another law (naming the law that reads it), an unknown law (listing
/// the registry's), and DMT under contact dynamics' rigid contacts.
#[test]
fn the_normal_laws_registry_refuses_bad_keys_with_the_fix() {
    let refusal = |model: &str| match grains::scene::parse(Path::new("pair.toml"), &two_spheres(model)) {
        Ok(_) => panic!("{model:?} was accepted"),
        Err(e) => e.to_string(),
    };
    let missing = refusal("normal = \"dmt\"");
    assert!(missing.contains("pair.toml") && missing.contains("model.surface_energy = (missing)") && missing.contains("J/m^2"), "{missing}");
    let negative = refusal("normal = \"dmt\"\nsurface_energy = -1.0");
    assert!(negative.contains("model.surface_energy = -1") && negative.contains("positive"), "{negative}");
    let stray = refusal("normal = \"hertz\"\nsurface_energy = 0.5");
    assert!(stray.contains("model.surface_energy") && stray.contains("normal = \"hertz\"") && stray.contains("normal = \"dmt\""), "{stray}");
    let unknown = refusal("normal = \"jkr\"");
    assert!(unknown.contains("model.normal = \"jkr\"") && unknown.contains("\"hertz\", \"linear\" or \"dmt\""), "{unknown}");
    let scene = common::parse(&two_spheres(&format!("normal = \"dmt\"\nsurface_energy = {GAMMA}")));
    let rigid = grains::cd::ContactDynamics::<f64>::new(&scene, Default::default()).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(rigid.contains("adhesive normal law"), "{rigid}");
}

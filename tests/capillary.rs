//! Capillary cohesion (Richefeu et al. (2009) eqs. 1-8): the law against the formula worked by hand, a wet
//! pair that a bridge holds together or lets go at its rupture distance as energy says it
//! should, liquid conserved while bridges break and form, and Richefeu et al.'s wet preparation
//! keeping the liquid's books.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::{Engine, Frame, Stats};
use grains::model::{capillary_force, capillary_potential, decay_length, rupture_distance, CohesionLaw};
use grains::protocol::{Progress, Recorder, StageResult};

/// The law against its formula: round-off.
const FORMULA: f64 = 1e-12;
/// Liquid conserved over a run: round-off of some thousand additions.
const LIQUID_ROUNDOFF: f64 = 1e-12;

#[test]
fn the_capillary_law_matches_the_formula_at_gaps_size_ratios_and_volumes() {
    let kappa = 2.0 * std::f64::consts::PI * 0.0728; // water, theta = 0
    for (ri, rj) in [(5e-4f64, 5e-4f64), (5e-4, 2.5e-4), (3e-4, 6e-4)] {
        for v in [1e-12f64, 1e-11, 5e-11] {
            // By hand: R = sqrt(ri rj), f0 = -kappa R, delta_max = V^(1/3),
            // lambda = 0.9 / sqrt(2) * sqrt((1/ri + 1/rj) / max(ri/rj, rj/ri) * V).
            let f0 = -kappa * (ri * rj).sqrt();
            let dmax = v.cbrt();
            let ratio = if ri > rj { ri / rj } else { rj / ri };
            let lambda = 0.9 / 2f64.sqrt() * ((1.0 / ri + 1.0 / rj) / ratio * v).sqrt();
            assert!((rupture_distance(0.0, v) / dmax - 1.0).abs() < FORMULA);
            assert!((decay_length(0.9, ri, rj, v) / lambda - 1.0).abs() < FORMULA);
            for (delta, expect) in [(-1e-6, f0), (0.0, f0), (0.3 * dmax, f0 * (-0.3 * dmax / lambda).exp()), (dmax, f0 * (-dmax / lambda).exp()), (1.01 * dmax, 0.0)] {
                let got = capillary_force(kappa, 0.0, 0.9, ri, rj, v, delta);
                assert!((got - expect).abs() <= FORMULA * expect.abs(), "R = ({ri}, {rj}), V = {v}, delta = {delta}: {got} vs {expect}");
            }
        }
    }
    // A contact angle shortens kappa by cos(theta) and lengthens the rupture distance by
    // (1 + theta/2); no liquid, no force.
    let theta = 20f64.to_radians();
    assert!((rupture_distance(theta, 1e-11) / ((1.0 + theta / 2.0) * 1e-11f64.cbrt()) - 1.0).abs() < FORMULA);
    assert_eq!(capillary_force(kappa, 0.0, 0.9, 5e-4, 5e-4, 0.0, 0.0), 0.0);
}

/// The bridge's potential energy is the force's: `f = -dU/d(delta)` by central differences
/// at gaps across the whole range (and in contact), continuous at contact, zero at rupture.
#[test]
fn the_capillary_potential_is_minus_the_integral_of_the_force() {
    /// Central differences of a smooth exponential at a step 1e-4 of its decay length.
    const DERIVATIVE: f64 = 1e-6;
    let kappa = 2.0 * std::f64::consts::PI * 0.0728;
    let (ri, rj, v) = (5e-4f64, 3e-4f64, 2e-11f64);
    let u = |delta: f64| capillary_potential(kappa, 0.0, 0.9, ri, rj, v, delta);
    let (dmax, lambda) = (rupture_distance(0.0, v), decay_length(0.9, ri, rj, v));
    let step = 1e-4 * lambda;
    for delta in [-0.5 * dmax, -0.01 * dmax, 0.01 * dmax, 0.3 * dmax, 0.7 * dmax, 0.99 * dmax] {
        let f = capillary_force(kappa, 0.0, 0.9, ri, rj, v, delta);
        let minus_du = -(u(delta + step) - u(delta - step)) / (2.0 * step);
        assert!((minus_du - f).abs() <= DERIVATIVE * f.abs(), "delta = {delta:e}: -dU/d(delta) = {minus_du:e}, f = {f:e}");
    }
    assert!((u(-1e-15) - u(0.0)).abs() <= 1e-9 * u(0.0).abs(), "continuous at contact");
    assert!(u(dmax).abs() <= 1e-12 * u(0.0).abs() && u(1.01 * dmax) == 0.0, "zero at and beyond rupture");
    assert!(u(0.0) < 0.0, "a bridge binds");
}

/// Two grains 10 um apart moving away from each other at `speed` each, wetted at the start
/// with `w` (all of it goes into their one bridge).
fn wet_pair(speed: f64, w: f64) -> grains::scene::Scene {
    common::parse(&format!(
        r#"
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 1.0e8
poisson_ratio = 0.3
restitution = 0.5
[[grain]]
material = "glass"
radius = 5.0e-4
position = [-5.05e-4, 0.0, 0.0]
velocity = [-{speed}, 0.0, 0.0]
[[grain]]
material = "glass"
radius = 5.0e-4
position = [5.05e-4, 0.0, 0.0]
velocity = [{speed}, 0.0, 0.0]
[model]
damping = "restitution"
cohesion = "capillary"
[simulation]
gravity = [0.0, 0.0, 0.0]
dt = 2.0e-7
stats_interval = 50
[[stage]]
kind = "run"
duration = 0.02
water_content = {w}
"#
    ))
}

#[test]
fn a_bridge_holds_a_slow_pair_and_breaks_at_its_rupture_distance_for_a_fast_one() {
    let w = 1e-3;
    let scene = wet_pair(0.0, w);
    let m = scene.grains.mass[0];
    let v_b = w * 2.0 * m / 1000.0;
    let kappa = 2.0 * std::f64::consts::PI * 0.0728;
    let (r, gap0) = (5.0e-4, 1.0e-5);
    let lambda = decay_length(0.9, r, r, v_b);
    let dmax = rupture_distance(0.0, v_b);
    // Work to pull the pair from gap0 to the rupture distance: kappa R lambda (e^-gap0/l - e^-dmax/l).
    let work = kappa * r * lambda * ((-gap0 / lambda).exp() - (-dmax / lambda).exp());
    let escape = (2.0 * work / (m / 2.0)).sqrt() / 2.0; // speed of each grain
    println!("V_b = {v_b:.3e} m^3, rupture distance {dmax:.3e} m, lambda {lambda:.3e} m, escape speed {escape:.4e} m/s per grain");
    for (factor, breaks) in [(0.7, false), (1.3, true)] {
        let scene = wet_pair(factor * escape, w);
        let mut e: CpuEngine<f64> = common::engine(&scene);
        e.wet(scene.stages[0].wet_volume.unwrap()).unwrap();
        let s0 = e.stats().unwrap();
        assert_eq!(s0.bridges, 1, "the one pair is wetted");
        assert!((s0.liquid_in_bridges / v_b - 1.0).abs() < 1e-12);
        let (mut max_gap, mut gap_at_break) = (0.0f64, None);
        let mut last_gap = gap0;
        for _ in 0..100_000 {
            e.step().unwrap();
            let b = e.bodies();
            let gap = (b[1].pos.x - b[0].pos.x) - 2.0 * r;
            max_gap = max_gap.max(gap);
            let s = e.stats().unwrap();
            if s.bridges == 0 && gap_at_break.is_none() {
                gap_at_break = Some((last_gap, gap));
                assert!((s.liquid_on_grains / v_b - 1.0).abs() < 1e-12, "the liquid goes back to the grains");
                break;
            }
            last_gap = gap;
        }
        println!("{factor} x escape: largest gap {max_gap:.4e} m, broke between gaps {gap_at_break:?}");
        match (breaks, gap_at_break) {
            (false, None) => assert!(max_gap < dmax, "held below the rupture distance"),
            (true, Some((before, after))) => assert!(before <= dmax && after > dmax, "breaks on crossing the rupture distance"),
            other => panic!("expected breaks = {breaks}, got {other:?}"),
        }
    }
}

#[test]
fn liquid_is_conserved_while_bridges_break_and_form() {
    let scene = common::wet_gas();
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let total = scene.stages[0].wet_volume.unwrap();
    e.wet(total).unwrap();
    let s0 = e.stats().unwrap();
    let (mut formed_or_broken, mut last) = (0u64, s0.bridges);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        e.advance(100).unwrap();
        let s = e.stats().unwrap();
        formed_or_broken += s.bridges.abs_diff(last);
        last = s.bridges;
        worst = worst.max(((s.liquid_in_bridges + s.liquid_on_grains) / total - 1.0).abs());
    }
    println!("{} bridges at the start, {} now, {formed_or_broken} net changes seen; liquid {total:.4e} m^3 conserved to {worst:.2e}", s0.bridges, last);
    assert!(s0.bridges > 0 && formed_or_broken > 10, "bridges must break and form");
    assert!(worst < LIQUID_ROUNDOFF);
}

/// Checks every statistics read and stage-end frame of a wet run for the liquid's books, from
/// the stage that wets the sample on.
struct LiquidBooks {
    /// The stage that wets the sample, and whether it has started.
    wetting: String,
    open: bool,
    /// Liquid poured (m^3).
    poured: f64,
    /// Largest bridge volume (m^3) and contact angle (rad).
    cap: f64,
    theta: f64,
    /// The last statistics read.
    last: Option<Stats>,
    /// Worst relative gap between the liquid poured and that in bridges and on grains.
    worst: f64,
    /// Statistics at the first read and at each stage end: (bridges, liquid on grains (m^3)).
    marks: Vec<(u64, f64)>,
    /// Bridges checked in the stage-end frames.
    bridges_seen: usize,
}

impl Recorder for LiquidBooks {
    fn stats(&mut self, stage: &str, s: &Stats) -> anyhow::Result<()> {
        self.open |= stage == self.wetting;
        if !self.open {
            return Ok(());
        }
        self.worst = self.worst.max(((s.liquid_in_bridges + s.liquid_on_grains) / self.poured - 1.0).abs());
        if self.last.is_none() {
            self.marks.push((s.bridges, s.liquid_on_grains));
        }
        self.last = Some(s.clone());
        Ok(())
    }
    fn frame(&mut self, f: &Frame) -> anyhow::Result<()> {
        if !self.open {
            return Ok(());
        }
        let s = self.last.as_ref().expect("a statistics read before the stage-end frame");
        let bridged: Vec<_> = f.contacts.as_ref().expect("contact forces are recorded").iter().filter(|c| c.bridge_volume > 0.0).collect();
        let held: f64 = bridged.iter().map(|c| c.bridge_volume).sum();
        assert_eq!(bridged.len() as u64, s.bridges, "every bridge shows in the frame");
        assert!((held / s.liquid_in_bridges - 1.0).abs() < LIQUID_ROUNDOFF, "the frame's bridges hold {held:e} m^3, the statistics count {:e}", s.liquid_in_bridges);
        for c in &bridged {
            assert!(c.bridge_volume <= self.cap * (1.0 + LIQUID_ROUNDOFF), "bridge {}-{} holds {:e} m^3 over the cap {:e}", c.i, c.j, c.bridge_volume, self.cap);
            assert!(-c.overlap <= rupture_distance(self.theta, c.bridge_volume) * (1.0 + FORMULA), "bridge {}-{} stretched past its rupture distance", c.i, c.j);
            assert!(c.normal_force < 0.0 || c.overlap > 0.0, "an open bridge pulls");
        }
        self.bridges_seen += bridged.len();
        self.marks.push((s.bridges, s.liquid_on_grains));
        Ok(())
    }
    fn stage_end(&mut self, _: &StageResult) -> anyhow::Result<()> {
        Ok(())
    }
    fn progress(&mut self, _: &str, _: u64, _: u64) {}
    fn checkpoint(&mut self, _: &Progress, _: &dyn Engine) -> anyhow::Result<()> {
        Ok(())
    }
}

/// Richefeu et al.'s wet preparations (300 grains, stages cut to 20 ms): wet_iso_0pa.toml (compacted
/// dry at 100 Pa, wetted, released) and wet_iso_0pa_wetted_loose.toml (liquid poured on the
/// loose gas, compacted, released). At every statistics read from the wetting on, the liquid
/// in bridges and on grains adds up to what was poured; at each stage end the frame's bridges
/// hold exactly the liquid the statistics count, none over the cap or past its rupture
/// distance.
#[test]
fn the_wet_preparations_keep_every_drop_of_liquid_accounted_for() {
    for name in ["wet_iso_0pa.toml", "wet_iso_0pa_wetted_loose.toml"] {
        let scene = common::parse(&common::edit(
            &std::fs::read_to_string(common::scene_path(name)).unwrap(),
            &[("count = 8000", "count = 300"), ("max = [28.0e-3, 28.0e-3, 28.0e-3]", "max = [9.4e-3, 9.4e-3, 9.4e-3]"), ("duration = 1.0\n", "duration = 2.0e-2\n"), ("analysis = true", "analysis = false")],
        ));
        let wetting = scene.stages.iter().find(|s| s.wet_volume.is_some()).expect("a stage wets the sample");
        let CohesionLaw::Capillary { theta, .. } = scene.model.cohesion else { panic!("a capillary scene") };
        let mut books = LiquidBooks { wetting: wetting.name.clone(), open: false, poured: wetting.wet_volume.unwrap(), cap: scene.bridges.volume_cap, theta, last: None, worst: 0.0, marks: Vec::new(), bridges_seen: 0 };
        let mut e: CpuEngine<f64> = common::engine(&scene);
        let results = grains::protocol::run(&scene, &mut e, &mut books).unwrap();
        let wet_stages = results.len() - scene.stages.iter().position(|s| s.wet_volume.is_some()).unwrap();
        println!(
            "{name}: {} stages ({} steps); (bridges, liquid on grains / poured) at the first wet read {:?} and the wet stage ends {:?}; {} bridges checked; liquid conserved to {:.2e}",
            results.len(),
            results.iter().map(|r| r.steps).sum::<u64>(),
            (books.marks[0].0, books.marks[0].1 / books.poured),
            books.marks[1..].iter().map(|(b, l)| (*b, l / books.poured)).collect::<Vec<_>>(),
            books.bridges_seen,
            books.worst
        );
        assert!(books.worst < LIQUID_ROUNDOFF, "{name}");
        assert_eq!(books.marks.len(), 1 + wet_stages, "{name}: a frame at each stage end");
        assert!(books.marks[0].0 as usize >= scene.grains.len() / 2, "{name}: the pairs within their rupture distance take the liquid ({} bridges)", books.marks[0].0);
        assert!(books.bridges_seen > 0);
    }
}

//! `wall_springs`: the grain-wall contacts' history, kept only for the grains that a wall can
//! reach before the list is next chosen (the candidates), as the pair list keeps only the pairs
//! within the skin. A grain whose position at the last rebuild lies farther than its radius
//! plus the skin from every wall cannot touch one while it moves less than half the skin (the
//! rebuild's trigger) and the walls move less than half the skin (the trigger of a new choice,
//! [`WallSprings::stale`]); its springs would be zero, so they are not kept, and the wall pass
//! does not visit it. Each candidate's entry holds one history block per wall, as the dense
//! array did per grain; the entries sit in slot order, so each run of slots has its own run of
//! entries.

use super::split::ALIGN;
use super::state::Props;
use super::wall_contacts::WallState;
use crate::real::{Real, Vec3};
use crate::walls::WallGeom;

/// No entry: a grain no wall can reach.
pub const NO_ENTRY: u32 = u32::MAX;

/// The candidates' wall springs.
#[derive(Clone, Debug, Default)]
pub struct WallSprings<T> {
    /// Each slot's entry, or [`NO_ENTRY`]; empty without walls.
    pub entry: Vec<u32>,
    /// The first entry of each run of [`ALIGN`] slots (where a thread's part of the slots may
    /// start), and the number of entries last.
    pub run_start: Vec<u32>,
    /// The entries' history blocks, `walls x stride` reals each.
    pub springs: Vec<T>,
    /// The walls' surfaces when the candidates were chosen.
    chosen_at: Vec<WallGeom<T>>,
}

impl<T: Real> WallSprings<T> {
    /// Chooses the candidates: the grains whose position at the last rebuild (`built_at`) is
    /// nearer than their radius plus `skin` to a wall, now. Each keeps its springs from `old`
    /// (whose entries are by the same slots), or starts from zero. `per_grain` reals an entry.
    pub fn choose(built_at: &[Vec3<T>], prop: &[Props<T>], walls: &[WallState<T>], skin: T, per_grain: usize, old: &WallSprings<T>) -> Self {
        if walls.is_empty() {
            return WallSprings::default();
        }
        let mut entry = Vec::with_capacity(built_at.len());
        let mut run_start = Vec::with_capacity(built_at.len().div_ceil(ALIGN) + 1);
        let mut springs = Vec::new();
        let mut count = 0u32;
        for (s, (x, p)) in built_at.iter().zip(prop).enumerate() {
            if s % ALIGN == 0 {
                run_start.push(count);
            }
            if !WallGeom::any_within(walls.iter().map(|w| &w.geom), *x, p.radius + skin) {
                entry.push(NO_ENTRY);
                continue;
            }
            entry.push(count);
            count += 1;
            match old.entry.get(s) {
                Some(&e) if e != NO_ENTRY => springs.extend_from_slice(&old.springs[e as usize * per_grain..(e as usize + 1) * per_grain]),
                _ => springs.resize(springs.len() + per_grain, T::ZERO),
            }
        }
        run_start.push(count);
        WallSprings { entry, run_start, springs, chosen_at: walls.iter().map(|w| w.geom).collect() }
    }

    /// True when a wall has moved half the skin or more since the candidates were chosen, so
    /// that they must be chosen again before the walls' next contacts.
    pub fn stale(&self, walls: &[WallState<T>], skin: T) -> bool {
        let half = skin * T::of(0.5);
        walls.iter().zip(&self.chosen_at).any(|(w, &before)| !(w.geom.moved_since(&before) < half))
    }

    /// Every grain's springs, `per_grain` reals each (zeros where a grain has no entry): the
    /// dense layout of saved states.
    pub fn dense(&self, n: usize, per_grain: usize) -> Vec<T> {
        let mut out = vec![T::ZERO; if self.entry.is_empty() { 0 } else { n * per_grain }];
        for (s, &e) in self.entry.iter().enumerate() {
            if e != NO_ENTRY {
                out[s * per_grain..(s + 1) * per_grain].copy_from_slice(&self.springs[e as usize * per_grain..(e as usize + 1) * per_grain]);
            }
        }
        out
    }

    /// [`Self::choose`] with the springs of a dense array ([`Self::dense`]).
    pub fn from_dense(dense: &[T], built_at: &[Vec3<T>], prop: &[Props<T>], walls: &[WallState<T>], skin: T, per_grain: usize) -> Self {
        let every = WallSprings { entry: (0..built_at.len() as u32).collect(), springs: dense.to_vec(), ..Default::default() };
        Self::choose(built_at, prop, walls, skin, per_grain, &every)
    }

    /// The first entry at or after `slot`, a multiple of [`ALIGN`] or the number of grains
    /// (0 without walls, where there are no entries).
    pub fn first_entry(&self, slot: usize) -> u32 {
        if self.run_start.is_empty() { 0 } else { self.run_start[slot.div_ceil(ALIGN)] }
    }

    /// Number of candidates.
    pub fn candidates(&self) -> usize {
        self.run_start.last().map_or(0, |&c| c as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::CpuEngine;
    use crate::engine::Engine;

    /// 300 grains at rest, no gravity, in a servo box whose walls start 3 mm away and close in
    /// at 1 m/s: they cross half the skin every 50 steps while no grain moves, so the
    /// candidates must be chosen again on the walls' account alone, and then the walls push.
    const SCENE: &str = r#"
seed = 8
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 1.0e8
poisson_ratio = 0.3
mu_s = 0.4
restitution = 0.3
[[generate]]
material = "glass"
count = 300
diameter = { min = 0.8e-3, max = 1.2e-3 }
region = { shape = "box", min = [0.0, 0.0, 0.0], max = [11.0e-3, 11.0e-3, 11.0e-3] }
[[wall]]
type = "servo_box"
material = "glass"
min = [-3.0e-3, -3.0e-3, -3.0e-3]
max = [14.0e-3, 14.0e-3, 14.0e-3]
pressure = 1.0e4
max_speed = 1.0
[model]
damping = "restitution"
tangential = "mindlin"
[simulation]
gravity = [0.0, 0.0, 0.0]
dt = 1.0e-6
[[stage]]
kind = "run"
duration = 1.0e-2
"#;

    /// At every step, every grain that touches a wall has an entry, so its springs are kept
    /// and its contact evaluated: as the walls close in (chosen again on their account) and
    /// while they push the grains.
    #[test]
    fn every_grain_a_wall_touches_has_its_springs_kept() {
        let scene = crate::scene::parse(std::path::Path::new("wall_springs_test.toml"), SCENE).unwrap();
        let mut e = CpuEngine::<f64>::new(&scene).unwrap();
        let (mut rechosen, mut contacts) = (0, 0);
        for step in 0..4500 {
            let (before, rebuilds) = (e.wall_springs.chosen_at.clone(), e.rebuilds);
            e.advance(1).unwrap();
            rechosen += (e.wall_springs.chosen_at != before && e.rebuilds == rebuilds) as u32;
            for (s, (b, p)) in e.body.iter().zip(&e.prop).enumerate() {
                for wall in &e.walls {
                    if wall.geom.frame(b.pos, Vec3::ZERO).1 < p.radius {
                        contacts += 1;
                        assert_ne!(e.wall_springs.entry[s], NO_ENTRY, "step {step}: grain {} touches a wall without an entry", e.id[s]);
                    }
                }
            }
        }
        let (candidates, n) = (e.wall_springs.candidates(), e.body.len());
        println!("{rechosen} choices on the walls' account, {contacts} grain-wall contacts seen, {candidates} candidates of {n} at the end");
        assert!(rechosen > 20, "the walls must have made the candidates stale");
        assert!(contacts > 1000, "the walls must push the grains");
        assert!(candidates < n, "the candidates must be a part of the grains");
    }
}

//! `wall_springs`: the grain-wall contacts' history, kept only for the grains that a wall can
//! reach before the list is next chosen (the candidates), as the pair list keeps only the pairs
//! within the skin. A grain whose position at the last rebuild lies farther than its radius
//! plus the skin from every wall cannot touch one while it moves less than half the skin (the
//! rebuild's trigger) and the walls move less than half the skin (the trigger of a new choice,
//! [`WallSprings::stale`]); its springs would be zero, so they are not kept, and the wall pass
//! does not visit it. Each candidate's entry holds one history block per wall, as the dense
//! array did per grain; the entries sit in slot order, so each run of slots has its own run of
//! entries. Which slots are candidates is one bit per slot (a word per run of [`ALIGN`]
//! slots), and a candidate's entry is its run's first entry plus the candidates before it in
//! the run: an eighth of a byte per grain where an entry index per slot took four.

use super::split::ALIGN;
use crate::state::Props;
use crate::state::WallState;
use crate::real::{Real, Vec3};
use crate::mesh::MeshSurface;
use crate::walls::WallGeom;

/// How far from `wall`'s pivot ([`WallGeom::pivot`]) a point whose distance to it matters
/// lies (m), for a wall that turns ([`WallGeom::moved_since`]): a mesh's farthest corner, or
/// the farthest grain in play (kept at `built_at`, moving less than the skin before the next
/// choice, which dwarfs the kept position's rounding); 0 for a wall that does not turn.
fn reach<T: Real>(wall: &WallState<T>, meshes: &[MeshSurface<T>], built_at: &[Vec3<f32>], prop: &[Props<T>], skin: T) -> T {
    if !wall.turns {
        return T::ZERO;
    }
    let farthest = |points: &mut dyn Iterator<Item = Vec3<T>>, from: Vec3<T>| points.map(|x| (x - from).norm()).fold(T::ZERO, T::max);
    match wall.geom {
        WallGeom::Mesh { mesh, pose } => farthest(&mut meshes[mesh as usize].vertices.iter().copied(), pose.pivot),
        geom => {
            let mut grains = built_at.iter().zip(prop).filter(|(_, p)| p.in_play()).map(|(&at, _)| super::built_at::widen::<T>(at));
            farthest(&mut grains, geom.pivot()) + skin
        }
    }
}

/// One word of candidate bits per run of slots.
const _: () = assert!(ALIGN == u64::BITS as usize);

/// The candidates' wall springs.
#[derive(Clone, Debug, Default)]
pub struct WallSprings<T> {
    /// Bit `s % ALIGN` of word `s / ALIGN` is set when slot `s` is a candidate; empty without
    /// walls.
    pub candidate: Vec<u64>,
    /// The first entry of each run of [`ALIGN`] slots (where a thread's part of the slots may
    /// start), and the number of entries last.
    pub run_start: Vec<u32>,
    /// The entries' history blocks, `walls x stride` reals each.
    pub springs: Vec<T>,
    /// The walls' surfaces when the candidates were chosen.
    chosen_at: Vec<WallGeom<T>>,
    /// How far from its pivot a point that matters to each wall could lie then (m; 0 for a
    /// wall that does not turn, [`reach`]).
    reach: Vec<T>,
    /// Set when a wall started turning since the choice ([`Self::expire`]).
    expired: bool,
}

/// True when slot `m` (counted from a multiple of [`ALIGN`]) is a candidate in `words`, the
/// candidate bits from that slot on.
#[inline(always)]
pub fn is_candidate(words: &[u64], m: usize) -> bool {
    words[m / ALIGN] >> (m % ALIGN) & 1 != 0
}

/// [`WallSprings::first_entry`] from the runs' first entries `run_start`.
#[inline]
pub fn first_entry(run_start: &[u32], slot: usize) -> u32 {
    if run_start.is_empty() { 0 } else { run_start[slot.div_ceil(ALIGN)] }
}

/// Candidates in slot order with their springs: what [`WallSprings::choose`] and
/// [`WallSprings::renumbered`] fill.
struct Builder<T> {
    candidate: Vec<u64>,
    run_start: Vec<u32>,
    springs: Vec<T>,
    count: u32,
}

impl<T: Real> Builder<T> {
    fn new(n: usize) -> Self {
        Builder { candidate: vec![0; n.div_ceil(ALIGN)], run_start: Vec::with_capacity(n.div_ceil(ALIGN) + 1), springs: Vec::new(), count: 0 }
    }

    /// Slot `s` (the next one): a candidate with `springs`, or none.
    fn push(&mut self, s: usize, springs: Option<&[T]>) {
        if s.is_multiple_of(ALIGN) {
            self.run_start.push(self.count);
        }
        if let Some(h) = springs {
            self.candidate[s / ALIGN] |= 1 << (s % ALIGN);
            self.springs.extend_from_slice(h);
            self.count += 1;
        }
    }

    fn finish(mut self, chosen_at: Vec<WallGeom<T>>, reach: Vec<T>) -> WallSprings<T> {
        self.run_start.push(self.count);
        WallSprings { candidate: self.candidate, run_start: self.run_start, springs: self.springs, chosen_at, reach, expired: false }
    }
}

impl<T: Real> WallSprings<T> {
    /// Chooses the candidates: the grains whose position at the last rebuild (`built_at`) is
    /// nearer than their radius plus `skin` to a wall, now. Each keeps its springs from `old`
    /// (whose entries are by the same slots), or starts from zero. `per_grain` reals an entry.
    pub fn choose(built_at: &[Vec3<f32>], prop: &[Props<T>], walls: &[WallState<T>], meshes: &[MeshSurface<T>], skin: T, per_grain: usize, old: &WallSprings<T>) -> Self {
        if walls.is_empty() {
            return WallSprings::default();
        }
        let zeros = vec![T::ZERO; per_grain];
        let mut b = Builder::new(built_at.len());
        for (s, (&at, p)) in built_at.iter().zip(prop).enumerate() {
            // The kept position's rounding ([`super::built_at`]) widens the reach.
            let (x, rounding) = (super::built_at::widen::<T>(at), super::built_at::bound::<T>(at));
            // A grain out of play touches no wall.
            let near = p.in_play() && WallGeom::any_within(walls.iter().map(|w| &w.geom), meshes, x, p.radius + skin + rounding);
            b.push(s, near.then(|| old.springs_of(s, per_grain).unwrap_or(&zeros)));
        }
        let reach = walls.iter().map(|w| reach(w, meshes, built_at, prop, skin)).collect();
        b.finish(walls.iter().map(|w| w.geom).collect(), reach)
    }

    /// The same candidates and springs in new slots: new slot `s` is old slot `from[s]`.
    pub fn renumbered(&self, from: &[u32], per_grain: usize) -> Self {
        if self.candidate.is_empty() {
            return self.clone();
        }
        let mut b = Builder::new(from.len());
        for (s, &o) in from.iter().enumerate() {
            b.push(s, self.springs_of(o as usize, per_grain));
        }
        b.finish(self.chosen_at.clone(), self.reach.clone())
    }

    /// Slot `s`'s entry, where it is a candidate.
    pub fn entry(&self, s: usize) -> Option<usize> {
        let word = *self.candidate.get(s / ALIGN)?;
        let below = word & ((1u64 << (s % ALIGN)) - 1);
        (word >> (s % ALIGN) & 1 != 0).then(|| self.run_start[s / ALIGN] as usize + below.count_ones() as usize)
    }

    /// Slot `s`'s springs, `per_grain` reals, where it is a candidate.
    fn springs_of(&self, s: usize, per_grain: usize) -> Option<&[T]> {
        self.entry(s).map(|e| &self.springs[e * per_grain..(e + 1) * per_grain])
    }

    /// True when a wall has moved half the skin or more since the candidates were chosen, so
    /// that they must be chosen again before the walls' next contacts.
    pub fn stale(&self, walls: &[WallState<T>], skin: T) -> bool {
        if self.expired {
            return true;
        }
        let half = skin * T::of(0.5);
        walls.iter().zip(&self.chosen_at).zip(&self.reach).any(|((w, &before), &reach)| !(w.geom.moved_since(&before, reach) < half))
    }

    /// Marks the choice [`Self::stale`]: a wall has started turning, and the reach its
    /// turns need ([`reach`]) was not measured when the candidates were chosen.
    pub fn expire(&mut self) {
        self.expired = true;
    }

    /// Every grain's springs, `per_grain` reals each (zeros where a grain has no entry): the
    /// dense layout of saved states.
    pub fn dense(&self, n: usize, per_grain: usize) -> Vec<T> {
        if self.candidate.is_empty() {
            return Vec::new();
        }
        let mut out = vec![T::ZERO; n * per_grain];
        for s in 0..n {
            if let Some(h) = self.springs_of(s, per_grain) {
                out[s * per_grain..(s + 1) * per_grain].copy_from_slice(h);
            }
        }
        out
    }

    /// [`Self::choose`] with the springs of a dense array ([`Self::dense`]).
    pub fn from_dense(dense: &[T], built_at: &[Vec3<f32>], prop: &[Props<T>], walls: &[WallState<T>], meshes: &[MeshSurface<T>], skin: T, per_grain: usize) -> Self {
        let mut every = Builder::new(built_at.len());
        for s in 0..built_at.len() {
            every.push(s, dense.get(s * per_grain..(s + 1) * per_grain));
        }
        Self::choose(built_at, prop, walls, meshes, skin, per_grain, &every.finish(Vec::new(), Vec::new()))
    }

    /// The first entry at or after `slot`, a multiple of [`ALIGN`] or the number of grains
    /// (0 without walls, where there are no entries).
    pub fn first_entry(&self, slot: usize) -> u32 {
        first_entry(&self.run_start, slot)
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
                        assert!(e.wall_springs.entry(s).is_some(), "step {step}: grain {} touches a wall without an entry", e.id[s]);
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

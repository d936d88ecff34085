//! The engine's state cut into rows, one per grain and one per pair, keyed by permanent id:
//! what the processes of a distributed run ([`crate::cpu::ranks`]) send one another when grains
//! change hands, and what they gather into the whole state. A set of rows becomes a state
//! again ([`state_of_rows`]) in the checkpoint's format, so that `restore_state` takes it.
//! Also what a distributed driver reads and writes of the engine between the operations of a
//! step ([`super::step::StepHooks`]).

use super::*;
use super::bridges::{move_liquid, BridgeEvent};
use super::wall_sums::WallSums;

/// The per-grain arrays of a checkpoint, in row order, and whether each holds integers.
const GRAIN_ARRAYS: [(&str, bool); 8] = [("body", false), ("load", false), ("residual", false), ("built_at", false), ("image", true), ("orientation", false), ("wall_hist", false), ("liquid", false)];

/// The per-pair arrays of a checkpoint, in row order, and whether each holds integers.
const PAIR_ARRAYS: [(&str, bool); 6] = [("hist", false), ("share", false), ("f_n", false), ("f_c", false), ("pair_flags", true), ("force_i", false)];

/// Values in a row of [`CpuEngine::bridge_rows`].
pub(crate) const BRIDGE_ROW: usize = 6;

/// The arrays that hold one value for the whole engine, not one per grain or pair.
const GLOBAL_ARRAYS: [&str; 14] = ["wall_touch_ids", "wall_touches", "wall_touch_power", "wall_reaction", "wall_count", "wall_power", "piston", "servo", "driven_walls", "wall_turns", "wall_present", "clock", "built_margin", "counters"];

/// Values per grain and per pair of each array of [`GRAIN_ARRAYS`] and [`PAIR_ARRAYS`] (0
/// where the scene keeps none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RowWidths {
    grain: [usize; 8],
    pair: [usize; 6],
}

impl RowWidths {
    /// Values in a grain row: its id, then the arrays.
    pub fn grain_row(&self) -> usize {
        1 + self.grain.iter().sum::<usize>()
    }
    /// Values in a pair row: the owner's and the partner's ids, then the arrays.
    pub fn pair_row(&self) -> usize {
        2 + self.pair.iter().sum::<usize>()
    }
}

/// Grain and pair rows, flat: a grain row is `[id, body.., load.., ..]`, a pair row
/// `[owner id, partner id, hist.., share.., ..]` (owner id < partner id); integers are held
/// exactly as reals (ids below 2^32, images small).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Rows {
    /// Grain rows.
    pub grains: Vec<f64>,
    /// Pair rows.
    pub pairs: Vec<f64>,
}

/// An integer array's value as a real, exactly (signed values are stored as their bits).
fn int_to_real(x: u64) -> f64 {
    x as i64 as f64
}

/// [`int_to_real`] undone.
fn real_to_int(x: f64) -> u64 {
    x as i64 as u64
}

/// Appends item `k` of each array in `names` (reals or ints of `s`, `widths[a]` values each).
fn push_row(out: &mut Vec<f64>, s: &EngineState, names: &[(&str, bool)], widths: &[usize], k: usize) {
    for (&(name, int), &w) in names.iter().zip(widths) {
        if w == 0 {
            continue;
        }
        if int {
            out.extend(s.ints[name][k * w..(k + 1) * w].iter().map(|&x| int_to_real(x)));
        } else {
            out.extend_from_slice(&s.reals[name][k * w..(k + 1) * w]);
        }
    }
}

/// Appends a row's values (after its ids) to the arrays in `names` of `s`.
fn pop_row(s: &mut EngineState, names: &[(&str, bool)], widths: &[usize], mut row: &[f64]) {
    for (&(name, int), &w) in names.iter().zip(widths) {
        let (here, rest) = row.split_at(w);
        row = rest;
        if int {
            s.ints.entry(name.to_string()).or_default().extend(here.iter().map(|&x| real_to_int(x)));
        } else {
            s.reals.entry(name.to_string()).or_default().extend_from_slice(here);
        }
    }
}

impl Rows {
    /// The rows of `s` (a state of an engine with `widths`) of the grains whose permanent id
    /// `keep_grain` accepts and of the pairs (owner id, partner id) `keep_pair` accepts.
    pub fn of_state(s: &EngineState, widths: &RowWidths, keep_grain: impl Fn(u32) -> bool, keep_pair: impl Fn(u32, u32) -> bool) -> Rows {
        let id = &s.ints["id"];
        let mut rows = Rows::default();
        for (slot, &i) in id.iter().enumerate() {
            if keep_grain(i as u32) {
                rows.grains.push(i as f64);
                push_row(&mut rows.grains, s, &GRAIN_ARRAYS, &widths.grain, slot);
            }
        }
        let (starts, partner) = (&s.ints["owner_start"], &s.ints["partner"]);
        for (slot, k) in crate::state::owned_pairs(starts) {
            let (a, b) = (id[slot] as u32, id[partner[k] as usize] as u32);
            if keep_pair(a, b) {
                rows.pairs.extend([a as f64, b as f64]);
                push_row(&mut rows.pairs, s, &PAIR_ARRAYS, &widths.pair, k);
            }
        }
        rows
    }

    /// Adds `other`'s rows after these.
    pub fn append(&mut self, other: &Rows) {
        self.grains.extend_from_slice(&other.grains);
        self.pairs.extend_from_slice(&other.pairs);
    }

    /// Replaces each id in the rows (grains' and both of each pair's) by `to`'s.
    pub fn renumber(&mut self, widths: &RowWidths, to: impl Fn(u32) -> u32) {
        for r in self.grains.chunks_exact_mut(widths.grain_row()) {
            r[0] = to(r[0] as u32) as f64;
        }
        for r in self.pairs.chunks_exact_mut(widths.pair_row()) {
            r[0] = to(r[0] as u32) as f64;
            r[1] = to(r[1] as u32) as f64;
        }
    }

    /// The rows as one message: `[grain values, grains.., pairs..]`.
    pub fn to_message(&self) -> Vec<f64> {
        let mut m = Vec::with_capacity(1 + self.grains.len() + self.pairs.len());
        m.push(self.grains.len() as f64);
        m.extend_from_slice(&self.grains);
        m.extend_from_slice(&self.pairs);
        m
    }

    /// [`Self::to_message`] undone.
    pub fn from_message(m: &[f64]) -> Rows {
        let n = m[0] as usize;
        Rows { grains: m[1..1 + n].to_vec(), pairs: m[1 + n..].to_vec() }
    }
}

/// The state whose grains are `rows`' grains renumbered `0..n` in ascending permanent id
/// (slot = id = that number), with `rows`' pairs between them (a pair listed twice keeps its
/// first row: the copies are equal) and the whole-engine arrays of `template` (the wall
/// contacts replaced by `touches`, given by grain number, when some). `ids` returns the
/// permanent ids in ascending order, each the grain of that number.
pub(crate) fn state_of_rows(rows: &Rows, widths: &RowWidths, template: &EngineState, touches: &EngineState) -> (EngineState, Vec<u32>) {
    let mut grains: Vec<&[f64]> = rows.grains.chunks_exact(widths.grain_row()).collect();
    grains.sort_by_key(|r| r[0] as u32);
    grains.dedup_by_key(|r| r[0] as u32);
    let ids: Vec<u32> = grains.iter().map(|r| r[0] as u32).collect();
    let number = |id: f64| ids.binary_search(&(id as u32)).ok();
    let mut s = EngineState::default();
    s.put_ints("id", 0..ids.len() as u64);
    for (name, int) in GRAIN_ARRAYS.iter().chain(&PAIR_ARRAYS) {
        if *int {
            s.put_ints(name, []);
        } else {
            s.put_reals(name, []);
        }
    }
    for r in &grains {
        pop_row(&mut s, &GRAIN_ARRAYS, &widths.grain, &r[1..]);
    }
    let mut pairs: Vec<(u32, u32, &[f64])> = rows.pairs.chunks_exact(widths.pair_row()).filter_map(|r| Some((number(r[0])? as u32, number(r[1])? as u32, &r[2..]))).collect();
    pairs.sort_by_key(|&(a, b, _)| (a, b));
    pairs.dedup_by_key(|&mut (a, b, _)| (a, b));
    let mut list = PairList { owner_start: vec![0; ids.len() + 1], ..Default::default() };
    for &(a, b, values) in &pairs {
        list.owner_start[a as usize + 1] += 1;
        list.partner.push(b);
        pop_row(&mut s, &PAIR_ARRAYS, &widths.pair, values);
    }
    for i in 0..ids.len() {
        list.owner_start[i + 1] += list.owner_start[i];
    }
    list.build_reverse(&(0..ids.len() as u32).collect::<Vec<_>>());
    for (name, v) in [("owner_start", &list.owner_start), ("partner", &list.partner), ("rev_start", &list.rev_start), ("rev_pair", &list.rev_pair)] {
        s.put_ints(name, v.iter().map(|&x| x as u64));
    }
    for name in GLOBAL_ARRAYS {
        let from = if name.starts_with("wall_touch") { touches } else { template };
        if let Some(v) = from.ints.get(name) {
            s.put_ints(name, v.iter().copied());
        }
        if let Some(v) = from.reals.get(name) {
            s.put_reals(name, v.iter().copied());
        }
    }
    (s, ids)
}

/// The wall contacts `touches` (by grain number) as a state's two arrays.
pub(crate) fn touches_state<T: Real>(touches: &[WallTouch<T>]) -> EngineState {
    let mut s = EngineState::default();
    let v3 = |v: &Vec3<T>| [v.x.f64(), v.y.f64(), v.z.f64()];
    s.put_ints("wall_touch_ids", touches.iter().flat_map(|t| [t.grain as u64, t.wall as u64, t.code() as u64]));
    s.put_reals("wall_touches", touches.iter().flat_map(|t| [v3(&t.force).as_slice(), &[t.stiffness.f64(), t.damping.f64()]].concat()));
    s.put_reals("wall_touch_power", touches.iter().map(|t| t.power.f64()));
    s
}

/// Values of a wall contact in [`touch_row`].
pub(crate) const TOUCH_ROW: usize = 9;

/// A wall contact as `[grain, wall, code, force x, y, z, stiffness, damping, power]`, with the
/// grain given by `id` ([`WallTouch::code`]).
pub(crate) fn touch_row<T: Real>(t: &WallTouch<T>, id: u32) -> [f64; TOUCH_ROW] {
    let f = t.force.f64();
    [id as f64, t.wall as f64, t.code() as f64, f[0], f[1], f[2], t.stiffness.f64(), t.damping.f64(), t.power.f64()]
}

/// [`touch_row`] undone.
pub(crate) fn touch_of_row<T: Real>(r: &[f64]) -> WallTouch<T> {
    let (regime, touching) = WallTouch::<T>::of_code(r[2] as u8);
    WallTouch { grain: r[0] as u32, wall: r[1] as u32, regime, touching, force: Vec3::new(T::of(r[3]), T::of(r[4]), T::of(r[5])), stiffness: T::of(r[6]), damping: T::of(r[7]), power: T::of(r[8]) }
}

impl<T: Real> CpuEngine<T> {
    /// The widths of this engine's rows.
    pub(crate) fn row_widths(&self) -> RowWidths {
        let stride = self.slots.stride;
        RowWidths {
            grain: [9, 6, 3 * T::COMPENSATED as usize, 3, 3 * (self.image.width() > 0) as usize, 4 * self.orientation.is_some() as usize, walls_reals(&self.walls, stride), self.slots.layout.bridge as usize],
            pair: [stride, 6, 1, self.slots.layout.bridge as usize, 1, 3 * self.model.keeps_both_forces() as usize],
        }
    }

    /// Values of a grain in [`Self::motion_rows`].
    pub(crate) fn motion_row(&self) -> usize {
        9 + 3 * T::COMPENSATED as usize + 4 * self.orientation.is_some() as usize
    }

    /// What a drift changes of the grains `ids` (permanent ids), each as `[pos, vel, omega,
    /// residual (f32), orientation (when tracked)]`.
    pub(crate) fn motion_rows(&self, ids: &[u32], out: &mut Vec<f64>) {
        for &i in ids {
            let s = self.slot[i as usize] as usize;
            let b = &self.body[s];
            for v in [b.pos, b.vel, b.omega] {
                out.extend(v.f64().to_array());
            }
            if T::COMPENSATED {
                out.extend(self.residual[s].f64().to_array());
            }
            if let Some(q) = &self.orientation {
                out.extend(q[s].map(T::f64));
            }
        }
    }

    /// Sets the grains `ids` from [`Self::motion_rows`]' rows.
    pub(crate) fn set_motion_rows(&mut self, ids: &[u32], rows: &[f64]) {
        let v3 = |r: &[f64]| Vec3::new(T::of(r[0]), T::of(r[1]), T::of(r[2]));
        for (&i, r) in ids.iter().zip(rows.chunks_exact(self.motion_row())) {
            let s = self.slot[i as usize] as usize;
            self.body[s] = Body { pos: v3(&r[0..3]), vel: v3(&r[3..6]), omega: v3(&r[6..9]) };
            let mut at = 9;
            if T::COMPENSATED {
                self.residual[s] = v3(&r[9..12]);
                at = 12;
            }
            if let Some(q) = &mut self.orientation {
                q[s] = [T::of(r[at]), T::of(r[at + 1]), T::of(r[at + 2]), T::of(r[at + 3])];
            }
        }
    }

    /// The largest squared displacement since the last build of the grains `ids` (m^2), as a
    /// drift computes it (with this engine's margin, [`super::built_at`]).
    pub(crate) fn moved2_of(&self, ids: impl Iterator<Item = u32>) -> f64 {
        let moved2 = ids
            .map(|i| {
                let s = self.slot[i as usize] as usize;
                super::built_at::moved2(self.body[s].pos, self.built_at[s])
            })
            .fold(T::ZERO, T::max);
        super::built_at::with_margin(moved2, self.built_margin).f64()
    }

    /// Sets the largest displacement since the last build (m^2) that the rebuild check reads.
    pub(crate) fn set_moved2(&mut self, moved2: f64) {
        self.max_moved2 = T::of(moved2);
    }

    /// True when the rebuild check would rebuild.
    pub(crate) fn needs_rebuild(&self) -> bool {
        let half = self.skin * T::of(0.5);
        !(self.max_moved2 < half * half)
    }

    /// The bridge events of this force evaluation on the pairs whose owner `keep` accepts (by
    /// permanent id), as [`BRIDGE_ROW`]s `[owner id, partner id, event (0: rupture, 1: touch),
    /// the pair's bridge volume, the owner's liquid, the partner's liquid]` (m^3) with the ids
    /// `to_id` gives, in canonical order.
    pub(crate) fn bridge_rows(&self, keep: impl Fn(u32) -> bool, to_id: impl Fn(u32) -> u32) -> Vec<f64> {
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        let mut rows = Vec::new();
        for (k, event) in self.bridge_events() {
            let k = k as usize;
            let (i, j) = self.pairs.grains_of(k);
            if keep(self.id[i]) {
                let kind = if event == BridgeEvent::Rupture { 0.0 } else { 1.0 };
                rows.extend([to_id(self.id[i]) as f64, to_id(self.id[j]) as f64, kind, self.hist[k * stride + b].f64(), self.liquid[i].f64(), self.liquid[j].f64()]);
            }
        }
        rows
    }

    /// Moves the liquid of `rows`, every process's bridge events ([`Self::bridge_rows`]) in
    /// canonical order: each grain's liquid starts from the first row that names it and
    /// follows the events as `update_bridges` moves it, so every grain's liquid and every
    /// pair's bridge come out with the bits of one process. The engine keeps those of its own
    /// grains and pairs (`local` gives the id here of a row's id, if this engine holds it).
    pub(crate) fn replay_bridges(&mut self, rows: &[f64], local: impl Fn(u32) -> Option<u32>) {
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        let mut liquid: std::collections::HashMap<u32, T> = std::collections::HashMap::new();
        for row in rows.chunks_exact(BRIDGE_ROW) {
            let (gi, gj) = (row[0] as u32, row[1] as u32);
            let event = if row[2] == 0.0 { BridgeEvent::Rupture } else { BridgeEvent::Touch };
            let mut l_i = *liquid.entry(gi).or_insert(T::of(row[4]));
            let mut l_j = *liquid.entry(gj).or_insert(T::of(row[5]));
            let bridge = move_liquid(event, T::of(row[3]), self.bridge_cap, &mut l_i, &mut l_j);
            liquid.insert(gi, l_i);
            liquid.insert(gj, l_j);
            if let (Some(i), Some(j)) = (local(gi), local(gj)) {
                let owner = self.slot[i as usize] as usize;
                let range = self.pairs.owner_start[owner] as usize..self.pairs.owner_start[owner + 1] as usize;
                let partners = &self.pairs.partner[range.clone()];
                if let Ok(m) = partners.binary_search_by_key(&j, |&p| self.id[p as usize]) {
                    self.hist[(range.start + m) * stride + b] = bridge;
                }
            }
        }
        for (g, l) in liquid {
            if let Some(i) = local(g) {
                self.liquid[self.slot[i as usize] as usize] = l;
            }
        }
    }

    /// The wall contacts of the last force evaluation of the grains `keep` accepts (by
    /// permanent id), as [`touch_row`]s with the id `to_id` gives.
    pub(crate) fn touch_rows(&self, keep: impl Fn(u32) -> bool, to_id: impl Fn(u32) -> u32) -> Vec<f64> {
        self.wall_touches.iter().filter(|t| keep(t.grain)).flat_map(|t| touch_row(t, to_id(t.grain))).collect()
    }

    /// Sets the walls' sums (force, contacts, response) from `touches` (sorted by grain id,
    /// then wall) among `n_grains` grains: every contact of every process, so that each
    /// process moves its walls alike.
    pub(crate) fn set_wall_sums(&mut self, touches: &[WallTouch<T>], n_grains: usize) {
        let sums = WallSums::of(self.walls.len(), n_grains, touches);
        self.wall_reaction = sums.reaction;
        self.wall_count = sums.count;
        self.wall_response = sums.response;
        self.wall_power = sums.power;
        self.wall_regimes = sums.regimes;
    }

    /// Keeps the slot of each permanent id from now on: the lookups by id below, which a
    /// process makes every step, read it.
    pub(crate) fn keep_slots(&mut self) {
        self.slot = super::rebuild::slots_of(&self.id);
    }

    /// True when grain `id`'s position and velocities are finite.
    pub(crate) fn is_finite(&self, id: u32) -> bool {
        let b = &self.body[self.slot[id as usize] as usize];
        b.pos.is_finite() && b.vel.is_finite() && b.omega.is_finite()
    }

    /// The position (m) of grain `id` along `axis`: `pos + residual`.
    pub(crate) fn coordinate(&self, id: u32, axis: usize) -> f64 {
        let s = self.slot[id as usize] as usize;
        position::absolute(self.body[s].pos, position::residual_at(&self.residual, s))[axis]
    }

    /// The position (m) of grain `id`: `pos + residual`.
    pub(crate) fn position(&self, id: u32) -> [f64; 3] {
        [0, 1, 2].map(|a| self.coordinate(id, a))
    }

    /// The step at which an error is reported, and the step suggested after an instability.
    pub(crate) fn error_context(&self) -> (u64, f64, f64) {
        (self.step, self.time, self.suggested_dt)
    }
}

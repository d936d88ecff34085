//! A force evaluation: `update_bridges`, `pair_force` in tasks of owner grains, `wall_contacts`
//! and `gather`, with the walls' sums and, inside a run of steps, the next step's kick and
//! drift carried into the gather's sweep.

use super::*;
use super::wall_sums::WallSums;

impl<T: Real> CpuEngine<T> {
    /// Runs the force passes: `pair_force`, `gather`, `wall_contacts`; the springs advance by
    /// `elapsed` (s). In capillary scenes the step's hooks update the bridges just before.
    /// With `kick` (s), the grains are then kicked in the gather's sweep, each as soon as its
    /// load is whole (the piston's kick is left to the caller); with `carry`, each is then also
    /// kicked and drifted as [`Self::drift`] would (the grains alone: see [`Self::step_in_run`]).
    /// Returns the largest squared displacement since the last build that the carried drift
    /// found (zero without one).
    pub(super) fn evaluate_forces(&mut self, elapsed: T, kick: Option<T>, carry: Option<Carry<T>>) -> T {
        if self.wall_springs.stale(&self.walls, self.skin) {
            self.choose_wall_springs();
        }
        let t = self.clock.start();
        // The gather's sweep takes the residuals apart, to drift a carried step.
        let sweep_ctx = ForceContext {
            model: &self.model,
            coeffs: &self.coeffs,
            n_materials: self.n_materials,
            slots: self.slots,
            elapsed,
            window: T::of(self.schedule.window(elapsed.f64())),
            periodic: self.periodic,
            residual: &[],
            material: &self.material,
            meshes: &self.meshes,
        };
        let ctx = ForceContext { residual: &self.residual, ..sweep_ctx };
        let (pairs, body, prop, gravity) = (&self.pairs, &self.body, &self.prop, self.gravity);
        let bounds = self.split();
        let mut blocks = owner_blocks(pairs, self.slots.stride, &mut self.load, &mut self.share, &mut self.report, &mut self.force_i, &mut self.hist).into_iter();
        // Each part's owner blocks (parts start at block boundaries).
        let parts: Vec<Vec<OwnerBlock<T>>> = bounds.windows(2).map(|w| blocks.by_ref().take(w[1].div_ceil(pair_force::OWNERS) - w[0].div_ceil(pair_force::OWNERS)).collect()).collect();
        let together = warm::Together::new(parts.len());
        parts.into_par_iter().with_max_len(1).for_each(|part| {
            let mut scratch = TaskScratch::default();
            for b in part {
                owner_block(b, &mut scratch, pairs, body, prop, &ctx, gravity);
            }
            together.finish();
        });
        self.clock.stop(Phase::Force, t);
        let t = self.clock.start();
        let grains = Grains { body: &mut self.body, residual: &mut self.residual, built_at: &self.built_at, prop, id: &self.id };
        let (sums, touches, moved, overflow) = complete_loads(&sweep_ctx, pairs, &self.share, grains, &bounds, &self.walls, &mut self.load, &mut self.wall_springs, kick, carry);
        self.wall_touches = touches;
        self.mesh_overflow = overflow;
        self.wall_reaction = sums.reaction;
        self.wall_count = sums.count;
        self.wall_response = sums.response;
        self.wall_power = sums.power;
        self.wall_regimes = sums.regimes;
        self.forces_valid = true;
        self.clock.stop(Phase::Gather, t);
        moved
    }

    /// The slots' parts, for the pool's threads ([`split::split`], [`split::parts_for`]), or
    /// one where the calling thread runs the step alone ([`crew`]).
    pub(super) fn split(&self) -> Vec<usize> {
        let wanted = match self.crew.who() {
            Who::Pool => split::parts_for(rayon::current_num_threads()),
            Who::Caller => 1,
        };
        split::split(&self.pairs, self.body.len(), wanted)
    }
}

/// The next step's kick by `kick` (s) and drift by `tau` (s), carried into a force
/// evaluation's gather sweep ([`CpuEngine::step_in_run`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Carry<T> {
    pub(super) kick: T,
    pub(super) tau: T,
}

/// The per-grain arrays the gather's sweep reads, and writes where it kicks and drifts.
pub(super) struct Grains<'a, T> {
    body: &'a mut [Body<T>],
    /// Empty unless positions are compensated.
    residual: &'a mut [Vec3<T>],
    built_at: &'a [Vec3<f32>],
    prop: &'a [Props<T>],
    id: &'a [u32],
}

/// `gather`, then `wall_contacts`, over every grain in one sweep, one part of the slots
/// ([`split::split`]'s `bounds`) a task: each grain's load gets its partners' shares, then its
/// wall load. Returns the per-wall sums ([`WallSums::of`]) and the wall contacts, sorted by
/// grain id, then wall, and the largest squared displacement the carried drift found. With
/// `kick` (s), each grain is then kicked by its load in the same sweep (see
/// [`CpuEngine::kick`]; the piston's kick is the caller's), and with `carry` kicked and
/// drifted again ([`integrate::kick_drift`]). `ctx.residual` is not read: the residuals
/// come in `grains`.
#[allow(clippy::too_many_arguments)]
pub(super) fn complete_loads<T: Real>(
    ctx: &ForceContext<T>,
    pairs: &PairList,
    share: &[Load<T>],
    grains: Grains<T>,
    bounds: &[usize],
    walls: &[WallState<T>],
    load: &mut [Load<T>],
    wall_springs: &mut WallSprings<T>,
    kick: Option<T>,
    carry: Option<Carry<T>>,
) -> (WallSums<T>, Vec<WallTouch<T>>, T, Option<u32>) {
    let per_grain = crate::state::walls_reals(walls, ctx.slots.stride);
    // Each part's first wall-spring entry (walls keep entries even where they keep no history).
    let first_entries: Vec<u32> = bounds.iter().map(|&b| wall_springs.first_entry(b)).collect();
    let (candidate, run_start, mut springs) = (&wall_springs.candidate, &wall_springs.run_start, &mut wall_springs.springs[..]);
    let Grains { body, residual, built_at, prop, id } = grains;
    let (mut loads, mut bodies, mut residuals) = (load, body, residual);
    let compensated = !residuals.is_empty();
    let parts: Vec<_> = bounds
        .windows(2)
        .zip(first_entries.windows(2))
        .map(|(w, e)| {
            let n = w[1] - w[0];
            (w[0], take_front(&mut loads, n), take_front(&mut bodies, n), take_front(&mut residuals, if compensated { n } else { 0 }), take_front(&mut springs, (e[1] - e[0]) as usize * per_grain))
        })
        .collect();
    let together = warm::Together::new(parts.len());
    let done: Vec<(Vec<WallTouch<T>>, T, Option<u32>)> = parts
        .into_par_iter()
        .with_max_len(1)
        .map(|(first, mut loads, mut bodies, mut residuals, mut springs)| {
            let (mut touches, mut moved, mut overflow) = (Vec::new(), T::ZERO, None);
            // A block of grains at a time, gathered, wall-contacted, kicked and (carried)
            // kicked and drifted while its arrays are in cache (a part of 10^6 grains is half
            // a million).
            let end = first + loads.len();
            let mut at = first;
            while at < end {
                let stop = (at - at % SWEEP_BLOCK + SWEEP_BLOCK).min(end);
                let grains = at..stop;
                let (loads, bodies) = (take_front(&mut loads, grains.len()), take_front(&mut bodies, grains.len()));
                let residuals = take_front(&mut residuals, if compensated { grains.len() } else { 0 });
                gather_block(at, loads, pairs, share);
                if !walls.is_empty() {
                    let springs = take_front(&mut springs, (wall_springs::first_entry(run_start, stop) - wall_springs::first_entry(run_start, at)) as usize * per_grain);
                    wall_block(at, loads, &candidate[at / split::ALIGN..], springs, &id[grains.clone()], bodies, residuals, &prop[grains.clone()], walls, ctx, &mut touches, &mut overflow);
                }
                if let Some(tau) = kick {
                    for ((b, l), p) in bodies.iter_mut().zip(loads.iter()).zip(&prop[grains.clone()]) {
                        integrate::kick(b, l, p, tau);
                    }
                }
                if let Some(c) = carry {
                    moved = moved.max(integrate::kick_drift(bodies, residuals, &built_at[grains.clone()], loads, &prop[grains], Some(c.kick), c.tau));
                }
                at = stop;
            }
            together.finish();
            (touches, moved, overflow)
        })
        .collect();
    let moved = done.iter().fold(T::ZERO, |m, d| m.max(d.1));
    let overflow = done.iter().filter_map(|d| d.2).min();
    let mut touches: Vec<WallTouch<T>> = done.into_iter().flat_map(|d| d.0).collect();
    // Stable: a grain's contacts with a mesh keep their slots' order.
    touches.sort_by_key(|t| (t.grain, t.wall));
    (WallSums::of(walls.len(), id.len(), &touches), touches, moved, overflow)
}

/// Splits the pair pass's outputs into the tasks of [`owner_block`]: [`pair_force::OWNERS`]
/// owner grains each, with the pairs they own.
pub(super) fn owner_blocks<'a, T: Real>(
    pairs: &PairList,
    stride: usize,
    mut load: &'a mut [Load<T>],
    mut share: &'a mut [Load<T>],
    report: &'a mut PairReports<T>,
    mut force_i: &'a mut [Vec3<T>],
    mut hist: &'a mut [T],
) -> Vec<OwnerBlock<'a, T>> {
    let n = load.len();
    let keep_fi = !force_i.is_empty();
    let keep_fc = !report.f_c.is_empty();
    let (mut f_n, mut f_c, mut flags) = (&mut report.f_n[..], &mut report.f_c[..], &mut report.flags[..]);
    let mut blocks = Vec::with_capacity(n.div_ceil(pair_force::OWNERS));
    for first in (0..n).step_by(pair_force::OWNERS) {
        let end = (first + pair_force::OWNERS).min(n);
        let count = (pairs.owner_start[end] - pairs.owner_start[first]) as usize;
        blocks.push(OwnerBlock {
            first,
            load: take_front(&mut load, end - first),
            share: take_front(&mut share, count),
            f_n: take_front(&mut f_n, count),
            f_c: take_front(&mut f_c, if keep_fc { count } else { 0 }),
            flags: take_front(&mut flags, count),
            force_i: take_front(&mut force_i, if keep_fi { count } else { 0 }),
            hist: take_front(&mut hist, count * stride),
        });
    }
    blocks
}

/// Splits the first `n` items off `s`, leaving it the rest.
pub(super) fn take_front<'a, X>(s: &mut &'a mut [X], n: usize) -> &'a mut [X] {
    let (front, rest) = std::mem::take(s).split_at_mut(n);
    *s = rest;
    front
}

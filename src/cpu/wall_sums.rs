//! What the walls receive from one force pass (their reaction, touching grains, stiffness and
//! damping, regimes), summed in the GPU's workgroup order for the f32 twin and in fixed
//! chunks for the f64 reference.

use super::*;

/// What the walls receive from one force pass, per wall.
pub(super) struct WallSums<T> {
    /// Force the grains exert (N).
    pub(super) reaction: Vec<Vec3<T>>,
    /// Touching grains.
    pub(super) count: Vec<u64>,
    /// Sums of the contacts' normal tangent stiffness (N/m) and damping (N s/m).
    pub(super) response: Vec<(T, T)>,
    /// Power (W) the wall's spin gives the grains.
    pub(super) power: Vec<T>,
    /// Contacts sliding and rolling, over all walls.
    pub(super) regimes: RegimeCounts,
}

/// One wall's share of the contacts of some grains: what `wall_contacts` and `wall_reduce`
/// add up (the WGSL rows' xyz, w and the stiffness half).
#[derive(Clone, Copy)]
pub(super) struct WallRow<T> {
    /// Force the grains exert (N).
    reaction: Vec3<T>,
    /// Touching grains.
    count: u64,
    /// Summed normal tangent stiffness (N/m) and damping (N s/m).
    response: (T, T),
    /// Summed spin power (W).
    power: T,
}

impl<T: Real> WallRow<T> {
    const ZERO: Self = WallRow { reaction: Vec3::ZERO, count: 0, response: (T::ZERO, T::ZERO), power: T::ZERO };

    fn of(t: &WallTouch<T>) -> Self {
        WallRow { reaction: -t.force, count: t.touching as u64, response: (t.stiffness, t.damping), power: t.power }
    }

    fn add(self, o: Self) -> Self {
        WallRow { reaction: self.reaction + o.reaction, count: self.count + o.count, response: (self.response.0 + o.response.0, self.response.1 + o.response.1), power: self.power + o.power }
    }
}

impl<T: Real> WallSums<T> {
    /// The sums of `touches` (sorted by grain id, then wall, a grain's contacts with a mesh in
    /// their slots' order) among `n_grains` grains: in the
    /// GPU's order for its twin ([`Real::GPU_TWIN`]), in chunks of ids otherwise. Either way
    /// the same bits however the slots are numbered.
    pub(super) fn of(n_walls: usize, n_grains: usize, touches: &[WallTouch<T>]) -> Self {
        let totals = if T::GPU_TWIN { WallRow::in_gpu_order(n_walls, n_grains, touches) } else { WallRow::in_chunks(n_walls, touches) };
        let mut regimes = RegimeCounts::default();
        for t in touches.iter().filter(|t| t.touching) {
            regimes.count(t.regime);
        }
        WallSums { reaction: totals.iter().map(|r| r.reaction).collect(), count: totals.iter().map(|r| r.count).collect(), response: totals.iter().map(|r| r.response).collect(), power: totals.iter().map(|r| r.power).collect(), regimes }
    }
}

impl<T: Real> WallRow<T> {
    /// Each wall's row, grains by permanent id in workgroups of [`WG`](crate::workgroup::WG),
    /// each summed by its tree (`wall_contacts`), then the workgroups' rows by `wall_reduce`'s
    /// strided tree: the GPU's order, whose grains sit in id order.
    fn in_gpu_order(n_walls: usize, n_grains: usize, touches: &[WallTouch<T>]) -> Vec<Self> {
        let wg = crate::workgroup::WG as usize;
        let rows = crate::workgroup::rows(n_grains as u64) as usize;
        let mut lanes = vec![WallRow::ZERO; wg];
        (0..n_walls)
            .map(|w| {
                let mut rest = touches;
                let partials = (0..rows).map(|r| {
                    let (here, next) = rest.split_at(rest.partition_point(|t| (t.grain as usize) < (r + 1) * wg));
                    rest = next;
                    if here.is_empty() {
                        return WallRow::ZERO;
                    }
                    lanes.fill(WallRow::ZERO);
                    // A grain's contacts with a mesh add up in its lane in their order.
                    let mut last = None;
                    for t in here.iter().filter(|t| t.wall as usize == w) {
                        let lane = &mut lanes[t.grain as usize % wg];
                        *lane = if last == Some(t.grain) { lane.add(WallRow::of(t)) } else { WallRow::of(t) };
                        last = Some(t.grain);
                    }
                    crate::workgroup::tree_sum(&mut lanes, WallRow::add)
                });
                crate::workgroup::strided_sum(partials, WallRow::ZERO, WallRow::add)
            })
            .collect()
    }

    /// Each wall's row as running sums over fixed chunks of [`CHUNK`] ids in id order, then
    /// over the chunks in order.
    fn in_chunks(n_walls: usize, touches: &[WallTouch<T>]) -> Vec<Self> {
        let mut total = vec![WallRow::ZERO; n_walls];
        let mut part = vec![WallRow::ZERO; n_walls];
        let mut chunk = touches.first().map_or(0, |t| t.grain as usize / CHUNK);
        for t in touches {
            if t.grain as usize / CHUNK != chunk {
                absorb(&mut total, &mut part);
                chunk = t.grain as usize / CHUNK;
            }
            let p = &mut part[t.wall as usize];
            p.reaction -= t.force;
            p.count += t.touching as u64;
            p.response = (p.response.0 + t.stiffness, p.response.1 + t.damping);
            p.power += t.power;
        }
        absorb(&mut total, &mut part);
        total
    }
}

/// Adds one chunk's rows to the totals and clears them.
pub(super) fn absorb<T: Real>(total: &mut [WallRow<T>], part: &mut [WallRow<T>]) {
    for (t, p) in total.iter_mut().zip(part.iter_mut()) {
        *t = t.add(*p);
        *p = WallRow::ZERO;
    }
}

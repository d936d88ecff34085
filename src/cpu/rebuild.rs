//! The rebuild of the neighbour list (`hash_cells`, `detect_pairs`, `remap_history`, in
//! [`crate::state`]) when a grain has moved half the skin since the last one, and the
//! renumbering of the grains in cell order every `reorder_every` rebuilds.

use super::*;

impl<T: Real> CpuEngine<T> {
    /// Rebuilds the neighbour list now (`hash_cells`, `detect_pairs`, `remap_history`),
    /// carrying every contact's history over, and every `reorder_every` rebuilds renumbers the
    /// slots in cell order (`reorder`).
    pub fn rebuild(&mut self) -> Result<(), SimError> {
        let t = self.clock.start();
        if self.periodic.any() {
            let (p, axes) = (self.periodic, self.image.axes().to_vec());
            let wrapped = match self.image.counts_mut() {
                Counts::Narrow(c) => wrap_grains(&p, &mut self.body, &mut self.residual, c, &axes),
                Counts::Wide(c) => wrap_grains(&p, &mut self.body, &mut self.residual, c, &axes),
            };
            match wrapped {
                Ok(largest) => self.image.widen_for(largest),
                Err(slot) => {
                    return Err(SimError::Unstable {
                        step: self.step,
                        time: self.time,
                        what: format!("a grain crossed more than {} periods between two neighbour builds", Images::WIDEN_AT),
                        grain: self.id[slot],
                        suggested_dt: self.suggested_dt,
                        also: "",
                    })
                }
            }
        }
        // The grids live for the rebuild alone (6 bytes a grain at the bed's density).
        let Some(grids) = Grids::hash(&self.body, &self.prop, self.cutoff, self.detect_reach, &self.periodic) else {
            return Err(self.non_finite_error());
        };
        self.clock.stop(Phase::Hash, t);
        let t = self.clock.start();
        let (prop, capacity, r_min) = (&self.prop, self.capacity, self.r_min);
        let capacity_of = |i: usize| crate::state::owner_capacity(capacity, r_min, prop[i].radius.f64() as f32);
        let pairs = PairList::detect(&self.body, &self.residual, &self.prop, &self.id, &grids, &self.periodic, self.detect_reach, capacity_of)
            .map_err(|(i, count)| SimError::Capacity { step: self.step, grain: self.id[i], count, capacity: self.capacity })?;
        self.clock.stop(Phase::Detect, t);
        let t = self.clock.start();
        self.hist = crate::state::remap_all(&pairs, &self.pairs, &self.hist, &self.id, self.slots.stride);
        self.pairs = pairs;
        if self.reorder_every > 0 && self.rebuilds.is_multiple_of(self.reorder_every) {
            self.reorder(grids.finest());
        }
        self.pairs.build_reverse(&kept_or_found(&self.slot, &self.id));
        let n_pairs = self.pairs.len();
        renew(&mut self.share, n_pairs);
        self.report.renew(n_pairs, self.slots.layout.bridge);
        renew(&mut self.force_i, if self.model.keeps_both_forces() { n_pairs } else { 0 });
        let mut margin2 = T::ZERO;
        for (b, at) in self.body.iter().zip(self.built_at.iter_mut()) {
            *at = built_at::record(b.pos);
            margin2 = margin2.max((b.pos - built_at::widen(*at)).norm2());
        }
        // One root for all (it is monotonic and correctly rounded: the same bits).
        self.built_margin = margin2.sqrt();
        self.choose_wall_springs();
        self.rebuilds += 1;
        self.max_moved2 = T::ZERO;
        self.forces_valid = false;
        self.clock.stop(Phase::Remap, t);
        Ok(())
    }

    /// `reorder`: renumbers the slots in Z order of `grid`'s cells (see [`reorder`]).
    pub(super) fn reorder(&mut self, grid: &CellGrid<T>) {
        let r = Renumbering::new(reorder::z_order(grid, &self.body));
        if r.is_identity() {
            return;
        }
        r.apply(&mut self.id);
        r.apply(&mut self.body);
        r.apply(&mut self.residual);
        r.apply(&mut self.prop);
        r.apply(&mut self.material);
        r.apply(&mut self.load);
        r.apply(&mut self.built_at);
        let width = self.image.width();
        match self.image.counts_mut() {
            Counts::Narrow(c) => r.apply_blocks(c, width),
            Counts::Wide(c) => r.apply_blocks(c, width),
        }
        r.apply(&mut self.liquid);
        self.wall_springs = self.wall_springs.renumbered(&r.from, walls_reals(&self.walls, self.slots.stride));
        if let Some(q) = &mut self.orientation {
            r.apply(q);
        }
        (self.pairs, self.hist) = r.apply_pairs(&self.pairs, &self.hist, self.slots.stride);
        self.refresh_slots();
        self.renumberings += 1;
    }

    /// Brings the kept slots of the ids, if kept, up to date with `id`.
    pub(super) fn refresh_slots(&mut self) {
        if !self.slot.is_empty() {
            self.slot = slots_of(&self.id);
        }
    }

    /// Rebuilds the neighbour list when a grain has moved half the skin since the last build
    /// (a non-finite displacement rebuilds too, and the rebuild reports it).
    pub(super) fn rebuild_if_needed(&mut self) -> Result<(), SimError> {
        let half = self.skin * T::of(0.5);
        if !(self.max_moved2 < half * half) {
            self.rebuild()?;
        }
        Ok(())
    }
}

/// `slot` where it is kept (as long as `id`), else the inverse of `id`.
pub(super) fn kept_or_found<'a>(slot: &'a [u32], id: &[u32]) -> Cow<'a, [u32]> {
    if slot.len() == id.len() {
        Cow::Borrowed(slot)
    } else {
        Cow::Owned(slots_of(id))
    }
}

/// The inverse of a numbering: `slot[id[s]] = s`.
pub(super) fn slots_of(id: &[u32]) -> Vec<u32> {
    let mut slot = vec![0; id.len()];
    for (s, &i) in id.iter().enumerate() {
        slot[i as usize] = s as u32;
    }
    slot
}

/// Wraps every grain's position into the periods and adds the periods it crossed along
/// `axes` to its image counts (`axes.len()` per grain). Returns the largest count's magnitude,
/// or, of the grains whose count no longer fits its width, the lowest slot.
pub(super) fn wrap_grains<T: Real, C: ImageCount>(p: &Periodic<T>, body: &mut [Body<T>], residual: &mut [Vec3<T>], counts: &mut [C], axes: &[usize]) -> Result<u32, usize> {
    let wrap = |(s, b, r, image): (usize, &mut Body<T>, &mut Vec3<T>, &mut [C])| {
        let moved = position::wrap(p, &mut b.pos, r);
        image.iter_mut().zip(axes).try_fold(0, |m, (c, &a)| c.add(moved[a]).map(|v| m.max(v.unsigned_abs())).ok_or(s))
    };
    // Of two results the error, and of two errors the lower slot: the same on any split.
    let first = |a: Result<u32, usize>, b: Result<u32, usize>| match (a, b) {
        (Ok(x), Ok(y)) => Ok(x.max(y)),
        (Err(x), Err(y)) => Err(x.min(y)),
        (Err(x), _) | (_, Err(x)) => Err(x),
    };
    let width = axes.len();
    if T::COMPENSATED {
        body.par_iter_mut().zip(residual.par_iter_mut()).zip(counts.par_chunks_mut(width)).with_min_len(PAR_MIN_ITEMS).enumerate().map(|(s, ((b, r), c))| wrap((s, b, r, c))).reduce(|| Ok(0), first)
    } else {
        body.par_iter_mut().zip(counts.par_chunks_mut(width)).with_min_len(PAR_MIN_ITEMS).enumerate().map(|(s, (b, c))| wrap((s, b, &mut Vec3::default(), c))).reduce(|| Ok(0), first)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two grains in a box periodic in x and y, each one period past its upper end along x
    /// (and the second also one below along y), with counts one short of the widening.
    fn crossing<C: ImageCount + From<i16>>() -> (Periodic<f64>, Vec<Body<f64>>, Vec<C>) {
        let p = Periodic::of(&[Some([0.0, 1.0]), Some([0.0, 1.0]), None]);
        let at = |x: f64, y: f64| Body { pos: Vec3::new(x, y, 0.5), ..Default::default() };
        let start = C::from(Images::WIDEN_AT as i16 - 1);
        (p, vec![at(1.25, 0.5), at(1.5, -0.5)], vec![start, C::from(0), start, start])
    }

    /// The wrap adds the periods crossed to the two-byte counts and reports the largest, which
    /// widens them; a count two bytes cannot hold names its grain and changes nothing.
    #[test]
    fn image_counts_widen_before_two_bytes_overflow() {
        let (p, mut body, mut counts) = crossing::<i16>();
        let largest = wrap_grains(&p, &mut body, &mut [], &mut counts, &[0, 1]);
        assert_eq!(largest, Ok(Images::WIDEN_AT as u32));
        assert_eq!(counts, vec![Images::WIDEN_AT as i16, 0, Images::WIDEN_AT as i16, Images::WIDEN_AT as i16 - 2]);
        assert_eq!((body[0].pos.x, body[1].pos.x, body[1].pos.y), (0.25, 0.5, 0.5));
        let mut images = Images::new([true, true, false], 2);
        for (i, c) in counts.chunks(2).enumerate() {
            images.set(i, [c[0] as i32, c[1] as i32, 0]);
        }
        assert!(matches!(images.counts_mut(), Counts::Wide(_)), "a count of WIDEN_AT widens them");
        assert_eq!(images.get(1), [Images::WIDEN_AT, Images::WIDEN_AT - 2, 0]);
        images.widen_for(0);
        assert_eq!(images.bytes(), 4 * 4, "two grains, two wrapping axes, four bytes a count");
        // One past what two bytes hold: an error naming the lowest such slot.
        let (p, mut body, _) = crossing::<i16>();
        let mut full = vec![i16::MAX, 0, i16::MAX, 0];
        assert_eq!(wrap_grains(&p, &mut body, &mut [], &mut full, &[0, 1]), Err(0));
        assert_eq!(full[0], i16::MAX);
        // Four bytes take it.
        let (p, mut body, mut wide) = crossing::<i32>();
        wide[0] = i16::MAX as i32;
        assert_eq!(wrap_grains(&p, &mut body, &mut [], &mut wide, &[0, 1]), Ok(i16::MAX as u32 + 1));
    }
}

//! Grains taken out of play (an outlet) and put into play (an inlet) between steps: a grain
//! out of play keeps its slot with its radius stored negated ([`Props::in_play`]).

use super::*;
use crate::engine::{Insertion, FAR_BUILT_AT};

impl<T: Real> CpuEngine<T> {
    /// Grains in play.
    pub(super) fn grains_in_play(&self) -> usize {
        self.prop.iter().filter(|p| p.in_play()).count()
    }

    /// [`crate::engine::Engine::remove_grains`].
    pub(super) fn take_out_of_play(&mut self, ids: &[u32]) {
        let slot = self.slots().into_owned();
        for &id in ids {
            let Some(&s) = slot.get(id as usize) else { continue };
            let s = s as usize;
            if !self.prop[s].in_play() {
                continue;
            }
            self.prop[s] = self.prop[s].with_play(false);
            let b = &mut self.body[s];
            (b.vel, b.omega) = (Vec3::ZERO, Vec3::ZERO);
            self.load[s] = Load::default();
            self.built_at[s] = Vec3::new(FAR_BUILT_AT, FAR_BUILT_AT, FAR_BUILT_AT);
            // Its share of the walls' contacts leaves the per-grain sums with it, as the
            // GPU's zeroed torque (whose w holds it) does; the walls' sums keep it until the
            // next evaluation, on both.
            self.wall_touches.retain(|t| t.grain != id);
        }
    }

    /// [`crate::engine::Engine::insert_grains`].
    pub(super) fn put_into_play(&mut self, grains: &[Insertion]) {
        let slot = self.slots().into_owned();
        for g in grains {
            let Some(&s) = slot.get(g.id as usize) else { continue };
            let s = s as usize;
            if self.prop[s].in_play() {
                continue;
            }
            self.prop[s] = self.prop[s].with_play(true);
            let (pos, residual) = position::split(g.position);
            self.body[s] = Body { pos, vel: Vec3::of(g.velocity), omega: Vec3::ZERO };
            if T::COMPENSATED {
                self.residual[s] = residual;
            }
            if self.image.width() > 0 {
                self.image.set(s, [0; 3]);
            }
            // Clear of every grain and wall: its weight is its whole load (the gather's sum).
            self.load[s] = Load { force: self.gravity * self.prop[s].mass + Vec3::ZERO, torque: Vec3::ZERO };
            self.built_at[s] = Vec3::new(FAR_BUILT_AT, FAR_BUILT_AT, FAR_BUILT_AT);
        }
    }
}

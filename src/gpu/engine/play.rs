//! Grains taken out of play (an outlet) and put into play (an inlet) between steps, as the
//! CPU twin does (`src/cpu/play.rs`): a grain out of play keeps its slot with its radius
//! stored negated in `pos.w` (WGSL `in_play`). The host writes the few words of each grain
//! that change.

use super::*;
use crate::engine::{Insertion, FAR_BUILT_AT};

impl GpuEngine {
    /// Writes `bytes` at grain `i`'s record of `buf` (16 bytes a grain), `offset` bytes in.
    fn write_grain(&self, buf: Buf, i: usize, offset: u64, bytes: &[u8]) {
        if let Some(b) = self.buffers.get(buf) {
            self.gpu.queue.write_buffer(b, 16 * i as u64 + offset, bytes);
        }
    }

    /// Grains in play.
    pub(super) fn grains_in_play(&self) -> usize {
        self.in_play.iter().filter(|&&p| p).count()
    }

    /// [`crate::engine::Engine::remove_grains`].
    pub(super) fn take_out_of_play(&mut self, ids: &[u32]) {
        let far = [FAR_BUILT_AT; 3];
        for &id in ids {
            let i = id as usize;
            if !self.in_play.get(i).copied().unwrap_or(false) {
                continue;
            }
            self.in_play[i] = false;
            self.write_grain(Buf::Pos, i, 12, bytemuck::bytes_of(&-self.radius[i]));
            self.write_grain(Buf::Vel, i, 0, bytemuck::bytes_of(&[0.0f32; 3]));
            self.write_grain(Buf::Omega, i, 0, bytemuck::bytes_of(&[0.0f32; 3]));
            self.write_grain(Buf::Force, i, 0, bytemuck::bytes_of(&[0.0f32; 4]));
            self.write_grain(Buf::Torque, i, 0, bytemuck::bytes_of(&[0.0f32; 4]));
            self.write_grain(Buf::BuiltAt, i, 0, bytemuck::bytes_of(&far));
        }
    }

    /// [`crate::engine::Engine::insert_grains`].
    pub(super) fn put_into_play(&mut self, grains: &[Insertion]) {
        let far = [FAR_BUILT_AT; 3];
        let g = self.params.gravity;
        for grain in grains {
            let i = grain.id as usize;
            if self.in_play.get(i).copied().unwrap_or(true) {
                continue;
            }
            self.in_play[i] = true;
            let (pos, residual) = crate::position::split::<f32>(grain.position);
            let v = grain.velocity.as_vec3();
            self.write_grain(Buf::Pos, i, 0, bytemuck::bytes_of(&[pos.x, pos.y, pos.z, self.radius[i]]));
            self.write_grain(Buf::Residual, i, 0, bytemuck::bytes_of(&[residual.x, residual.y, residual.z, 0.0]));
            self.write_grain(Buf::Vel, i, 0, bytemuck::bytes_of(&[v.x, v.y, v.z]));
            self.write_grain(Buf::Omega, i, 0, bytemuck::bytes_of(&[0.0f32; 3]));
            if self.periodic.any() {
                self.write_grain(Buf::Image, i, 0, bytemuck::bytes_of(&[0i32; 4]));
            }
            // Clear of every grain and wall: its weight is its whole load (the gather's sum).
            let m = self.mass[i];
            self.write_grain(Buf::Force, i, 0, bytemuck::bytes_of(&[g.x * m + 0.0, g.y * m + 0.0, g.z * m + 0.0, 0.0]));
            self.write_grain(Buf::Torque, i, 0, bytemuck::bytes_of(&[0.0f32; 4]));
            self.write_grain(Buf::BuiltAt, i, 0, bytemuck::bytes_of(&far));
        }
    }

    /// The grains in play as the pos buffer holds them (after a restore).
    pub(super) fn read_in_play(&mut self) -> Result<(), SimError> {
        let pos = self.read_vec4s(&[Buf::Pos])?;
        self.in_play = pos[0].iter().map(|p| p[3] > 0.0).collect();
        Ok(())
    }
}

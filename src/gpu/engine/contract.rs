//! The [`Engine`] contract on the GPU: the host loop's calls, each encoded, read back or
//! forwarded to the engine's other files.

use super::*;

impl Engine for GpuEngine {
    fn backend(&self) -> &'static str {
        "gpu"
    }
    fn precision(&self) -> &'static str {
        "f32"
    }
    fn grain_count(&self) -> usize {
        self.n as usize
    }
    fn steps(&self) -> u64 {
        self.step
    }
    fn time(&self) -> f64 {
        self.time
    }

    fn advance(&mut self, n: u64) -> Result<(), SimError> {
        let (start, end) = (self.step, self.step + n);
        while self.step < end {
            // Submissions of STEPS_PER_SUBMIT steps, then a check (which may take the run back
            // to a rebuild that stopped on full pair buffers, and on from there).
            for _ in 0..SUBMITS_PER_CHECK {
                if self.step == end {
                    break;
                }
                let chunk = STEPS_PER_SUBMIT.min(end - self.step);
                let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
                {
                    let mut pass = encoder.begin_compute_pass(&Default::default());
                    if self.plans.needs_loads && !self.forces_valid {
                        self.encode_plan(&mut pass, None, false, false);
                    }
                    for _ in 0..chunk {
                        let s = self.step;
                        self.encode_plan(&mut pass, Some(s), s > start, s + 1 < end);
                        self.step += 1;
                        self.time += self.dt;
                    }
                }
                self.gpu.queue.submit([encoder.finish()]);
                self.forces_valid = true;
            }
            self.check()?;
        }
        Ok(())
    }

    fn stats(&mut self) -> Result<Stats, SimError> {
        self.statistics()
    }

    fn frame(&self, contacts: bool) -> Result<Frame, SimError> {
        self.snapshot(contacts)
    }

    fn wet(&mut self, volume: f64) -> anyhow::Result<()> {
        self.wet_pairs(volume)
    }

    fn save(&self) -> Result<crate::engine::EngineState, SimError> {
        self.save_state()
    }

    fn restore(&mut self, s: &crate::engine::EngineState) -> anyhow::Result<()> {
        self.restore_state(s)
    }

    fn set_wall_drive(&mut self, wall: usize, drive: &crate::scene::WallDrive) {
        let base = (wall * std::mem::size_of::<layout::Wall>()) as u64;
        let (v, w) = (drive.velocity.as_vec3(), drive.angular_velocity.as_vec3());
        let flags = &mut self.wall_flags[wall];
        *flags = if drive.moves() { *flags | layout::wall_flags::DRIVEN } else { *flags & !layout::wall_flags::DRIVEN };
        if drive.turns {
            *flags |= layout::wall_flags::TURNS;
        }
        let queue = &self.gpu.queue;
        queue.write_buffer(&self.buffers[Buf::Walls], base + std::mem::offset_of!(layout::Wall, flags) as u64, bytemuck::bytes_of(flags));
        queue.write_buffer(&self.buffers[Buf::Walls], base + std::mem::offset_of!(layout::Wall, velocity) as u64, bytemuck::bytes_of(&v));
        queue.write_buffer(&self.buffers[Buf::Walls], base + std::mem::offset_of!(layout::Wall, drive) as u64, bytemuck::bytes_of(&w));
    }

    fn set_wall_present(&mut self, wall: usize, present: bool) {
        let flags = &mut self.wall_flags[wall];
        *flags = if present { *flags & !layout::wall_flags::ABSENT } else { *flags | layout::wall_flags::ABSENT };
        let at = (wall * std::mem::size_of::<layout::Wall>() + std::mem::offset_of!(layout::Wall, flags)) as u64;
        self.gpu.queue.write_buffer(&self.buffers[Buf::Walls], at, bytemuck::bytes_of(flags));
    }

    fn remove_grains(&mut self, ids: &[u32]) -> anyhow::Result<()> {
        self.take_out_of_play(ids);
        Ok(())
    }

    fn insert_grains(&mut self, grains: &[crate::engine::Insertion]) -> anyhow::Result<()> {
        self.put_into_play(grains);
        Ok(())
    }

    fn set_servo(&mut self, pressure: Option<f64>, axial_strain_rate: Option<f64>) {
        if self.servo.is_none() {
            return;
        }
        let buffer = &self.buffers[Buf::Servo];
        let at = |offset: usize| offset as u64;
        if let Some(p) = pressure {
            self.gpu.queue.write_buffer(buffer, at(std::mem::offset_of!(layout::Servo, pressure)), bytemuck::bytes_of(&(p as f32)));
        }
        let (strain, rate) = axial_strain_rate.map_or((0u32, 0.0f32), |r| (1, r as f32));
        self.gpu.queue.write_buffer(buffer, at(std::mem::offset_of!(layout::Servo, strain_rate)), bytemuck::bytes_of(&rate));
        self.gpu.queue.write_buffer(buffer, at(std::mem::offset_of!(layout::Servo, strain)), bytemuck::bytes_of(&strain));
    }

    fn memory_bytes(&self) -> u64 {
        self.buffers.bytes()
    }

    fn dispatches(&self) -> Option<u64> {
        Some(self.dispatches.get())
    }

    fn step_traffic(&self) -> Vec<(&'static str, u64)> {
        self.traffic()
    }

    fn place_piston(&mut self, z: f64) {
        if let Some(w) = self.piston {
            let base = (w * std::mem::size_of::<layout::Wall>()) as u64;
            let queue = &self.gpu.queue;
            queue.write_buffer(&self.buffers[Buf::Walls], base + std::mem::offset_of!(layout::Wall, point) as u64 + 8, bytemuck::bytes_of(&(z as f32)));
            queue.write_buffer(&self.buffers[Buf::Walls], base + std::mem::offset_of!(layout::Wall, velocity) as u64 + 8, bytemuck::bytes_of(&0.0f32));
        }
    }

    fn set_piston_pressure(&mut self, pressure: f64) {
        if let Some(w) = self.piston {
            let offset = (w * std::mem::size_of::<layout::Wall>() + std::mem::offset_of!(layout::Wall, drive) + 8) as u64;
            self.gpu.queue.write_buffer(&self.buffers[Buf::Walls], offset, bytemuck::bytes_of(&(pressure as f32)));
        }
    }
}

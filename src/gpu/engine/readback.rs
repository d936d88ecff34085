//! Reading the device back: buffers, the control flags, the statistics.

use super::*;

/// The pressure the grains exert on plane `k` (0..6) of the servo box whose walls are
/// `planes` (Pa): the CPU's `servo_pressure`, from the GPU's walls and reactions.
fn servo_pressure(walls: &[layout::Wall], reaction: &[[f32; 4]], planes: [usize; 6], k: usize) -> f64 {
    let coord = |k: usize| walls[planes[k]].point[k / 2] as f64;
    let extents = [0, 1, 2].map(|a| coord(2 * a + 1) - coord(2 * a));
    let a = k / 2;
    let area = extents[(a + 1) % 3] * extents[(a + 2) % 3];
    let (r, n) = (reaction[planes[k]], walls[planes[k]].normal);
    -(0..3).map(|c| r[c] as f64 * n[c] as f64).sum::<f64>() / area
}

/// `factor` times `pairs`, rounded up: pair buffers with a margin.
fn with_margin(pairs: u64, factor: f64) -> u64 {
    (pairs as f64 * factor).ceil() as u64
}

/// Force (N) and torque (N m) on one grain.
pub type GrainLoad = ([f32; 3], [f32; 3]);

impl GpuEngine {
    /// Copies buffers out: `(buffer, offset, bytes)` each, returned in order as 4-byte words
    /// (every type the kernels share is 4-byte aligned); a device that fails to answer is a
    /// [`SimError::Device`] naming the buffers.
    pub(super) fn read(&self, parts: &[(Buf, u64, u64)]) -> Result<Vec<Vec<u32>>, SimError> {
        let buffers: Vec<(&wgpu::Buffer, u64, u64)> = parts.iter().map(|&(name, offset, bytes)| (&self.buffers[name], offset, bytes)).collect();
        super::super::pipeline::read_back(&self.gpu, &buffers).map_err(|reason| SimError::Device { what: parts.iter().map(|p| p.0.name()).collect::<Vec<_>>().join(", "), reason })
    }

    /// The error for grain `grain`, which touched a mesh at more places than it keeps (the
    /// mesh named where the scene has one).
    fn mesh_overflow_error(&self, grain: u32) -> SimError {
        let wall = if self.meshes.len() == 1 { self.mesh_names.first().cloned().unwrap_or_default() } else { format!("(one of {})", self.mesh_names.join(", ")) };
        SimError::MeshContacts { step: self.step, grain, wall, max: crate::mesh::MESH_CONTACTS, raw: crate::mesh::RAW_CONTACTS }
    }

    /// Reads the control flags and counters back (and keeps them).
    pub(super) fn read_control(&mut self) -> Result<Control, SimError> {
        let c = self.read(&[(Buf::Control, 0, std::mem::size_of::<Control>() as u64)])?;
        self.control = *bytemuck::from_bytes(bytemuck::cast_slice(&c[0]));
        Ok(self.control)
    }

    /// Checks the flags the last steps raised, and grows the pair buffers when they fill up.
    /// A rebuild that stopped the run on full pair buffers (`pairs_ready`) is found among the
    /// checks encoded since the last time ([`RebuildMark`]): the buffers grow, keeping what
    /// they hold, and the run goes on from that rebuild's pair count, then to the end of its
    /// plan; the step counter and time are set back to that plan's, so the caller encodes the
    /// steps after it again. Every kernel after the stop ran with zero workgroups and the
    /// rebuild had touched nothing of the old list, so the bits are those of buffers that were
    /// large enough.
    pub(super) fn check(&mut self) -> Result<(), SimError> {
        loop {
            let c = self.read_control()?;
            if c.overflow_grain != NONE {
                return Err(SimError::Capacity { step: self.step, grain: c.overflow_grain, count: c.overflow_count as usize, capacity: self.params.max_neighbours as usize });
            }
            if c.mesh_overflow != NONE {
                return Err(self.mesh_overflow_error(c.mesh_overflow));
            }
            let marks = std::mem::take(&mut self.marks);
            let base = std::mem::replace(&mut self.marks_base, c.rebuild_checks);
            if c.pair_overflow == 0 {
                return if self.grow_ahead { self.make_room_for(c.n_pairs as u64) } else { Ok(()) };
            }
            let stopped = c.rebuild_checks.wrapping_sub(base) as usize;
            let Some(&mark) = stopped.checked_sub(1).and_then(|k| marks.get(k)) else {
                return Err(SimError::Device { what: "control".into(), reason: format!("a rebuild stopped on full pair buffers at rebuild check {stopped} of {} encoded since the last check", marks.len()) });
            };
            let needed = self.listed_pairs()?;
            let grown = if self.grow_ahead { with_margin(needed, PAIR_GROWTH) } else { needed };
            self.grow_pairs(grown, needed)?;
            self.go_on_after_stop(mark);
        }
    }

    /// Goes on with the rebuild of `mark`, which stopped at its pair count, and the rest of
    /// its plan: the flag lowered, the dispatch sizes the rest of the rebuild reads put back as
    /// `decide_rebuild` set them (the steps' own too), the trace cut back to the rebuild.
    fn go_on_after_stop(&mut self, mark: RebuildMark) {
        let queue = &self.gpu.queue;
        queue.write_buffer(&self.buffers[Buf::Control], std::mem::offset_of!(Control, pair_overflow) as u64, bytemuck::bytes_of(&0u32));
        let n = self.n as u64;
        let at = |slot: u64| slot * std::mem::size_of::<DispatchArgs>() as u64;
        for (slot, a) in [(args::GRAINS, DispatchArgs::items(n)), (args::GRAIN_BLOCKS, DispatchArgs::scan_blocks(n + 1)), (args::ONE, DispatchArgs::ONE), (args::STEP_GRAINS, DispatchArgs::items(n)), (args::STEP_ONE, DispatchArgs::ONE)] {
            queue.write_buffer(&self.buffers[Buf::Args], at(slot), bytemuck::bytes_of(&a));
        }
        (self.step, self.time) = (mark.step, mark.time);
        self.trace.keep_first(mark.traced);
        let plan = self.plan_of(&mark);
        for &op in &plan[mark.entry].ops {
            self.trace.record(op);
        }
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.encode_list_fill(&mut pass);
            self.encode_entries(&mut pass, RebuildMark { entry: mark.entry + 1, ..mark });
        }
        self.gpu.queue.submit([encoder.finish()]);
        if mark.plan.is_some() {
            self.step += 1;
            self.time += self.dt;
        }
        self.pair_stops += 1;
    }

    /// The number of pairs the last rebuild's count found (the end of `pair_start`), which
    /// may exceed the buffers' capacity.
    fn listed_pairs(&self) -> Result<u64, SimError> {
        Ok(self.read(&[(Buf::PairStart, 4 * self.n as u64, 4)])?[0][0] as u64)
    }

    /// Grows the pair buffers, keeping what they hold, to [`PAIR_GROWTH`] times `pairs` when
    /// `pairs` fill more than [`PAIR_GROWTH_THRESHOLD`] of them.
    fn make_room_for(&mut self, pairs: u64) -> Result<(), SimError> {
        if pairs as f64 > PAIR_GROWTH_THRESHOLD * self.params.pair_capacity as f64 {
            self.grow_pairs(with_margin(pairs, PAIR_GROWTH), pairs)?;
        }
        Ok(())
    }

    /// Grows the pair buffers, keeping what they hold, to `capacity` pairs, or to what one
    /// storage binding holds if less, but not below `needed`.
    fn grow_pairs(&mut self, capacity: u64, needed: u64) -> Result<(), SimError> {
        let binding = self.gpu.limits.max_storage_buffer_binding_size;
        let per_pair = 16 * (self.params.hist_blocks as u64).max(1);
        let grown = capacity.min(binding / per_pair).min(binding / 16);
        if grown < needed {
            return Err(SimError::PairBuffers { step: self.step, pairs: needed, capacity: grown });
        }
        if grown > self.params.pair_capacity as u64 {
            let mib = self.pair_bytes(grown) as f64 / (1u64 << 20) as f64;
            self.allocate_pairs(grown).map_err(|reason| SimError::DeviceMemory { step: self.step, pairs: grown, mib, reason })?;
            self.build_bind_groups();
        }
        Ok(())
    }

    /// Sizes the pair buffers for the list the first rebuild will build, counted by the
    /// rebuild's own kernels before the first step (the control record then put back as it
    /// was): [`PAIR_HEADROOM`] times its pairs. (A list that outgrew them later would only
    /// stop the run until they grew.)
    pub(super) fn make_room_for_the_first_list(&mut self) -> Result<(), SimError> {
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.run(&mut pass, StepKernel::DecideRebuild, Size::One, None);
            self.encode_pair_count(&mut pass);
        }
        self.gpu.queue.submit([encoder.finish()]);
        let pairs = self.listed_pairs()?;
        self.gpu.queue.write_buffer(&self.buffers[Buf::Control], 0, bytemuck::bytes_of(&self.control));
        self.grow_pairs(with_margin(pairs, PAIR_HEADROOM), pairs)
    }

    /// Rebuilds the neighbour list at the next step, whatever the displacements.
    pub fn rebuild_next_step(&mut self) {
        self.gpu.queue.write_buffer(&self.buffers[Buf::Control], 0, bytemuck::bytes_of(&f32::INFINITY.to_bits()));
    }

    /// The pair list (CSR: starts per grain, partners), read back.
    pub fn pair_list(&mut self) -> Result<(Vec<u32>, Vec<u32>), SimError> {
        let n_pairs = self.read_control()?.n_pairs as u64;
        let parts = self.read(&[(Buf::PairStart, 0, 4 * (self.n as u64 + 1)), (Buf::PairJ, 0, 4 * n_pairs)])?;
        Ok((parts[0].clone(), parts[1].clone()))
    }

    /// Force and torque on each grain from the last force evaluation (N, N m), read back.
    pub fn loads(&self) -> Result<Vec<GrainLoad>, SimError> {
        let a = self.read_vec4s(&[Buf::Force, Buf::Torque])?;
        Ok(a[0].iter().zip(&a[1]).map(|(f, t)| ([f[0], f[1], f[2]], [t[0], t[1], t[2]])).collect())
    }

    /// Liquid bridges among the first `n_pairs` pairs, the liquid they hold and the liquid
    /// waiting on the grains (m^3), and the bridges' potential energy (J, the CPU twin's law
    /// in f32 on the host), read back.
    pub(super) fn liquid_sums(&self, n_pairs: u64) -> Result<(u64, f64, f64, f64), SimError> {
        use crate::real::Vec3;
        let crate::model::CohesionLaw::Capillary { kappa, theta, c } = self.model.cohesion else { return Ok((0, 0.0, 0.0, 0.0)) };
        let blocks = self.params.hist_blocks as usize;
        let n = self.n as u64;
        let parts = self.read(&[(Buf::Hist, 0, 16 * n_pairs * blocks as u64), (Buf::Liquid, 0, 4 * n), (Buf::Pos, 0, 16 * n), (Buf::PairI, 0, 4 * n_pairs), (Buf::PairJ, 0, 4 * n_pairs), (Buf::Residual, 0, 16 * n)])?;
        let residual: &[[f32; 4]] = bytemuck::cast_slice(&parts[5]);
        let hist: &[[f32; 4]] = bytemuck::cast_slice(&parts[0]);
        let liquid: &[f32] = bytemuck::cast_slice(&parts[1]);
        let pos: &[[f32; 4]] = bytemuck::cast_slice(&parts[2]);
        let (pi, pj) = (&parts[3], &parts[4]);
        let v3 = |p: &[f32; 4]| Vec3::new(p[0], p[1], p[2]);
        let (mut bridges, mut held, mut energy) = (0u64, 0.0f64, 0.0f64);
        for k in 0..n_pairs as usize {
            let v = hist[k * blocks + blocks - 1][0];
            if v > 0.0 {
                let (i, j) = (pi[k] as usize, pj[k] as usize);
                let (a, b) = (&pos[i], &pos[j]);
                let gap = crate::position::separation(&self.periodic, v3(a), v3(&residual[i]), v3(b), v3(&residual[j])).norm() - a[3] - b[3];
                bridges += 1;
                held += v as f64;
                energy += crate::model::capillary_potential(kappa, theta, c, a[3], b[3], v, gap) as f64;
            }
        }
        Ok((bridges, held, liquid.iter().map(|&l| l as f64).sum(), energy))
    }

    /// Reads grain arrays back (vec4 per grain).
    pub(super) fn read_vec4s(&self, names: &[Buf]) -> Result<Vec<Vec<[f32; 4]>>, SimError> {
        let parts: Vec<(Buf, u64, u64)> = names.iter().map(|&n| (n, 0, 16 * self.n as u64)).collect();
        Ok(self.read(&parts)?.into_iter().map(|b| bytemuck::cast_slice(&b).to_vec()).collect())
    }

    /// The statistics of the current state (loads evaluated first if nothing has).
    pub(super) fn statistics(&mut self) -> Result<Stats, SimError> {
        self.ensure_loads()?;
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.run(&mut pass, StepKernel::ReduceGrains, Size::Grains, None);
            self.run(&mut pass, StepKernel::ReducePairs, Size::Indirect(args::PAIRS), None);
            self.run(&mut pass, StepKernel::ReduceFinal, Size::One, None);
        }
        self.gpu.queue.submit([encoder.finish()]);
        let n_walls = self.wall_names.len();
        let parts = self.read(&[
            (Buf::Control, 0, std::mem::size_of::<Control>() as u64),
            (Buf::Stats, 0, 2 * STAT_ROW as u64 * 4),
            (Buf::WallReaction, 0, MAX_WALLS as u64 * 16),
            (Buf::Walls, 0, (n_walls.max(1) * std::mem::size_of::<layout::Wall>()) as u64),
            (Buf::Servo, 0, std::mem::size_of::<layout::Servo>() as u64),
        ])?;
        let control: Control = *bytemuck::from_bytes(bytemuck::cast_slice(&parts[0]));
        let servo: layout::Servo = *bytemuck::from_bytes(bytemuck::cast_slice(&parts[4]));
        self.control = control;
        let s: &[f32] = bytemuck::cast_slice(&parts[1]);
        let reaction: &[[f32; 4]] = bytemuck::cast_slice(&parts[2]);
        // Copied out: a wall's vectors are 16-byte aligned, the words read back 4.
        let walls: Vec<layout::Wall> = bytemuck::pod_collect_to_vec(&parts[3]);
        use layout::stat::{grain as gr, pair as pr};
        let g = |f: usize| s[f] as f64;
        let p = |f: usize| s[STAT_ROW + f] as f64;
        let g_count = |f: usize| s[f].to_bits() as u64;
        let p_count = |f: usize| s[STAT_ROW + f].to_bits() as u64;
        let n = self.grains_in_play() as f64;
        let contacts = p_count(pr::CONTACTS);
        let wall_contacts = g_count(gr::WALL_CONTACTS);
        let contact_ends = 2 * contacts + wall_contacts;
        let rattlers = g_count(gr::RATTLERS);
        let contact_force = p(pr::FORCE) + g(gr::WALL_FORCE);
        let unbalanced_force = crate::engine::unbalanced(g(gr::NET_FORCE), n, contact_force, contact_ends);
        let unbalanced_force_loaded = crate::engine::unbalanced(g(gr::NET_LOADED), n - rattlers as f64, contact_force, contact_ends);
        let (max_overlap, max_overlap_grain) = {
            let (gv, gi) = (g(STAT_ROW - 2), s[STAT_ROW - 1].to_bits());
            let (pv, pi) = (p(STAT_ROW - 2), s[2 * STAT_ROW - 1].to_bits());
            if gv > pv || (gv == pv && gi < pi) { (gv, gi) } else { (pv, pi) }
        };
        let (bridges, liquid_in_bridges, liquid_on_grains, capillary_energy) = self.liquid_sums(control.n_pairs as u64)?;
        let piston = self.piston.map(|w| {
            let wall = &walls[w];
            PistonStats {
                z: wall.point[2] as f64,
                velocity: wall.velocity[2] as f64,
                target_pressure: wall.drive[2] as f64,
                pressure: reaction[w][2] as f64 / wall.drive[1] as f64,
            }
        });
        Ok(Stats {
            step: self.step,
            time: self.time,
            ke_translational: g(gr::KE_T),
            ke_rotational: g(gr::KE_R),
            elastic_energy: p(pr::ELASTIC) + g(gr::WALL_ELASTIC),
            capillary_energy,
            gravity_energy: g(gr::PE_G),
            piston_ke: self.piston.map_or(0.0, |w| 0.5 * walls[w].drive[0] as f64 * (walls[w].velocity[2] as f64).powi(2)),
            // The piston's and the driven walls' work, booked in their `drive.w`.
            external_work: walls.iter().map(|w| w.drive[3] as f64).sum::<f64>() + servo.work as f64 + servo.work_lo as f64,
            momentum: [0, 1, 2].map(|a| g(gr::MOMENTUM + a)),
            angular_momentum: [0, 1, 2].map(|a| g(gr::ANGULAR + a)),
            pairs: control.n_pairs as u64,
            contacts,
            wall_contacts,
            clamped: p_count(pr::CLAMPED),
            sliding: p_count(pr::SLIDING) + g_count(gr::WALL_SLIDING),
            rolling: p_count(pr::ROLLING) + g_count(gr::WALL_ROLLING),
            coordination: crate::engine::coordination(contacts, n),
            grains: n as u64,
            max_overlap,
            max_overlap_grain: if max_overlap_grain == NONE { 0 } else { max_overlap_grain },
            unbalanced_force,
            unbalanced_force_loaded,
            rattlers,
            ke_rattlers: g(gr::KE_RATTLERS),
            non_finite_grain: (control.non_finite != NONE).then_some(control.non_finite),
            rebuilds: control.rebuilds as u64,
            bridges,
            liquid_in_bridges,
            liquid_on_grains,
            walls: (0..n_walls)
                .map(|w| {
                    let servo_plane = self.servo.and_then(|planes| planes.iter().position(|&p| p == w));
                    WallStats {
                        name: self.wall_names[w].clone(),
                        force: [reaction[w][0] as f64, reaction[w][1] as f64, reaction[w][2] as f64],
                        contacts: reaction[w][3].to_bits() as u64,
                        position: servo_plane.map(|k| walls[w].point[k / 2] as f64),
                        pressure: servo_plane.map(|k| servo_pressure(&walls, reaction, self.servo.expect("a servo plane"), k)),
                    }
                })
                .collect(),
            piston,
            solver: None,
            flow: Vec::new(),
        })
    }
}

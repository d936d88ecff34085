//! The engine's device buffers that grow with the pair list, its pipelines (one per kernel,
//! specialised to the scene's laws by override constants) and its bind groups.

use super::*;

/// An array the two-level scan runs over (`scan_blocks`, `scan_add`), with its blocks' totals
/// (scanned in turn as one block whose own total goes to a spare word): one bind group each.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Scan {
    /// The hash buckets' counts.
    Cells,
    /// Their blocks' totals.
    CellSums,
    /// Each grain's pair count.
    PairStarts,
    /// Each grain's partner count, for the reverse list.
    RevStarts,
    /// The grain arrays' blocks' totals.
    GrainSums,
}

impl Scan {
    const ALL: [Scan; 5] = [Scan::Cells, Scan::CellSums, Scan::PairStarts, Scan::RevStarts, Scan::GrainSums];

    /// The buffers bound as the kernels' `scan_data` and `block_sums`.
    fn arrays(self) -> [(Buf, Buf); 2] {
        let (data, sums) = match self {
            Scan::Cells => (Buf::CellCount, Buf::HashSums),
            Scan::CellSums => (Buf::HashSums, Buf::SpareSum),
            Scan::PairStarts => (Buf::PairStart, Buf::GrainSums),
            Scan::RevStarts => (Buf::RevStart, Buf::GrainSums),
            Scan::GrainSums => (Buf::GrainSums, Buf::SpareSum),
        };
        [(Buf::ScanData, data), (Buf::BlockSums, sums)]
    }
}

impl GpuEngine {
    /// The per-pair buffers and their bytes per pair.
    pub(super) fn pair_buffers(&self) -> [(Buf, u64); 9] {
        let blocks = self.params.hist_blocks as u64;
        [
            (Buf::BridgeEvent, if self.history.bridge { 4 } else { 0 }),
            (Buf::PairI, 4),
            (Buf::PairJ, 4),
            (Buf::RevPair, 4),
            (Buf::Hist, 16 * blocks),
            (Buf::OutFi, 16),
            // The force on the partner, where it is not the owner's reversed.
            (Buf::OutFj, if self.model.keeps_both_forces() { 16 } else { 0 }),
            (Buf::OutTi, 16),
            (Buf::OutTj, 16),
        ]
    }

    /// The per-pair buffers' names and sizes for `capacity` pairs (B).
    pub(super) fn pair_buffer_sizes(&self, capacity: u64) -> Vec<(Buf, u64)> {
        let mut sizes: Vec<(Buf, u64)> = self.pair_buffers().iter().map(|&(name, per_pair)| (name, (per_pair * capacity).max(16))).collect();
        sizes.push((Buf::PairRows, (workgroup::rows(capacity) * STAT_ROW as u64 * 4).max(16)));
        sizes
    }

    /// The per-pair buffers' bytes for `capacity` pairs.
    pub(super) fn pair_bytes(&self, capacity: u64) -> u64 {
        self.pair_buffer_sizes(capacity).iter().map(|s| s.1).sum()
    }

    /// (Re)allocates the per-pair buffers for `capacity` pairs, keeping what the live pairs
    /// hold; the driver's reason when the device has not the memory (the buffers held are then
    /// kept as they were).
    pub(super) fn allocate_pairs(&mut self, capacity: u64) -> Result<(), String> {
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let out_of_memory = self.gpu.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let grown: Vec<(Buf, wgpu::Buffer)> = self
            .pair_buffer_sizes(capacity)
            .into_iter()
            .map(|(name, size)| (name, self.gpu.device.create_buffer(&wgpu::BufferDescriptor { label: Some(name.name()), size, usage: storage, mapped_at_creation: false })))
            .collect();
        if let Some(e) = pollster::block_on(out_of_memory.pop()) {
            return Err(e.to_string());
        }
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        for (name, b) in grown {
            if let Some(old) = self.buffers.get(name) {
                encoder.copy_buffer_to_buffer(old, 0, &b, 0, old.size().min(b.size()));
            }
            self.buffers.insert(name, b);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.params.pair_capacity = capacity as u32;
        self.gpu.queue.write_buffer(&self.buffers[Buf::Params], 0, bytemuck::bytes_of(&self.params));
        Ok(())
    }

    pub(super) fn build_pipelines(&mut self, scene: &Scene) {
        let m = &scene.model;
        let model_constants = [
            ("NORMAL_LAW", m.normal.code() as f64),
            ("DAMPING_LAW", m.damping.code() as f64),
            ("TANGENTIAL_LAW", m.tangential.code() as f64),
            ("ROLLING_LAW", m.rolling.code() as f64),
            ("TWISTING_LAW", m.twisting.code() as f64),
            ("COHESION_LAW", m.cohesion.code() as f64),
            ("HAS_TANGENTIAL_HISTORY", self.history.tangential as u8 as f64),
            ("HAS_ROLLING_HISTORY", self.history.rolling as u8 as f64),
            ("NORMAL_SLOT", layout::normal_slot(self.history) as f64),
            ("LIMIT_DAMPING", m.limit_damping as u8 as f64),
            ("CENTRED_KICKS", crate::schedule::centred_kicks(scene.integrator) as u8 as f64),
        ];
        let orientation = ("TRACK_ORIENTATION", self.track_orientation as u8 as f64);
        // The servo reads its walls' stiffness and damping, a spinning wall's work its power.
        let spins = scene.walls.iter().map(|w| w.drive).chain(scene.stages.iter().flat_map(|s| s.walls.iter().map(|w| w.1))).any(|d| d.angular_velocity != glam::DVec3::ZERO);
        let wall_response = ("WALL_RESPONSE", (self.servo.is_some() || spins) as u8 as f64);
        let partner_force = ("PARTNER_FORCE_STORED", m.keeps_both_forces() as u8 as f64);
        (self.layouts, self.pipelines) = StepKernel::ALL
            .iter()
            .map(|&id| {
                let k = id.kernel();
                let mut constants: Vec<(&str, f64)> = if k.includes.contains(&"model") { model_constants.to_vec() } else { Vec::new() };
                match id {
                    StepKernel::Integrate => constants.push(orientation),
                    StepKernel::PairForce => constants.push(partner_force),
                    StepKernel::Gather => constants.extend([partner_force, wall_response, orientation]),
                    _ => {}
                }
                crate::gpu::pipeline::compute_pipeline(&self.gpu.device, k, &constants)
            })
            .unzip();
    }

    /// Bind groups: one per kernel, and one per scanned array for the scan kernels.
    pub(super) fn build_bind_groups(&mut self) {
        self.bind_groups.clear();
        for &id in StepKernel::ALL {
            let k = id.kernel();
            let scans: Vec<Option<Scan>> = if matches!(id, StepKernel::ScanBlocks | StepKernel::ScanAdd) { Scan::ALL.iter().copied().map(Some).collect() } else { vec![None] };
            for scan in scans {
                let arrays = scan.map(Scan::arrays);
                let buffer = |name: Buf| {
                    let held = arrays.iter().flatten().chain(&REBUILD_SCRATCH).find(|(a, _)| *a == name).map_or(name, |(_, b)| *b);
                    &self.buffers[held]
                };
                let label = match scan {
                    Some(scan) => format!("{}:{scan:?}", k.name),
                    None => k.name.to_string(),
                };
                let bg = crate::gpu::pipeline::bind_group(&self.gpu.device, &label, k, &self.layouts[id as usize], buffer, std::mem::size_of::<Phase>() as u64);
                self.bind_groups.insert((id, scan), bg);
            }
        }
    }
}

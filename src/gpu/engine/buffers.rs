//! The engine's device buffers that grow with the pair list, its pipelines (one per kernel,
//! specialised to the scene's laws by override constants) and its bind groups.

use super::*;

impl GpuEngine {
    /// The per-pair buffers and their bytes per pair.
    pub(super) fn pair_buffers(&self) -> [(&'static str, u64); 9] {
        let blocks = self.params.hist_blocks as u64;
        [
            ("bridge_event", if self.history.bridge { 4 } else { 0 }),
            ("pair_i", 4),
            ("pair_j", 4),
            ("rev_pair", 4),
            ("hist", 16 * blocks),
            ("out_fi", 16),
            // The force on the partner, where it is not the owner's reversed.
            ("out_fj", if self.model.keeps_both_forces() { 16 } else { 0 }),
            ("out_ti", 16),
            ("out_tj", 16),
        ]
    }

    /// The per-pair buffers' names and sizes for `capacity` pairs (B).
    pub(super) fn pair_buffer_sizes(&self, capacity: u64) -> Vec<(&'static str, u64)> {
        let mut sizes: Vec<(&'static str, u64)> = self.pair_buffers().iter().map(|&(name, per_pair)| (name, (per_pair * capacity).max(16))).collect();
        sizes.push(("pair_rows", (workgroup::rows(capacity) * STAT_ROW as u64 * 4).max(16)));
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
        let grown: Vec<(&'static str, wgpu::Buffer)> = self
            .pair_buffer_sizes(capacity)
            .into_iter()
            .map(|(name, size)| (name, self.gpu.device.create_buffer(&wgpu::BufferDescriptor { label: Some(name), size, usage: storage, mapped_at_creation: false })))
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
        self.gpu.queue.write_buffer(&self.buffers["params"], 0, bytemuck::bytes_of(&self.params));
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
        let wall_response = ("WALL_RESPONSE", self.servo.is_some() as u8 as f64);
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
        // Each scanned array, and its block totals (scanned in turn as one block whose own
        // total goes to a spare word).
        let scans: [(&str, &str, &str); 5] = [
            ("cell", "cell_count", "hash_sums"),
            ("cell_sums", "hash_sums", "spare_sum"),
            ("pairs", "pair_start", "grain_sums"),
            ("rev", "rev_start", "grain_sums"),
            ("grain_sums", "grain_sums", "spare_sum"),
        ];
        for &id in StepKernel::ALL {
            let k = id.kernel();
            let instances: Vec<(String, Vec<(&str, &str)>)> = if matches!(id, StepKernel::ScanBlocks | StepKernel::ScanAdd) {
                scans.iter().map(|(tag, data, sums)| (format!("{}:{tag}", k.name), vec![("scan_data", *data), ("block_sums", *sums)])).collect()
            } else {
                vec![(k.name.to_string(), vec![])]
            };
            for (key, aliases) in instances {
                let buffer = |name: &str| {
                    let buffer_name = aliases.iter().chain(&REBUILD_SCRATCH).find(|(a, _)| *a == name).map_or(name, |(_, b)| *b);
                    self.buffers.get(buffer_name).unwrap_or_else(|| panic!("kernel {} binds {buffer_name}, which the engine lacks", k.name))
                };
                let bg = crate::gpu::pipeline::bind_group(&self.gpu.device, &key, k, &self.layouts[id as usize], buffer, std::mem::size_of::<Phase>() as u64);
                self.bind_groups.insert(key, bg);
            }
        }
    }
}

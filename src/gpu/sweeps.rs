//! Contact dynamics' Gauss-Seidel sweeps on the GPU: the host detects the step's contacts,
//! colours them and sets their laws (`crate::cd`), then this uploads them with the grains'
//! velocities and runs the sweeps as the CPU does: per sweep one dispatch per colour
//! (`cd_sweep_colour`, a colour's contacts at once), the serial tail on one invocation
//! (`cd_sweep_tail`), the convergence measure summed by blocks (`cd_measure`) and the decision
//! (`cd_decide`), which stops every later dispatch once the tolerance or the cap is reached.
//! Sweeps are submitted in batches that double from one (a warm-started step often converges
//! in a few) up to [`MAX_SWEEPS_PER_SUBMIT`]; the host reads the 32-byte control record
//! ([`CdControl`]) between batches. The arithmetic is the CPU's f32 in its order; a device
//! that fuses a multiply and an add (lavapipe does) moves an impulse by an ulp now and then
//! (`tests/contact_dynamics_gpu.rs` bounds a step's difference).

use super::device::Gpu;
use super::layout::{CdColour, CdContact, CdControl, CdParams};
use super::pipeline::{bind_group, compute_pipeline, read_back, Buffers};
use crate::cd::{Contact, Partner, Schedule, Solved, SweepSettings, Sweeps, WallMotion, MAX_COLOURS, MEASURE_BLOCK};
use crate::state::Body;
use crate::engine::SimError;
use crate::gpu::kernels::{Buf, CdKernel, CD_KERNELS};
use crate::real::Vec3;

/// Most sweeps recorded in one submission.
pub const MAX_SWEEPS_PER_SUBMIT: u32 = 32;

/// The sweeps on a GPU (f32).
pub struct GpuSweeps {
    gpu: Gpu,
    /// Each kernel's bind group layout and pipeline, indexed by [`CdKernel`].
    pipelines: Vec<(wgpu::BindGroupLayout, wgpu::ComputePipeline)>,
    buffers: Buffers,
    /// Each kernel's bind group, indexed by [`CdKernel`].
    bind_groups: Vec<wgpu::BindGroup>,
    /// Contacts the contact buffers hold.
    capacity: u64,
    /// Bytes between colours in the `phase` uniform (the device's uniform offset alignment).
    colour_stride: u64,
}

impl GpuSweeps {
    /// The sweeps of a system of `grains` grains and `walls` walls on an opened device.
    pub fn new(gpu: Gpu, grains: usize, walls: usize) -> Self {
        let pipelines = CD_KERNELS.iter().map(|k| compute_pipeline(&gpu.device, k, &[])).collect();
        let colour_stride = (gpu.limits.min_uniform_buffer_offset_alignment as u64).max(std::mem::size_of::<CdColour>() as u64);
        let mut sweeps = GpuSweeps { gpu, pipelines, buffers: Buffers::default(), bind_groups: Vec::new(), capacity: 0, colour_stride };
        let uniform = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        sweeps.buffer(Buf::Cd, std::mem::size_of::<CdParams>() as u64, uniform);
        sweeps.buffer(Buf::Phase, MAX_COLOURS as u64 * colour_stride, uniform);
        sweeps.buffer(Buf::Vel, 16 * grains.max(1) as u64, Self::STORAGE);
        sweeps.buffer(Buf::Omega, 16 * grains.max(1) as u64, Self::STORAGE);
        sweeps.buffer(Buf::WallVel, 16 * walls.max(1) as u64, Self::STORAGE);
        sweeps.buffer(Buf::Sweeps, std::mem::size_of::<CdControl>() as u64, Self::STORAGE);
        sweeps.grow(1024);
        sweeps
    }

    const STORAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_DST).union(wgpu::BufferUsages::COPY_SRC);

    fn buffer(&mut self, name: Buf, bytes: u64, usage: wgpu::BufferUsages) {
        let b = self.gpu.device.create_buffer(&wgpu::BufferDescriptor { label: Some(name.name()), size: bytes.max(16), usage, mapped_at_creation: false });
        self.buffers.insert(name, b);
    }

    /// Contact buffers for `capacity` contacts, and the bind groups over them.
    fn grow(&mut self, capacity: u64) {
        self.capacity = capacity;
        self.buffer(Buf::Contacts, capacity * std::mem::size_of::<CdContact>() as u64, Self::STORAGE);
        self.buffer(Buf::Impulse, 16 * capacity, Self::STORAGE);
        self.buffer(Buf::Measure, 8 * capacity, Self::STORAGE);
        self.buffer(Buf::Blocks, 8 * capacity.div_ceil(MEASURE_BLOCK as u64), Self::STORAGE);
        self.bind_groups = CdKernel::ALL
            .iter()
            .map(|&id| bind_group(&self.gpu.device, id.name(), id.kernel(), &self.pipelines[id as usize].0, |name| &self.buffers[name], std::mem::size_of::<CdColour>() as u64))
            .collect();
    }

    fn write<T: bytemuck::NoUninit>(&self, name: Buf, offset: u64, data: &[T]) {
        if !data.is_empty() {
            self.gpu.queue.write_buffer(&self.buffers[name], offset, bytemuck::cast_slice(data));
        }
    }

    /// Records `sweeps` sweeps over colours of the given sizes.
    fn record(&self, sweeps: u32, colour_sizes: &[usize], tail: bool, blocks: u64) {
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            let mut dispatch = |kernel: CdKernel, items: u64, offset: Option<u32>| {
                let (x, y) = crate::workgroup::groups(items);
                pass.set_pipeline(&self.pipelines[kernel as usize].1);
                pass.set_bind_group(0, &self.bind_groups[kernel as usize], offset.as_slice());
                pass.dispatch_workgroups(x, y, 1);
            };
            for _ in 0..sweeps {
                for (k, &size) in colour_sizes.iter().enumerate() {
                    dispatch(CdKernel::CdSweepColour, size as u64, Some((k as u64 * self.colour_stride) as u32));
                }
                if tail {
                    dispatch(CdKernel::CdSweepTail, 1, None);
                }
                if blocks > 0 {
                    dispatch(CdKernel::CdMeasure, blocks, None);
                }
                dispatch(CdKernel::CdDecide, 1, None);
            }
        }
        self.gpu.queue.submit([encoder.finish()]);
    }

    fn read(&self, parts: &[(Buf, u64)]) -> Result<Vec<Vec<u32>>, SimError> {
        let buffers: Vec<(&wgpu::Buffer, u64, u64)> = parts.iter().map(|&(name, bytes)| (&self.buffers[name], 0, bytes)).collect();
        read_back(&self.gpu, &buffers).map_err(|reason| SimError::Device { what: parts.iter().map(|p| p.0.name()).collect::<Vec<_>>().join(", "), reason })
    }
}

/// A contact as the kernels read it.
fn pack(c: &Contact<f32>) -> CdContact {
    let (b, to_wall) = match c.b {
        Partner::Grain(j) => (j, 0),
        Partner::Wall(w) => (w, 1),
    };
    CdContact {
        a: c.a,
        b,
        to_wall,
        n: glam::Vec4::new(c.n.x, c.n.y, c.n.z, c.u_min),
        radius_a: c.radius_a,
        radius_b: c.radius_b,
        mu: c.mu,
        w_n: c.w_n,
        w_t: c.w_t,
        inv_w_n: c.inv_w_n,
        inv_w_t: c.inv_w_t,
        inv_mass_a: c.inv_mass_a,
        inv_inertia_a: c.inv_inertia_a,
        inv_mass_b: c.inv_mass_b,
        inv_inertia_b: c.inv_inertia_b,
        ..Default::default()
    }
}

fn vec4(v: Vec3<f32>) -> [f32; 4] {
    [v.x, v.y, v.z, 0.0]
}

fn vec3(w: &[u32]) -> Vec3<f32> {
    Vec3::new(f32::from_bits(w[0]), f32::from_bits(w[1]), f32::from_bits(w[2]))
}

impl Sweeps<f32> for GpuSweeps {
    fn backend(&self) -> &'static str {
        "gpu"
    }

    fn solve(&mut self, contacts: &mut [Contact<f32>], schedule: &Schedule, body: &mut [Body<f32>], walls: &mut [WallMotion<f32>], settings: SweepSettings<f32>) -> Result<Solved, SimError> {
        let n = contacts.len() as u64;
        if n > self.capacity {
            self.grow(n.next_power_of_two());
        }
        let blocks = n.div_ceil(MEASURE_BLOCK as u64);
        let tail = schedule.tail();
        let params = CdParams { n_contacts: n as u32, tail: tail as u32, n_blocks: blocks as u32, max_iterations: settings.max_iterations, tolerance2: settings.tolerance * settings.tolerance, relaxation: settings.relaxation, ..Default::default() };
        self.write(Buf::Cd, 0, &[params]);
        let colour_sizes: Vec<usize> = schedule.colours().map(|r| r.len()).collect();
        for (k, range) in schedule.colours().enumerate() {
            self.write(Buf::Phase, k as u64 * self.colour_stride, &[CdColour { start: range.start as u32, end: range.end as u32, ..Default::default() }]);
        }
        self.write(Buf::Contacts, 0, &contacts.iter().map(pack).collect::<Vec<_>>());
        self.write(Buf::Impulse, 0, &contacts.iter().map(|c| vec4(c.r)).collect::<Vec<_>>());
        self.write(Buf::Vel, 0, &body.iter().map(|b| vec4(b.vel)).collect::<Vec<_>>());
        self.write(Buf::Omega, 0, &body.iter().map(|b| vec4(b.omega)).collect::<Vec<_>>());
        self.write(Buf::WallVel, 0, &walls.iter().map(|w| vec4(w.vel)).collect::<Vec<_>>());
        self.write(Buf::Sweeps, 0, &[CdControl::default()]);
        let mut batch = 1;
        let control = loop {
            self.record(batch, &colour_sizes, tail < contacts.len(), blocks);
            let words = self.read(&[(Buf::Sweeps, std::mem::size_of::<CdControl>() as u64)])?;
            let control: CdControl = *bytemuck::from_bytes(bytemuck::cast_slice(&words[0]));
            if control.done != 0 {
                break control;
            }
            batch = (2 * batch).min(MAX_SWEEPS_PER_SUBMIT);
        };
        let (grains, nw) = (16 * body.len() as u64, 16 * walls.len() as u64);
        let out = self.read(&[(Buf::Impulse, 16 * n), (Buf::Vel, grains), (Buf::Omega, grains), (Buf::WallVel, nw)])?;
        for (c, w) in contacts.iter_mut().zip(out[0].chunks_exact(4)) {
            c.r = vec3(w);
        }
        for ((b, v), o) in body.iter_mut().zip(out[1].chunks_exact(4)).zip(out[2].chunks_exact(4)) {
            (b.vel, b.omega) = (vec3(v), vec3(o));
        }
        for (m, v) in walls.iter_mut().zip(out[3].chunks_exact(4)) {
            m.vel = vec3(v);
        }
        Ok(Solved { iterations: control.iterations, converged: control.converged != 0, sweep_norm: (control.sweep_norm2 as f64).sqrt() })
    }
}

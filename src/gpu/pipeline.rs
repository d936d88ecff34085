//! What every GPU solver builds alike from the kernel table: a kernel's bind group layout and
//! pipeline, its buffers by name, a bind group over them, and buffers read back to the host.

use super::device::Gpu;
use crate::gpu::kernels::{Access, Buf, Kernel};

/// A solver's device buffers, one per [`Buf`] it uses.
#[derive(Default)]
pub struct Buffers(Vec<Option<wgpu::Buffer>>);

impl Buffers {
    /// Holds `buffer` as `name`'s, replacing the one held before.
    pub fn insert(&mut self, name: Buf, buffer: wgpu::Buffer) {
        let at = name as usize;
        if self.0.len() <= at {
            self.0.resize_with(at + 1, || None);
        }
        self.0[at] = Some(buffer);
    }

    /// The buffer of `name`, if the solver holds one.
    pub fn get(&self, name: Buf) -> Option<&wgpu::Buffer> {
        self.0.get(name as usize).and_then(Option::as_ref)
    }

    /// Every buffer held, with its name, in the order of [`Buf`].
    pub fn iter(&self) -> impl Iterator<Item = (Buf, &wgpu::Buffer)> {
        Buf::ALL.iter().filter_map(|&name| self.get(name).map(|b| (name, b)))
    }

    /// The bytes of all the buffers held.
    pub fn bytes(&self) -> u64 {
        self.iter().map(|(_, b)| b.size()).sum()
    }
}

impl std::ops::Index<Buf> for Buffers {
    type Output = wgpu::Buffer;

    /// The buffer of `name`; a solver asks only for the buffers it made.
    fn index(&self, name: Buf) -> &wgpu::Buffer {
        self.get(name).unwrap_or_else(|| panic!("no GPU buffer `{}`: the solver made none", name.name()))
    }
}

/// A kernel's bind group layout and compute pipeline, its override constants set to `constants`.
pub fn compute_pipeline(device: &wgpu::Device, k: &Kernel, constants: &[(&str, f64)]) -> (wgpu::BindGroupLayout, wgpu::ComputePipeline) {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = k
        .bindings
        .iter()
        .enumerate()
        .map(|(i, (_, access))| wgpu::BindGroupLayoutEntry {
            binding: i as u32,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: match access {
                    Access::Uniform | Access::Phase => wgpu::BufferBindingType::Uniform,
                    Access::Read => wgpu::BufferBindingType::Storage { read_only: true },
                    Access::ReadWrite | Access::Write => wgpu::BufferBindingType::Storage { read_only: false },
                },
                has_dynamic_offset: *access == Access::Phase,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(k.name), entries: &entries });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some(k.name), bind_group_layouts: &[Some(&layout)], ..Default::default() });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(k.name), source: wgpu::ShaderSource::Wgsl(k.wgsl().into()) });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(k.name),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some(k.name),
        compilation_options: wgpu::PipelineCompilationOptions { constants, zero_initialize_workgroup_memory: true },
        cache: None,
    });
    (layout, pipeline)
}

/// A bind group of kernel `k` over the buffers `buffer` gives for its bindings; the `Phase`
/// binding (at a dynamic offset) sees `phase_bytes` of its buffer.
pub fn bind_group<'a>(device: &wgpu::Device, label: &str, k: &Kernel, layout: &wgpu::BindGroupLayout, buffer: impl Fn(Buf) -> &'a wgpu::Buffer, phase_bytes: u64) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = k
        .bindings
        .iter()
        .enumerate()
        .map(|(i, &(name, access))| {
            let buffer = buffer(name);
            let resource = if access == Access::Phase {
                wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer, offset: 0, size: wgpu::BufferSize::new(phase_bytes) })
            } else {
                buffer.as_entire_binding()
            };
            wgpu::BindGroupEntry { binding: i as u32, resource }
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

/// Copies `(buffer, offset, bytes)` parts out, returned in order as 4-byte words (every type
/// the kernels share is 4-byte aligned); the driver's reason when the device fails to answer.
pub fn read_back(gpu: &Gpu, parts: &[(&wgpu::Buffer, u64, u64)]) -> Result<Vec<Vec<u32>>, String> {
    let total: u64 = parts.iter().map(|p| p.2.next_multiple_of(4)).sum();
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor { label: Some("readback"), size: total.max(4), usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST, mapped_at_creation: false });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let mut at = 0;
    for &(buffer, offset, bytes) in parts {
        encoder.copy_buffer_to_buffer(buffer, offset, &staging, at, bytes.next_multiple_of(4));
        at += bytes.next_multiple_of(4);
    }
    gpu.queue.submit([encoder.finish()]);
    let (sent, mapped) = std::sync::mpsc::channel();
    staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        // The receiver waits below; a send fails only if it is gone, and then nobody asks.
        sent.send(r).ok();
    });
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| e.to_string())?;
    mapped.recv().map_err(|e| e.to_string())?.map_err(|e| e.to_string())?;
    let view = staging.slice(..).get_mapped_range().map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    let mut at = 0usize;
    for &(_, _, bytes) in parts {
        out.push(bytemuck::pod_collect_to_vec(&view[at..at + bytes as usize]));
        at += bytes.next_multiple_of(4) as usize;
    }
    Ok(out)
}

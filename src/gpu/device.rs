//! Adapters and devices: listing, choosing the best (or a named) adapter, opening it with its
//! own limits rather than WebGPU's defaults.

use crate::gpu::kernels::{Access, CD_KERNELS, KERNELS};

/// Backends tried: Vulkan (every desktop OS, and lavapipe without a GPU), Metal, DX12. GL is
/// left out: it lacks the storage-buffer counts the kernels need, and with it a missing
/// Vulkan would silently fall back to llvmpipe's GL.
pub fn backends() -> wgpu::Backends {
    wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12
}

/// Why no device could be opened.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter at all.
    #[error(
        "no GPU adapter found (Vulkan, Metal or DX12); fix: install a driver (on Debian/Ubuntu without a GPU, `apt install mesa-vulkan-drivers libvulkan1` gives the software Vulkan driver lavapipe) or run with --backend cpu"
    )]
    NoAdapter,
    /// `--adapter NAME` matched nothing.
    #[error("no GPU adapter matches \"{name}\" (found: {found}); fix: pick one of those names (`grains devices` lists them)")]
    NoMatch {
        /// The name asked for.
        name: String,
        /// Adapters present.
        found: String,
    },
    /// The adapter's limits are below what the kernels need.
    #[error("GPU adapter \"{adapter}\" allows {have} {what}, the kernels need {need}; fix: use another adapter or --backend cpu")]
    Limit {
        /// Adapter name.
        adapter: String,
        /// Which limit.
        what: &'static str,
        /// What it allows.
        have: u64,
        /// What is needed.
        need: u64,
    },
    /// Device creation failed.
    #[error("cannot open GPU adapter \"{adapter}\": {reason}; fix: update the driver or run with --backend cpu")]
    Device {
        /// Adapter name.
        adapter: String,
        /// The driver's reason.
        reason: String,
    },
}

/// An opened device.
pub struct Gpu {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter says of itself.
    pub info: wgpu::AdapterInfo,
    /// The limits the device was opened with (the adapter's own).
    pub limits: wgpu::Limits,
}

/// Every adapter of the enabled backends.
pub fn adapters() -> Vec<wgpu::Adapter> {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = backends();
    let instance = wgpu::Instance::new(desc);
    pollster::block_on(instance.enumerate_adapters(backends()))
}

/// Preference of a device type: discrete GPUs first, software last.
fn rank(t: wgpu::DeviceType) -> u32 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// Storage buffers the busiest kernel binds.
pub fn storage_buffers_needed() -> u64 {
    KERNELS.iter().chain(CD_KERNELS).map(|k| k.bindings.iter().filter(|(_, a)| matches!(a, Access::Read | Access::ReadWrite | Access::Write)).count() as u64).max().unwrap_or(0)
}

/// Opens the best adapter, or the first whose name contains `name` (case-insensitive).
pub fn open(name: Option<&str>) -> Result<Gpu, GpuError> {
    let mut list = adapters();
    if list.is_empty() {
        return Err(GpuError::NoAdapter);
    }
    list.sort_by_key(|a| rank(a.get_info().device_type));
    let adapter = match name {
        None => list.into_iter().next().expect("non-empty"),
        Some(n) => {
            let found = list.iter().map(|a| a.get_info().name).collect::<Vec<_>>().join(", ");
            let lower = n.to_lowercase();
            list.into_iter().find(|a| a.get_info().name.to_lowercase().contains(&lower)).ok_or(GpuError::NoMatch { name: n.to_string(), found })?
        }
    };
    let info = adapter.get_info();
    let limits = adapter.limits();
    let need = storage_buffers_needed();
    if (limits.max_storage_buffers_per_shader_stage as u64) < need {
        return Err(GpuError::Limit { adapter: info.name, what: "storage buffers per shader stage", have: limits.max_storage_buffers_per_shader_stage as u64, need });
    }
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("grains"),
        required_features: wgpu::Features::empty(),
        required_limits: limits.clone(),
        ..Default::default()
    }))
    .map_err(|e| GpuError::Device { adapter: info.name.clone(), reason: e.to_string() })?;
    Ok(Gpu { device, queue, info, limits })
}

/// One line per adapter for `grains devices`: name, backend, type, driver and the limits
/// that bound a run.
pub fn describe_all() -> Vec<String> {
    let mut list = adapters();
    list.sort_by_key(|a| rank(a.get_info().device_type));
    list.iter()
        .map(|a| {
            let i = a.get_info();
            let l = a.limits();
            format!(
                "{} | {:?} | {:?} | driver {} {} | storage buffers/stage {}, storage binding {} MiB, buffer {} MiB, workgroups/dim {}",
                i.name,
                i.backend,
                i.device_type,
                i.driver,
                i.driver_info,
                l.max_storage_buffers_per_shader_stage,
                l.max_storage_buffer_binding_size / (1 << 20),
                l.max_buffer_size / (1 << 20),
                l.max_compute_workgroups_per_dimension
            )
        })
        .collect()
}

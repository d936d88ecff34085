//! The GPU engine: the step's kernels in WGSL (`shaders/`) through wgpu, f32, deterministic
//! run to run (integer atomics only; sums in fixed trees).

pub mod device;
mod engine;
pub mod kernels;
pub mod layout;
mod pipeline;
mod sweeps;
pub mod plan;

pub use device::{describe_all, open, Gpu, GpuError};
pub use sweeps::{GpuSweeps, MAX_SWEEPS_PER_SUBMIT};
pub use engine::{GpuEngine, GpuSetupError, PAIR_GROWTH, PAIR_GROWTH_THRESHOLD, PAIR_HEADROOM, STEPS_PER_SUBMIT, SUBMITS_PER_CHECK};

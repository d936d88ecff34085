//! The GPU engine: the kernels in WGSL through wgpu.

pub mod layout;

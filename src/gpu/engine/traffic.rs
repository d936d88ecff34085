//! The bytes a step that keeps its neighbour list moves to and from the GPU's memory, counted
//! from the kernel table: each kernel the plan dispatches with work (the rebuild kernels run
//! with zero workgroups on such steps; `decide_rebuild` runs) streams each storage buffer it
//! binds once: a read-only one read, a read-write one read and written, one the kernel only
//! stores to ([`Access::Write`]) written; the per-pair buffers at the live pair count.

use super::*;
use crate::gpu::kernels::Access;

impl GpuEngine {
    /// Bytes each kernel of a later step moves, by kernel, in dispatch order.
    pub(super) fn traffic(&self) -> Vec<(&'static str, u64)> {
        let pairs = self.control.n_pairs as u64;
        let per_pair = self.pair_buffers();
        let used = |name: Buf| match per_pair.iter().find(|p| p.0 == name) {
            Some(&(_, bytes)) => bytes * pairs,
            None => self.buffers.get(name).map_or(0, wgpu::Buffer::size),
        };
        let moved = |kernel: StepKernel| -> u64 {
            kernel
                .kernel()
                .bindings
                .iter()
                .map(|&(buffer, access)| match access {
                    Access::Read | Access::Write => used(buffer),
                    Access::ReadWrite => 2 * used(buffer),
                    Access::Uniform | Access::Phase => 0,
                })
                .sum()
        };
        let mut out: Vec<(&'static str, u64)> = Vec::new();
        // A later step inside a run of steps.
        for e in &self.plans.step_in_run(1, true, true) {
            let kernels: Vec<StepKernel> = if e.dispatch == Dispatch::RebuildIfNeeded { vec![StepKernel::DecideRebuild] } else { self.kernels_of(e).into_iter().map(|k| k.0).collect() };
            for kernel in kernels {
                match out.iter_mut().find(|x| x.0 == kernel.name()) {
                    Some(x) => x.1 += moved(kernel),
                    None => out.push((kernel.name(), moved(kernel))),
                }
            }
        }
        out
    }
}

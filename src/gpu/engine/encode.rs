//! Encoding the step: the plan's dispatches into a compute pass.

use super::buffers::Scan;
use super::*;

/// The steps' own sizes: every grain, or one workgroup, until a pair buffer overflow stops
/// the run (then zero).
const STEP_GRAINS: Size = Size::Indirect(args::STEP_GRAINS);
const STEP_ONE: Size = Size::Indirect(args::STEP_ONE);

/// How a kernel is dispatched.
#[derive(Clone, Copy, Debug)]
pub(super) enum Size {
    /// One invocation per grain.
    Grains,
    /// One workgroup.
    One,
    /// From an indirect-argument slot.
    Indirect(u64),
}

impl GpuEngine {
    pub(super) fn dispatch(&self, pass: &mut wgpu::ComputePass, kernel: StepKernel, scan: Option<Scan>, size: Size, phase: Option<Phase>) {
        pass.set_pipeline(&self.pipelines[kernel as usize]);
        // A kernel with a phase binding is given its phase; the others none.
        let slot = |p: Phase| self.phases.iter().position(|q| *q == p).expect("every phase of the plans has a uniform slot");
        let offsets: Vec<u32> = phase.map(|p| (slot(p) as u64 * self.phase_stride) as u32).into_iter().collect();
        pass.set_bind_group(0, &self.bind_groups[&(kernel, scan)], &offsets);
        self.dispatches.set(self.dispatches.get() + 1);
        match size {
            Size::Grains => {
                let (x, y) = crate::workgroup::groups(self.n as u64);
                pass.dispatch_workgroups(x, y, 1);
            }
            Size::One => pass.dispatch_workgroups(1, 1, 1),
            Size::Indirect(slot) => pass.dispatch_workgroups_indirect(&self.buffers[Buf::Args], slot * std::mem::size_of::<DispatchArgs>() as u64),
        }
    }

    pub(super) fn run(&self, pass: &mut wgpu::ComputePass, kernel: StepKernel, size: Size, phase: Option<Phase>) {
        self.dispatch(pass, kernel, None, size, phase);
    }

    /// Exclusive scan of an array of `elements`: blocks, the blocks' totals, then the offsets
    /// added back (the last two only when there is more than one block).
    pub(super) fn scan(&self, pass: &mut wgpu::ComputePass, array: Scan, sums: Scan, blocks: u64, elements: u64) {
        self.dispatch(pass, StepKernel::ScanBlocks, Some(array), Size::Indirect(blocks), None);
        // An array of one block is scanned by then: its offset would be 0.
        if elements <= SCAN_BLOCK {
            return;
        }
        self.dispatch(pass, StepKernel::ScanBlocks, Some(sums), Size::Indirect(args::ONE), None);
        self.dispatch(pass, StepKernel::ScanAdd, Some(array), Size::Indirect(blocks), None);
    }

    /// `decide_rebuild` and the rebuild kernels, which run with zero workgroups when the
    /// list is still good.
    pub(super) fn encode_rebuild_if_needed(&self, pass: &mut wgpu::ComputePass) {
        self.run(pass, StepKernel::DecideRebuild, Size::One, None);
        if self.params.hist_blocks > 0 {
            self.run(pass, StepKernel::SaveStarts, Size::Indirect(args::GRAIN_STARTS), None);
            self.run(pass, StepKernel::SavePairs, Size::Indirect(args::OLD_PAIRS), None);
        }
        self.encode_pair_count(pass);
        self.encode_list_fill(pass);
    }

    /// The rebuild from its pair count on: `pairs_ready` (which stops the run instead where
    /// the new list outgrows the pair buffers), the new list, its history and its reverse
    /// lists. A rebuild stopped there goes on from here once the buffers have grown.
    pub(super) fn encode_list_fill(&self, pass: &mut wgpu::ComputePass) {
        self.run(pass, StepKernel::PairsReady, Size::One, None);
        self.run(pass, StepKernel::DetectFill, Size::Indirect(args::GRAINS), None);
        if self.params.hist_blocks > 0 {
            self.run(pass, StepKernel::RemapHistory, Size::Indirect(args::NEW_PAIRS), None);
        }
        self.run(pass, StepKernel::ReverseCount, Size::Indirect(args::NEW_PAIRS), None);
        self.scan(pass, Scan::RevStarts, Scan::GrainSums, args::GRAIN_BLOCKS, self.n as u64 + 1);
        self.run(pass, StepKernel::ReverseFill, Size::Indirect(args::NEW_PAIRS), None);
        self.run(pass, StepKernel::ReverseSort, Size::Indirect(args::GRAINS), None);
    }

    /// The rebuild's hashing and pair count, at the sizes `decide_rebuild` wrote: then
    /// `pair_start` holds each grain's first pair and, last, the number of pairs.
    pub(super) fn encode_pair_count(&self, pass: &mut wgpu::ComputePass) {
        self.run(pass, StepKernel::ClearCells, Size::Indirect(args::HASH), None);
        self.run(pass, StepKernel::HashCells, Size::Indirect(args::GRAINS), None);
        self.scan(pass, Scan::Cells, Scan::CellSums, args::HASH_BLOCKS, self.params.hash_size as u64);
        self.run(pass, StepKernel::ScatterCells, Size::Indirect(args::GRAINS), None);
        self.run(pass, StepKernel::DetectCount, Size::Indirect(args::GRAINS), None);
        self.scan(pass, Scan::PairStarts, Scan::GrainSums, args::GRAIN_BLOCKS, self.n as u64 + 1);
    }

    /// The kernels of a plan entry other than the rebuild check, with their sizes and phases
    /// (from the steps' own indirect slots, which a pair buffer overflow zeroes):
    /// `integrate` (then `servo_move` after a drift in servo scenes); or
    /// `find_bridge_events` and `update_bridges` (capillary scenes), `pair_force`,
    /// `gather` (with the wall contacts, and the kick after it), `wall_reduce` (and the
    /// piston's kick) where there are walls, then `servo_move` where they carry a drift in
    /// servo scenes; nothing for a carried entry.
    pub(super) fn kernels_of(&self, e: &Entry) -> Vec<(StepKernel, Size, Option<Phase>)> {
        let phase = Some(e.phase);
        let mut k = Vec::new();
        match e.dispatch {
            Dispatch::Integrate => {
                k.push((StepKernel::Integrate, STEP_GRAINS, phase));
                if self.servo.is_some() && e.phase.drift > 0.0 {
                    k.push((StepKernel::ServoMove, STEP_ONE, phase));
                }
            }
            Dispatch::RebuildIfNeeded | Dispatch::Carried => {}
            Dispatch::Forces => {
                if self.history.bridge {
                    k.push((StepKernel::FindBridgeEvents, Size::Indirect(args::PAIRS), None));
                    k.push((StepKernel::UpdateBridges, STEP_ONE, None));
                }
                k.push((StepKernel::PairForce, Size::Indirect(args::PAIRS), phase));
                k.push((StepKernel::Gather, STEP_GRAINS, phase));
                if self.has_walls {
                    k.push((StepKernel::WallReduce, STEP_ONE, phase));
                }
                if self.servo.is_some() && e.phase.drift > 0.0 {
                    k.push((StepKernel::ServoMove, STEP_ONE, phase));
                }
            }
        }
        k
    }

    /// Encodes one entry of a plan.
    pub(super) fn encode(&self, pass: &mut wgpu::ComputePass, e: &Entry) {
        if e.dispatch == Dispatch::RebuildIfNeeded {
            return self.encode_rebuild_if_needed(pass);
        }
        for (kernel, size, phase) in self.kernels_of(e) {
            self.run(pass, kernel, size, phase);
        }
    }

    /// Encodes the plan of step number `step`, or the prologue's with `None`, and traces its
    /// operations; inside a run of steps, its first entry left to the step before
    /// (`carried_in`) and the next step's run in its last (`carry_out`). Each rebuild check
    /// is marked, where the run may stop ([`RebuildMark`]).
    pub(super) fn encode_plan(&mut self, pass: &mut wgpu::ComputePass, step: Option<u64>, carried_in: bool, carry_out: bool) {
        let at = RebuildMark { plan: step, entry: 0, carried_in, carry_out, step: self.step, time: self.time, traced: 0 };
        self.encode_entries(pass, at);
    }

    /// Encodes the entries of `at`'s plan from `at.entry` on, marking each rebuild check.
    pub(super) fn encode_entries(&mut self, pass: &mut wgpu::ComputePass, at: RebuildMark) {
        let entries = self.plan_of(&at);
        for (k, e) in entries.iter().enumerate().skip(at.entry) {
            if e.dispatch == Dispatch::RebuildIfNeeded {
                self.marks.push(RebuildMark { entry: k, traced: self.trace.ops().len(), ..at });
            }
            self.encode(pass, e);
            for &op in &e.ops {
                self.trace.record(op);
            }
        }
    }

    /// The entries of the plan `at` belongs to.
    pub(super) fn plan_of(&self, at: &RebuildMark) -> Vec<Entry> {
        match at.plan {
            None => self.plans.prologue.clone(),
            Some(n) => self.plans.step_in_run(n, at.carried_in, at.carry_out),
        }
    }

    /// Runs the schedule's prologue (the list built if need be, forces evaluated) where
    /// nothing has evaluated the loads yet: before the first step, or after wetting.
    pub(super) fn ensure_loads(&mut self) -> Result<(), SimError> {
        if self.forces_valid {
            return Ok(());
        }
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.encode_plan(&mut pass, None, false, false);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.forces_valid = true;
        self.check()
    }

    /// Starts recording the operations encoded (see [`Trace`]).
    pub fn trace_schedule(&mut self) {
        self.trace.start();
    }

    /// The operations encoded since [`Self::trace_schedule`].
    pub fn traced(&self) -> &[Op] {
        self.trace.ops()
    }
}

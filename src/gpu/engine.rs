//! The GPU engine: buffers (structure of arrays, f32), one pipeline per kernel specialised to
//! the scene's laws by override constants, and the step as the dispatches of the schedule's
//! plan ([`super::plan`]). Whether
//! a step rebuilds the neighbour list is decided on the GPU (`decide_rebuild` writes the
//! rebuild kernels' indirect dispatch sizes), so the host only records steps and reads a few
//! statistics back every `stats_interval` steps.

mod buffers;
mod contract;
mod encode;
mod play;
mod readback;
mod setup;
mod snapshot;
mod traffic;

use glam::{UVec4, Vec4};
use super::device::Gpu;
use encode::Size;
use super::layout::{self, args, Control, DispatchArgs, Params, Phase, MAX_SCAN, MAX_WALLS, NONE, SCAN_BLOCK, STAT_ROW};
use crate::engine::{ContactRecord, Engine, Frame, PistonStats, SimError, Stats, WallStats};
use crate::gpu::kernels::{Buf, StepKernel};
use super::pipeline::Buffers;
use crate::model::{HistoryLayout, NormalSetup, PairCoeffs, RollingFriction, TangentialLaw};
use super::plan::{Dispatch, Entry, Plans};
use crate::schedule::{Op, Schedule, Trace};
use crate::scene::{Scene, WallShape};
use std::collections::HashMap;
use crate::workgroup;
use wgpu::util::DeviceExt;

/// The pair buffers start with room for this many times the pairs of the first list (counted
/// before the first step), and for one pair per grain at least. They need no more margin: a
/// rebuild whose list outgrows them stops the run where it is, and the host grows them and
/// goes on with the same bits ([`readback`]'s `check`). A dense packing with a skin of a tenth
/// of a diameter lists about 3.7 pairs per grain: 76 B per pair of room on a dry bed.
pub const PAIR_HEADROOM: f64 = 1.1;
/// Fill fraction of the pair buffers that makes them grow at a check, before a rebuild has to
/// stop on them: above the first list's share, so that a list that does not grow keeps the
/// buffers it started with.
pub const PAIR_GROWTH_THRESHOLD: f64 = 0.95;
const _: () = assert!(PAIR_GROWTH_THRESHOLD * PAIR_HEADROOM > 1.0);
/// Pairs the buffers grow to, over the pairs in use (at a check) or needed (after a stop).
pub const PAIR_GROWTH: f64 = 1.5;
/// Steps recorded per queue submission.
pub const STEPS_PER_SUBMIT: u64 = 16;
/// Submissions between two checks of the control record inside one `advance` (the pair
/// buffers grow at a check, so a long advance over a compacting pour checks every 512 steps
/// rather than only at its end; each check waits for the device once).
pub const SUBMITS_PER_CHECK: u64 = 32;

/// Buffers a checkpoint leaves out: the scene's constants (set up again from the scene) and
/// scratch space every step or statistics read rewrites before reading it.
const NOT_STATE: [Buf; 17] = [
    Buf::Params, Buf::Phase, Buf::Material, Buf::Coeffs, Buf::Meshes, Buf::MeshData, Buf::MeshIndex, // constants
    Buf::CellCount, Buf::CellFill, Buf::HashSums, Buf::GrainSums, Buf::SpareSum, // the hash grid
    Buf::BridgeEvent, // bridge scratch
    Buf::WallPartials, Buf::GrainRows, Buf::PairRows, Buf::Stats, // reductions
];

/// The rebuild's scratch, as (binding, buffer): the replaced list's partners and history
/// blocks (`save_pairs`, `remap_history`) are kept in buffers that nothing reads before they
/// are rewritten: `rev_pair` (rewritten by the rebuild's `reverse_fill`) and the pair force
/// records (rewritten by the force evaluation every plan runs after a rebuild, and read only
/// after it). The replaced list needs no buffers of its own: 20 bytes per pair of capacity on
/// a dry bed, 36 with rolling springs. Likewise `reverse_fill`'s per-grain counters sit in
/// `cell_fill` (hash buckets, at least one per grain), dead once `scatter_cells` has run;
/// `detect_count` clears them. And the per-grain scratch of the rebuild (the saved pair starts,
/// 4 B per grain and one; each grain's bucket and the grains sorted by bucket, 4 B per grain
/// each) sits in buffers dead between the kick that reads the last loads and the evaluation
/// that rewrites them, where every rebuild runs (`force`, `torque`: 16 B per grain), or
/// between one evaluation's `wall_reduce` and the next one's gather (`wall_partials`: 256 B
/// per 64 grains).
const REBUILD_SCRATCH: [(Buf, Buf); 8] = [
    (Buf::OldJ, Buf::RevPair),
    (Buf::OldHist0, Buf::OutFi),
    (Buf::OldHist1, Buf::OutTj),
    (Buf::OldHist2, Buf::OutTi),
    (Buf::RevFill, Buf::CellFill),
    (Buf::OldStart, Buf::Force),
    (Buf::CellOf, Buf::Torque),
    (Buf::CellGrains, Buf::WallPartials),
];

/// Why the GPU engine refused a scene.
#[derive(Debug, thiserror::Error)]
pub enum GpuSetupError {
    /// The scene exceeds a limit of the device or of the kernels.
    #[error("the scene needs {need} {what}, the GPU backend allows {have} on \"{adapter}\"; fix: {fix}")]
    Limit {
        /// Adapter.
        adapter: String,
        /// What.
        what: &'static str,
        /// Needed.
        need: u64,
        /// Allowed.
        have: u64,
        /// How to fix.
        fix: &'static str,
    },
    /// The device had not the memory for the scene's buffers.
    #[error("\"{adapter}\" could not allocate the {mib:.0} MiB of buffers the scene needs: {reason}; fix: run fewer grains on this device, or run with --backend cpu")]
    Memory {
        /// Adapter.
        adapter: String,
        /// The buffers' size (MiB).
        mib: f64,
        /// The driver's reason.
        reason: String,
    },
}

/// The GPU engine (f32).
pub struct GpuEngine {
    gpu: Gpu,
    n: u32,
    params: Params,
    /// How the schedule's prologue, first step and later steps are encoded.
    plans: Plans,
    /// The phases of the plans, in the order of their uniform slots in `phase`.
    phases: Vec<Phase>,
    /// The operations encoded, when tracing.
    trace: Trace,
    dt: f64,
    /// Each kernel's bind group layout and pipeline, indexed by [`StepKernel`].
    layouts: Vec<wgpu::BindGroupLayout>,
    pipelines: Vec<wgpu::ComputePipeline>,
    buffers: Buffers,
    /// Each kernel's bind group, and the scan kernels' one per scanned array.
    bind_groups: HashMap<(StepKernel, Option<buffers::Scan>), wgpu::BindGroup>,
    phase_stride: u64,
    has_walls: bool,
    history: HistoryLayout,
    track_orientation: bool,
    wall_names: Vec<String>,
    /// Each wall's [`layout::wall_flags`] as the walls buffer holds them (the host changes
    /// them, the kernels only read them).
    wall_flags: Vec<u32>,
    /// Each grain's radius (m) and mass (kg) as the kernels hold them, for the grains the
    /// host puts into play or out of it ([`play`]).
    radius: Vec<f32>,
    mass: Vec<f32>,
    /// Whether each grain is in play, as `pos.w`'s sign says (WGSL `in_play`).
    in_play: Vec<bool>,
    /// The mesh walls' surfaces in f32, for the host's re-evaluation of wall contacts.
    meshes: Vec<crate::mesh::MeshSurface<f32>>,
    /// The mesh walls' names, in their order.
    mesh_names: Vec<String>,
    piston: Option<usize>,
    /// The servo box's planes (x_min, x_max, y_min, y_max, z_min, z_max), if any.
    servo: Option<[usize; 6]>,
    /// Wrapping axes, for the host's own geometry (wetting).
    periodic: crate::periodic::Periodic<f32>,
    /// The contact model and coefficients in f32, for re-evaluating wall contacts on the host.
    model: crate::model::ContactModel<f32>,
    coeffs: Vec<PairCoeffs<f32>>,
    n_materials: usize,
    step: u64,
    time: f64,
    forces_valid: bool,
    control: Control,
    /// The rebuild checks encoded since the last check of the control record, in order: where
    /// a run stopped on full pair buffers goes on.
    marks: Vec<RebuildMark>,
    /// The device's count of rebuild checks run (`Control::rebuild_checks`) at the last check.
    marks_base: u32,
    /// Rebuilds that stopped on full pair buffers and went on once they had grown.
    pair_stops: u64,
    /// Whether the pair buffers grow at checks before a rebuild has to stop on them, and with
    /// a margin ([`PAIR_GROWTH`]) after a stop.
    grow_ahead: bool,
    /// Dispatches recorded so far.
    dispatches: std::cell::Cell<u64>,
}

/// A rebuild check as encoded: the plan it belongs to, its entry there, and the step, time
/// and trace length before it.
#[derive(Clone, Copy, Debug)]
struct RebuildMark {
    /// The step number of the plan, or `None` for the prologue.
    plan: Option<u64>,
    /// Index of the rebuild check among the plan's entries.
    entry: usize,
    /// The plan's first entry left to the step before ([`Plans::step_in_run`]).
    carried_in: bool,
    /// The next step's first entry run in the plan's last.
    carry_out: bool,
    /// The engine's step counter while the plan runs.
    step: u64,
    /// Its time (s).
    time: f64,
    /// Operations traced before the rebuild check.
    traced: usize,
}

impl GpuEngine {
    /// Sets the engine up for a scene on an opened device, with pair buffers sized for the
    /// first neighbour list ([`PAIR_HEADROOM`]).
    pub fn new(gpu: Gpu, scene: &Scene) -> Result<Self, anyhow::Error> {
        Self::with_pair_capacity(gpu, scene, None)
    }

    /// [`Self::new`] with pair buffers for `pairs` pairs to start with, where given, instead
    /// of the first list's count, and which grow only when a rebuild's list outgrows them, to
    /// that list's pairs exactly (that rebuild stops the run until they have grown; the path
    /// the tests take on purpose), not ahead of it at the checks: for a caller that knows the
    /// list a run will reach, or that would rather hold no margin at all.
    pub fn with_pair_capacity(gpu: Gpu, scene: &Scene, pairs: Option<u64>) -> Result<Self, anyhow::Error> {
        let n = scene.grains.len() as u64;
        let adapter = gpu.info.name.clone();
        let limit = |what, need: u64, have: u64, fix| -> Result<(), GpuSetupError> {
            if need > have { Err(GpuSetupError::Limit { adapter: adapter.clone(), what, need, have, fix }) } else { Ok(()) }
        };
        if let crate::scene::Method::ContactDynamics(_) = scene.method {
            anyhow::bail!("{}: simulation.method = \"contact_dynamics\" has no DEM kernels; fix: build its engine with grains::runner::gpu_engine", scene.path.display());
        }
        let binding = gpu.limits.max_storage_buffer_binding_size;
        limit("walls", scene.walls.len() as u64, MAX_WALLS as u64, "split the container into at most 8 walls or use --backend cpu")?;
        limit("bytes per grain array (16 per grain)", 16 * n, binding, "use fewer grains per run or a device with larger storage bindings")?;
        let hash_size = (n.max(64)).next_power_of_two();
        limit("scan elements (hash buckets)", hash_size, MAX_SCAN, "use fewer grains per run (the two-level scan holds 4,194,304)")?;
        let layout_of_history = scene.model.history_layout();
        let hist_blocks = layout::history_blocks(layout_of_history) as u64;
        let per_pair_bytes = 16 * hist_blocks.max(1);
        // Room for the first list comes once its pairs are counted (make_room_for_the_first_list).
        let pair_capacity = pairs.unwrap_or(n.max(1024)).max(1).min(binding / per_pair_bytes).min(binding / 16);
        let mut params = setup::params_of(scene, pair_capacity, hash_size, hist_blocks);
        let (walls, piston, wall_blocks) = setup::walls_of(scene, hist_blocks as u32);
        let wall_flags = walls.iter().map(|w| w.flags).collect();
        params.wall_blocks = wall_blocks;
        limit("bytes of wall history", 16 * n * wall_blocks as u64, binding, "use fewer walls or grains")?;
        if let Some(p) = piston {
            params.piston = p as u32;
        }
        let control = Control { max_disp2: f32::INFINITY.to_bits(), overflow_grain: NONE, non_finite: NONE, mesh_overflow: NONE, ..Default::default() };
        let phase_stride = (gpu.limits.min_uniform_buffer_offset_alignment as u64).max(std::mem::size_of::<Phase>() as u64);
        let dt = scene.time_step.dt;
        let plans = Plans::of(&Schedule::new(scene.integrator, dt));
        let (phases, phase_bytes) = setup::phase_slots(&plans, phase_stride);
        // A device without the memory reports it here, not through wgpu's handler (a panic).
        let out_of_memory = gpu.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        // The mesh walls' surfaces: the kernels' buffers and the host's re-evaluation share them.
        let meshes = scene.mesh_surfaces::<f32>();
        let buffers = setup::scene_buffers(&gpu.device, scene, &params, walls, &meshes, &control, &phase_bytes);
        if let Some(e) = pollster::block_on(out_of_memory.pop()) {
            let mib = buffers.bytes() as f64 / (1u64 << 20) as f64;
            return Err(GpuSetupError::Memory { adapter, mib, reason: e.to_string() }.into());
        }

        let mut engine = GpuEngine {
            gpu,
            n: n as u32,
            params,
            plans,
            phases,
            trace: Trace::default(),
            dt,
            layouts: Vec::new(),
            pipelines: Vec::new(),
            buffers,
            bind_groups: HashMap::new(),
            phase_stride,
            has_walls: !scene.walls.is_empty(),
            history: layout_of_history,
            track_orientation: scene.track_orientation,
            wall_names: scene.walls.iter().map(|w| w.name.clone()).collect(),
            wall_flags,
            radius: scene.grains.radius.iter().map(|&r| r as f32).collect(),
            mass: scene.grains.mass.iter().map(|&m| m as f32).collect(),
            in_play: (0..n as usize).map(|i| scene.grains.starts_in_play(i)).collect(),
            meshes,
            mesh_names: scene.walls.iter().filter(|w| matches!(w.shape, WallShape::Mesh { .. })).map(|w| w.name.clone()).collect(),
            piston,
            servo: scene.servo.map(|s| s.walls),
            periodic: crate::periodic::Periodic::of(&scene.periodic),
            model: scene.model.cast::<f32>(),
            coeffs: scene.pair_coeffs(),
            n_materials: scene.materials.len(),
            step: 0,
            time: 0.0,
            forces_valid: false,
            control,
            marks: Vec::new(),
            marks_base: 0,
            pair_stops: 0,
            grow_ahead: pairs.is_none(),
            dispatches: std::cell::Cell::new(0),
        };
        engine.allocate_pairs(pair_capacity).map_err(|reason| GpuSetupError::Memory { adapter: engine.gpu.info.name.clone(), mib: engine.pair_bytes(pair_capacity) as f64 / (1u64 << 20) as f64, reason })?;
        engine.build_pipelines(scene);
        engine.build_bind_groups();
        if pairs.is_none() {
            engine.make_room_for_the_first_list()?;
        }
        Ok(engine)
    }

    /// The adapter this engine runs on.
    pub fn adapter(&self) -> &wgpu::AdapterInfo {
        &self.gpu.info
    }

    /// Pairs the pair buffers hold now.
    pub fn pair_capacity(&self) -> u32 {
        self.params.pair_capacity
    }

    /// Rebuilds so far that stopped on full pair buffers and went on once they had grown.
    pub fn pair_stops(&self) -> u64 {
        self.pair_stops
    }

}


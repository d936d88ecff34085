//! The GPU engine: buffers (structure of arrays, f32), one pipeline per kernel specialised to
//! the scene's laws by override constants, and the step as the dispatches of the schedule's
//! plan ([`super::plan`]). Whether
//! a step rebuilds the neighbour list is decided on the GPU (`decide_rebuild` writes the
//! rebuild kernels' indirect dispatch sizes), so the host only records steps and reads a few
//! statistics back every `stats_interval` steps.

mod buffers;
mod contract;
mod encode;
mod readback;
mod snapshot;
mod traffic;

use glam::{UVec4, Vec4};
use super::device::Gpu;
use encode::Size;
use super::layout::{self, args, Control, DispatchArgs, Params, Phase, MAX_SCAN, MAX_WALLS, NONE, SCAN_BLOCK, STAT_ROW};
use crate::engine::{ContactRecord, Engine, Frame, PistonStats, SimError, Stats, WallStats};
use crate::kernels::StepKernel;
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
const NOT_STATE: [&str; 14] = [
    "params", "phase", "material", "coeffs", // constants
    "cell_count", "cell_fill", "hash_sums", "grain_sums", "spare_sum", // the hash grid
    "bridge_event", // bridge scratch
    "wall_partials", "grain_rows", "pair_rows", "stats", // reductions
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
const REBUILD_SCRATCH: [(&str, &str); 8] = [
    ("old_j", "rev_pair"),
    ("old_hist0", "out_fi"),
    ("old_hist1", "out_tj"),
    ("old_hist2", "out_ti"),
    ("rev_fill", "cell_fill"),
    ("old_start", "force"),
    ("cell_of", "torque"),
    ("cell_grains", "wall_partials"),
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
    buffers: HashMap<&'static str, wgpu::Buffer>,
    bind_groups: HashMap<String, wgpu::BindGroup>,
    phase_stride: u64,
    has_walls: bool,
    history: HistoryLayout,
    track_orientation: bool,
    wall_names: Vec<String>,
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
        limit("bytes of wall history", 16 * n * scene.walls.len() as u64 * hist_blocks, binding, "use fewer walls or grains")?;

        let model = &scene.model;
        let r_max = scene.grains.radius.iter().copied().fold(0.0, f64::max);
        let reach = scene.skin + scene.bridges.reach;
        let cutoff = 2.0 * r_max + reach;
        let mut params = Params {
            n_grains: n as u32,
            n_walls: scene.walls.len() as u32,
            n_materials: scene.materials.len() as u32,
            pair_capacity: pair_capacity as u32,
            hash_size: hash_size as u32,
            max_neighbours: scene.max_neighbours as u32,
            piston: NONE,
            hist_blocks: hist_blocks as u32,
            gravity: Vec4::new(scene.gravity[0] as f32, scene.gravity[1] as f32, scene.gravity[2] as f32, 0.0),
            cell: Vec4::splat(cutoff as f32),
            skin: scene.skin as f32,
            reach: reach as f32,
            ..Default::default()
        };
        for a in 0..3 {
            if let Some([lo, hi]) = scene.periodic[a] {
                let dims = ((hi - lo) / cutoff).floor().max(1.0);
                params.periodic_lo[a] = lo as f32;
                params.periodic_len[a] = (hi - lo) as f32;
                params.periodic_dims[a] = dims as u32;
                params.cell[a] = ((hi - lo) / dims) as f32;
            }
        }
        params.normal = model.normal.gpu_block();
        params.damping = model.damping.gpu_block();
        params.tangential = model.tangential.gpu_block();
        params.rolling = model.rolling.gpu_block();
        params.cohesion = model.cohesion.gpu_block(scene.bridges.volume_cap);
        match model.tangential {
            TangentialLaw::None => {}
            TangentialLaw::Oquendo(l) => {
                params.kt_law = l.stiffness.code();
                params.rolling_as_written = (l.rolling_friction == RollingFriction::AsWritten) as u32;
            }
            TangentialLaw::Mindlin { stiffness, .. } => params.kt_law = stiffness.code(),
        }

        // Walls.
        let mut piston = None;
        let walls: Vec<layout::Wall> = scene
            .walls
            .iter()
            .enumerate()
            .map(|(w, wall)| {
                let mut g = layout::Wall { material: wall.material as u32, ..Default::default() };
                match wall.shape {
                    WallShape::Plane { point, normal } => {
                        g.kind = layout::wall_kind::PLANE;
                        g.point = Vec4::new(point[0] as f32, point[1] as f32, point[2] as f32, 0.0);
                        g.normal = Vec4::new(normal[0] as f32, normal[1] as f32, normal[2] as f32, 0.0);
                    }
                    WallShape::Cylinder { center, radius } => {
                        g.kind = layout::wall_kind::CYLINDER;
                        g.point = Vec4::new(center[0] as f32, center[1] as f32, 0.0, 0.0);
                        g.normal = Vec4::new(0.0, 0.0, 0.0, radius as f32);
                    }
                    WallShape::Piston { z, pressure, mass, area } => {
                        g.kind = layout::wall_kind::PISTON;
                        g.point = Vec4::new(0.0, 0.0, z as f32, 0.0);
                        g.piston = Vec4::new(mass as f32, area as f32, pressure as f32, 0.0);
                        piston = Some(w);
                    }
                }
                g
            })
            .collect();
        if let Some(p) = piston {
            params.piston = p as u32;
        }

        let coeffs: Vec<layout::PairCoeffs> = scene
            .materials
            .iter()
            .flat_map(|a| scene.materials.iter().map(move |b| (a, b)))
            .map(|(a, b)| {
                let c: PairCoeffs<f32> = PairCoeffs::mix(&a.constants, &b.constants, &scene.model);
                layout::PairCoeffs { v_eff: c.v_eff, g_eff: c.g_eff, mu_s: c.mu_s, mu_k: c.mu_k, tan_roll: c.tan_roll, gamma_n: c.gamma_n, gamma_nt: c.gamma_nt, beta: c.beta }
            })
            .collect();

        let g = &scene.grains;
        let v4 = |a: glam::DVec3, w: f64| [a[0] as f32, a[1] as f32, a[2] as f32, w as f32];
        let pos: Vec<[f32; 4]> = (0..g.len()).map(|i| v4(g.position[i], g.radius[i])).collect();
        // What rounding took off each position (src/position.rs), as the CPU's f32 engine keeps it.
        let residual: Vec<[f32; 4]> = g.position.iter().map(|&x| { let (_, r) = crate::position::split::<f32>(x); [r.x, r.y, r.z, 0.0] }).collect();
        let vel: Vec<[f32; 4]> = (0..g.len()).map(|i| v4(g.velocity[i], g.mass[i])).collect();
        // The inertia in w as the CPU's f32 engine keeps it.
        let inertia = |i: usize| crate::state::Props::<f32>::sphere(g.radius[i], g.mass[i]).inertia;
        let omega: Vec<[f32; 4]> = (0..g.len()).map(|i| { let w = g.angular_velocity[i]; [w[0] as f32, w[1] as f32, w[2] as f32, inertia(i)] }).collect();
        let material: Vec<u32> = g.material.iter().map(|&m| m as u32).collect();
        let history = model.history_layout();
        let periodic = scene.periodic.iter().any(Option::is_some);

        let device = &gpu.device;
        // A device without the memory reports it here, not through wgpu's handler (a panic).
        let out_of_memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let mut buffers = HashMap::new();
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let mut init = |name: &'static str, bytes: &[u8], extra: wgpu::BufferUsages| {
            let b = device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(name), contents: bytes, usage: storage | extra });
            buffers.insert(name, b);
        };
        init("pos", bytemuck::cast_slice(&pos), wgpu::BufferUsages::empty());
        init("residual", bytemuck::cast_slice(&residual), wgpu::BufferUsages::empty());
        init("vel", bytemuck::cast_slice(&vel), wgpu::BufferUsages::empty());
        init("omega", bytemuck::cast_slice(&omega), wgpu::BufferUsages::empty());
        init("material", bytemuck::cast_slice(&material), wgpu::BufferUsages::empty());
        let liquid = vec![0.0f32; if layout_of_history.bridge { g.len() } else { 4 }];
        init("liquid", bytemuck::cast_slice(&liquid), wgpu::BufferUsages::empty());
        init("coeffs", bytemuck::cast_slice(&coeffs), wgpu::BufferUsages::empty());
        let walls_bytes: Vec<layout::Wall> = if walls.is_empty() { vec![layout::Wall::default()] } else { walls };
        init("walls", bytemuck::cast_slice(&walls_bytes), wgpu::BufferUsages::empty());
        let control = Control { max_disp2: f32::INFINITY.to_bits(), overflow_grain: NONE, non_finite: NONE, ..Default::default() };
        init("control", bytemuck::bytes_of(&control), wgpu::BufferUsages::empty());
        let mut dispatch_args = vec![DispatchArgs { x: 0, y: 1, z: 1 }; args::SLOTS as usize];
        (dispatch_args[args::STEP_GRAINS as usize], dispatch_args[args::STEP_ONE as usize]) = (DispatchArgs::items(n), DispatchArgs::ONE);
        init("args", bytemuck::cast_slice(&dispatch_args), wgpu::BufferUsages::INDIRECT);
        let quat: Vec<[f32; 4]> = if scene.track_orientation { vec![[1.0, 0.0, 0.0, 0.0]; g.len()] } else { vec![[0.0; 4]] };
        init("quat", bytemuck::cast_slice(&quat), wgpu::BufferUsages::empty());
        init("params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
        let servo = scene.servo.map_or(layout::Servo::default(), |s| {
            let w = s.walls.map(|w| w as u32);
            layout::Servo {
                walls_lo: UVec4::new(w[0], w[1], w[2], w[3]),
                walls_hi: UVec4::new(w[4], w[5], 0, 0),
                pressure: s.pressure as f32,
                gain: s.gain as f32,
                max_speed: s.max_speed as f32,
                relaxation: crate::walls::SERVO_RELAXATION as f32,
                ..Default::default()
            }
        });
        init("servo", bytemuck::bytes_of(&servo), wgpu::BufferUsages::empty());

        let phase_stride = (gpu.limits.min_uniform_buffer_offset_alignment as u64).max(std::mem::size_of::<Phase>() as u64);
        let dt = scene.time_step.dt;
        let plans = Plans::of(&Schedule::new(scene.integrator, dt));
        let mut phases: Vec<Phase> = Vec::new();
        for e in &plans.entries() {
            if !phases.contains(&e.phase) {
                phases.push(e.phase);
            }
        }
        let mut phase_bytes = vec![0u8; phase_stride as usize * phases.len()];
        for (slot, p) in phases.iter().enumerate() {
            let at = slot * phase_stride as usize;
            phase_bytes[at..at + std::mem::size_of::<Phase>()].copy_from_slice(bytemuck::bytes_of(p));
        }
        init("phase", &phase_bytes, wgpu::BufferUsages::UNIFORM);

        let mut zeroed = |name: &'static str, bytes: u64| {
            let b = device.create_buffer(&wgpu::BufferDescriptor { label: Some(name), size: bytes.max(16), usage: storage, mapped_at_creation: false });
            buffers.insert(name, b);
        };
        let v = 16 * n;
        for name in ["force", "torque", "built_at"] {
            zeroed(name, v);
        }
        zeroed("image", if periodic { v } else { 16 });
        zeroed("cell_count", 4 * hash_size);
        zeroed("cell_fill", 4 * hash_size);
        zeroed("hash_sums", 4 * hash_size.div_ceil(2048));
        zeroed("grain_sums", 4 * (n + 1).div_ceil(2048));
        zeroed("spare_sum", 4);
        for name in ["pair_start", "rev_start"] {
            zeroed(name, 4 * (n + 1));
        }
        let wall_hist = if hist_blocks > 0 { 16 * n * scene.walls.len() as u64 * hist_blocks } else { 16 };
        zeroed("wall_hist", wall_hist);
        // Per wall: the reaction, then the contacts' stiffness and damping (servo walls).
        let wall_partials = workgroup::rows(n) * 2 * MAX_WALLS as u64 * 16;
        zeroed("wall_partials", wall_partials);
        // The rebuild's scratch fits the buffers that hold it (REBUILD_SCRATCH).
        debug_assert!(v.max(16) >= 4 * (n + 1) && wall_partials >= 4 * n);
        zeroed("wall_reaction", 2 * MAX_WALLS as u64 * 16);
        zeroed("grain_rows", workgroup::rows(n) * STAT_ROW as u64 * 4);
        zeroed("stats", 2 * STAT_ROW as u64 * 4);
        if let Some(e) = pollster::block_on(out_of_memory.pop()) {
            let mib = buffers.values().map(wgpu::Buffer::size).sum::<u64>() as f64 / (1u64 << 20) as f64;
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
            history,
            track_orientation: scene.track_orientation,
            wall_names: scene.walls.iter().map(|w| w.name.clone()).collect(),
            piston,
            servo: scene.servo.map(|s| s.walls),
            periodic: crate::periodic::Periodic::of(&scene.periodic),
            model: scene.model.cast::<f32>(),
            coeffs: scene.materials.iter().flat_map(|a| scene.materials.iter().map(move |b| PairCoeffs::mix(&a.constants, &b.constants, &scene.model))).collect(),
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


//! The GPU engine: buffers (structure of arrays, f32), one pipeline per kernel specialised to
//! the scene's laws by override constants, and the step as a sequence of dispatches. Whether
//! a step rebuilds the neighbour list is decided on the GPU (`decide_rebuild` writes the
//! rebuild kernels' indirect dispatch sizes), so the host only records steps and reads a few
//! statistics back every `stats_interval` steps.

use super::device::Gpu;
use super::layout::{self, args, Control, DispatchArgs, Params, Phase, MAX_SCAN, MAX_WALLS, NONE, SCAN_BLOCK, STAT_ROW, WG};
use crate::engine::{ContactRecord, Engine, Frame, PistonStats, SimError, Stats, WallStats};
use crate::kernels::{Access, KERNELS};
use crate::model::{DampingLaw, HistoryLayout, NormalLaw, PairCoeffs, RollingFriction, RollingLaw, TangentialLaw, TangentialStiffness, TwistingLaw};
use super::plan::{plan, Dispatch, Entry};
use crate::schedule::{Op, Schedule, Trace};
use crate::scene::{Scene, WallShape};
use std::collections::HashMap;
use wgpu::util::DeviceExt;

/// Pairs per grain the pair buffers start with; they grow at statistics reads when more than
/// [`PAIR_GROWTH_THRESHOLD`] of them are in use. A dense packing with a skin of a tenth of a
/// diameter lists about 3.7 per grain; 6 keeps 10^6 grains' buffers under 1 GiB.
pub const INITIAL_PAIRS_PER_GRAIN: u64 = 6;
/// Fill fraction of the pair buffers that makes them grow (to twice the pairs in use).
pub const PAIR_GROWTH_THRESHOLD: f64 = 0.75;
/// Steps recorded per queue submission.
pub const STEPS_PER_SUBMIT: u64 = 16;

/// Buffers a checkpoint leaves out: the scene's constants (set up again from the scene) and
/// scratch space every step or statistics read rewrites before reading it.
const NOT_STATE: [&str; 19] = [
    "params", "phase", "material", "coeffs", // constants
    "cell_of", "cell_grains", "cell_count", "cell_fill", "hash_sums", "grain_sums", "spare_sum", // the hash grid
    "old_start", "old_j", "old_hist", "rev_fill", // rebuild scratch
    "wall_partials", "grain_rows", "pair_rows", "stats", // reductions
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
}

/// How a kernel is dispatched.
#[derive(Clone, Copy, Debug)]
enum Size {
    /// One invocation per grain.
    Grains,
    /// One workgroup.
    One,
    /// From an indirect-argument slot.
    Indirect(u64),
}

/// The GPU engine (f32).
pub struct GpuEngine {
    gpu: Gpu,
    n: u32,
    params: Params,
    schedule: Schedule,
    /// The plans of the schedule's prologue, first step and later steps.
    plans: [Vec<Entry>; 3],
    /// The phases of the plans, in the order of their uniform slots in `phase`.
    phases: Vec<Phase>,
    /// The operations encoded, when tracing.
    trace: Trace,
    dt: f64,
    layouts: HashMap<&'static str, wgpu::BindGroupLayout>,
    pipelines: HashMap<&'static str, wgpu::ComputePipeline>,
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
    /// Dispatches recorded so far.
    dispatches: std::cell::Cell<u64>,
}

/// The GPU's history (one vec4 per block and contact: tangential with the sliding flag in w,
/// rolling, bridge volume in x) in the CPU engine's packed slots.
fn cpu_history(blocks: &[[f32; 4]], slots: &crate::cpu::HistorySlots) -> Vec<f32> {
    let layout = slots.layout;
    let per_contact = [layout.tangential, layout.rolling, layout.bridge].into_iter().filter(|&b| b).count().max(1);
    let mut out = Vec::with_capacity(blocks.len() / per_contact * slots.stride);
    for contact in blocks.chunks_exact(per_contact) {
        let mut s = vec![0.0f32; slots.stride];
        let mut b = contact.iter();
        if layout.tangential {
            let t = b.next().expect("a tangential block");
            s[slots.tangential..slots.tangential + 3].copy_from_slice(&t[..3]);
            if layout.sliding {
                s[slots.sliding] = t[3];
            }
        }
        if layout.rolling {
            let r = b.next().expect("a rolling block");
            s[slots.rolling..slots.rolling + 3].copy_from_slice(&r[..3]);
        }
        if layout.bridge {
            s[slots.bridge] = b.next().expect("a bridge block")[0];
        }
        out.extend(s);
    }
    out
}

/// The pressure the grains exert on plane `k` (0..6) of the servo box whose walls are
/// `planes` (Pa): the CPU's `servo_pressure`, from the GPU's walls and reactions.
fn servo_pressure(walls: &[layout::Wall], reaction: &[[f32; 4]], planes: [usize; 6], k: usize) -> f64 {
    let coord = |k: usize| walls[planes[k]].point[k / 2] as f64;
    let extents = [0, 1, 2].map(|a| coord(2 * a + 1) - coord(2 * a));
    let a = k / 2;
    let area = extents[(a + 1) % 3] * extents[(a + 2) % 3];
    let (r, n) = (reaction[planes[k]], walls[planes[k]].normal);
    -(0..3).map(|c| r[c] as f64 * n[c] as f64).sum::<f64>() / area
}

fn groups_for(n: u64) -> (u32, u32) {
    let g = n.div_ceil(WG as u64);
    if g <= 65535 { (g as u32, 1) } else { (65535, g.div_ceil(65535) as u32) }
}

fn rows_for(n: u64) -> u64 {
    let (x, y) = groups_for(n.max(1));
    x as u64 * y as u64
}

impl GpuEngine {
    /// Sets the engine up for a scene on an opened device and builds the first neighbour list.
    pub fn new(gpu: Gpu, scene: &Scene) -> Result<Self, anyhow::Error> {
        let n = scene.grains.len() as u64;
        let adapter = gpu.info.name.clone();
        let limit = |what, need: u64, have: u64, fix| -> Result<(), GpuSetupError> {
            if need > have { Err(GpuSetupError::Limit { adapter: adapter.clone(), what, need, have, fix }) } else { Ok(()) }
        };
        let binding = gpu.limits.max_storage_buffer_binding_size;
        limit("walls", scene.walls.len() as u64, MAX_WALLS as u64, "split the container into at most 8 walls or use --backend cpu")?;
        limit("bytes per grain array (16 per grain)", 16 * n, binding, "use fewer grains per run or a device with larger storage bindings")?;
        let hash_size = (n.max(64)).next_power_of_two();
        limit("scan elements (hash buckets)", hash_size, MAX_SCAN, "use fewer grains per run (the two-level scan holds 4,194,304)")?;
        let layout_of_history = scene.model.history_layout();
        let hist_blocks = [layout_of_history.tangential, layout_of_history.rolling, layout_of_history.bridge].into_iter().filter(|&b| b).count() as u64;
        let per_pair_bytes = 16 * hist_blocks.max(1);
        let pair_capacity = (INITIAL_PAIRS_PER_GRAIN * n).max(1024).min(binding / per_pair_bytes).min(binding / 16);
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
            gravity: [scene.gravity[0] as f32, scene.gravity[1] as f32, scene.gravity[2] as f32, 0.0],
            cell: [cutoff as f32; 4],
            skin: scene.skin as f32,
            reach: reach as f32,
            bridge_cap: scene.bridges.volume_cap as f32,
            ..Default::default()
        };
        if let crate::model::CohesionLaw::Capillary { kappa, theta, c } = model.cohesion {
            (params.kappa, params.theta, params.capillary_c) = (kappa as f32, theta as f32, c as f32);
        }
        for a in 0..3 {
            if let Some([lo, hi]) = scene.periodic[a] {
                let dims = ((hi - lo) / cutoff).floor().max(1.0);
                params.periodic_lo[a] = lo as f32;
                params.periodic_len[a] = (hi - lo) as f32;
                params.periodic_dims[a] = dims as u32;
                params.cell[a] = ((hi - lo) / dims) as f32;
            }
        }
        if let NormalLaw::Linear { k_n } = model.normal {
            params.k_n = k_n as f32;
        }
        if let DampingLaw::Viscous { c_n } = model.damping {
            params.c_n = c_n as f32;
        }
        let stiffness = |s: TangentialStiffness<f64>| match s {
            TangentialStiffness::Mindlin => -1.0,
            TangentialStiffness::RatioToNormal(r) => r as f32,
        };
        match model.tangential {
            TangentialLaw::None => {}
            TangentialLaw::Oquendo(l) => {
                params.static_damping = l.static_damping as f32;
                params.rolling_as_written = (l.rolling_friction == RollingFriction::AsWritten) as u32;
                params.kt_ratio = stiffness(l.stiffness);
            }
            TangentialLaw::Mindlin { damping_ratio, stiffness: s } => {
                params.damping_ratio = damping_ratio as f32;
                params.kt_ratio = stiffness(s);
            }
        }
        if let RollingLaw::Sds { k_r, gamma_r, mu_r } = model.rolling {
            params.k_r = k_r as f32;
            params.gamma_r = gamma_r as f32;
            params.mu_r = mu_r as f32;
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
                        g.kind = 0;
                        g.point = [point[0] as f32, point[1] as f32, point[2] as f32, 0.0];
                        g.normal = [normal[0] as f32, normal[1] as f32, normal[2] as f32, 0.0];
                    }
                    WallShape::Cylinder { center, radius } => {
                        g.kind = 1;
                        g.point = [center[0] as f32, center[1] as f32, 0.0, 0.0];
                        g.normal = [0.0, 0.0, 0.0, radius as f32];
                    }
                    WallShape::Piston { z, pressure, mass, area } => {
                        g.kind = 2;
                        g.point = [0.0, 0.0, z as f32, 0.0];
                        g.piston = [mass as f32, area as f32, pressure as f32, 0.0];
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
                let c: PairCoeffs<f32> = PairCoeffs::mix(&a.constants, &b.constants);
                layout::PairCoeffs { v_eff: c.v_eff, g_eff: c.g_eff, mu_s: c.mu_s, mu_k: c.mu_k, tan_roll: c.tan_roll, gamma_n: c.gamma_n, gamma_nt: c.gamma_nt, beta: c.beta }
            })
            .collect();

        let g = &scene.grains;
        let v4 = |a: [f64; 3], w: f64| [a[0] as f32, a[1] as f32, a[2] as f32, w as f32];
        let pos: Vec<[f32; 4]> = (0..g.len()).map(|i| v4(g.position[i], g.radius[i])).collect();
        let vel: Vec<[f32; 4]> = (0..g.len()).map(|i| v4(g.velocity[i], g.mass[i])).collect();
        let omega: Vec<[f32; 4]> = (0..g.len()).map(|i| v4(g.angular_velocity[i], 0.4 * g.mass[i] * g.radius[i] * g.radius[i])).collect();
        let material: Vec<u32> = g.material.iter().map(|&m| m as u32).collect();
        let history = model.history_layout();
        let periodic = scene.periodic.iter().any(Option::is_some);

        let device = &gpu.device;
        let mut buffers = HashMap::new();
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let mut init = |name: &'static str, bytes: &[u8], extra: wgpu::BufferUsages| {
            let b = device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(name), contents: bytes, usage: storage | extra });
            buffers.insert(name, b);
        };
        init("pos", bytemuck::cast_slice(&pos), wgpu::BufferUsages::empty());
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
        init("args", bytemuck::cast_slice(&vec![DispatchArgs { x: 0, y: 1, z: 1 }; args::SLOTS as usize]), wgpu::BufferUsages::INDIRECT);
        let quat: Vec<[f32; 4]> = if scene.track_orientation { vec![[1.0, 0.0, 0.0, 0.0]; g.len()] } else { vec![[0.0; 4]] };
        init("quat", bytemuck::cast_slice(&quat), wgpu::BufferUsages::empty());
        init("params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
        let servo = scene.servo.map_or(layout::Servo::default(), |s| {
            let w = s.walls.map(|w| w as u32);
            layout::Servo {
                walls_lo: [w[0], w[1], w[2], w[3]],
                walls_hi: [w[4], w[5], 0, 0],
                pressure: s.pressure as f32,
                gain: s.gain as f32,
                max_speed: s.max_speed as f32,
                relaxation: crate::cpu::SERVO_RELAXATION as f32,
                ..Default::default()
            }
        });
        init("servo", bytemuck::bytes_of(&servo), wgpu::BufferUsages::empty());

        let phase_stride = (gpu.limits.min_uniform_buffer_offset_alignment as u64).max(std::mem::size_of::<Phase>() as u64);
        let dt = scene.time_step.dt;
        let schedule = Schedule::new(scene.integrator, dt);
        let plans = [plan(&schedule.prologue), plan(&schedule.first), plan(&schedule.step)];
        let mut phases: Vec<Phase> = Vec::new();
        for e in plans.iter().flatten() {
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
        for name in ["force", "torque", "built_at", "wall_force", "wall_torque"] {
            zeroed(name, v);
        }
        zeroed("image", if periodic { v } else { 16 });
        zeroed("cell_of", 4 * n);
        zeroed("cell_grains", 4 * n);
        zeroed("cell_count", 4 * hash_size);
        zeroed("cell_fill", 4 * hash_size);
        zeroed("hash_sums", 4 * hash_size.div_ceil(2048));
        zeroed("grain_sums", 4 * (n + 1).div_ceil(2048));
        zeroed("spare_sum", 4);
        for name in ["pair_start", "old_start", "rev_start"] {
            zeroed(name, 4 * (n + 1));
        }
        zeroed("rev_fill", 4 * n);
        let wall_hist = if hist_blocks > 0 { 16 * n * scene.walls.len() as u64 * hist_blocks } else { 16 };
        zeroed("wall_hist", wall_hist);
        // Per wall: the reaction, then the contacts' stiffness and damping (servo walls).
        zeroed("wall_partials", rows_for(n) * 2 * MAX_WALLS as u64 * 16);
        zeroed("wall_reaction", 2 * MAX_WALLS as u64 * 16);
        zeroed("grain_rows", rows_for(n) * STAT_ROW as u64 * 4);
        zeroed("stats", 2 * STAT_ROW as u64 * 4);

        let mut engine = GpuEngine {
            gpu,
            n: n as u32,
            params,
            schedule,
            plans,
            phases,
            trace: Trace::default(),
            dt,
            layouts: HashMap::new(),
            pipelines: HashMap::new(),
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
            coeffs: scene.materials.iter().flat_map(|a| scene.materials.iter().map(move |b| PairCoeffs::mix(&a.constants, &b.constants))).collect(),
            n_materials: scene.materials.len(),
            step: 0,
            time: 0.0,
            forces_valid: false,
            control,
            dispatches: std::cell::Cell::new(0),
        };
        engine.allocate_pairs(pair_capacity);
        engine.build_pipelines(scene);
        engine.build_bind_groups();
        Ok(engine)
    }

    /// The per-pair buffers and their bytes per pair.
    fn pair_buffers(&self) -> [(&'static str, u64); 10] {
        let blocks = self.params.hist_blocks as u64;
        [
            ("pair_i", 4),
            ("pair_j", 4),
            ("old_j", 4),
            ("rev_pair", 4),
            ("hist", 16 * blocks),
            ("old_hist", 16 * blocks),
            ("out_fi", 16),
            ("out_fj", 16),
            ("out_ti", 16),
            ("out_tj", 16),
        ]
    }

    /// (Re)allocates the per-pair buffers for `capacity` pairs.
    fn allocate_pairs(&mut self, capacity: u64) {
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let mut sizes: Vec<(&'static str, u64)> = self.pair_buffers().iter().map(|&(name, per_pair)| (name, per_pair * capacity)).collect();
        sizes.push(("pair_rows", rows_for(capacity) * STAT_ROW as u64 * 4));
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        for (name, size) in sizes {
            let b = self.gpu.device.create_buffer(&wgpu::BufferDescriptor { label: Some(name), size: size.max(16), usage: storage, mapped_at_creation: false });
            // Growing keeps what the live pairs hold.
            if let Some(old) = self.buffers.get(name) {
                encoder.copy_buffer_to_buffer(old, 0, &b, 0, old.size().min(b.size()));
            }
            self.buffers.insert(name, b);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.params.pair_capacity = capacity as u32;
        self.gpu.queue.write_buffer(&self.buffers["params"], 0, bytemuck::bytes_of(&self.params));
    }

    fn build_pipelines(&mut self, scene: &Scene) {
        let m = &scene.model;
        let normal = match m.normal {
            NormalLaw::Hertz => 0.0,
            NormalLaw::Linear { .. } => 1.0,
        };
        let damping = match m.damping {
            DampingLaw::None => 0.0,
            DampingLaw::Papers => 1.0,
            DampingLaw::Restitution => 2.0,
            DampingLaw::Viscous { .. } => 3.0,
        };
        let tangential = match m.tangential {
            TangentialLaw::None => 0.0,
            TangentialLaw::Oquendo { .. } => 1.0,
            TangentialLaw::Mindlin { .. } => 2.0,
        };
        let rolling = if let RollingLaw::Sds { .. } = m.rolling { 1.0 } else { 0.0 };
        let twisting = if let TwistingLaw::Oquendo = m.twisting { 1.0 } else { 0.0 };
        let cohesion = if self.history.bridge { 1.0 } else { 0.0 };
        let model_constants = [
            ("NORMAL_LAW", normal),
            ("DAMPING_LAW", damping),
            ("TANGENTIAL_LAW", tangential),
            ("ROLLING_LAW", rolling),
            ("TWISTING_LAW", twisting),
            ("COHESION_LAW", cohesion),
            ("HAS_TANGENTIAL_HISTORY", self.history.tangential as u8 as f64),
            ("HAS_ROLLING_HISTORY", self.history.rolling as u8 as f64),
        ];
        let orientation = ("TRACK_ORIENTATION", self.track_orientation as u8 as f64);
        let wall_response = ("WALL_RESPONSE", self.servo.is_some() as u8 as f64);
        for k in KERNELS {
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
                            Access::ReadWrite => wgpu::BufferBindingType::Storage { read_only: false },
                        },
                        has_dynamic_offset: *access == Access::Phase,
                        min_binding_size: None,
                    },
                    count: None,
                })
                .collect();
            let device = &self.gpu.device;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(k.name), entries: &entries });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some(k.name), bind_group_layouts: &[Some(&layout)], ..Default::default() });
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(k.name), source: wgpu::ShaderSource::Wgsl(k.wgsl().into()) });
            let mut constants: Vec<(&str, f64)> = if k.includes.contains(&"model") { model_constants.to_vec() } else { Vec::new() };
            match k.name {
                "integrate" => constants.push(orientation),
                "wall_contacts" => constants.push(wall_response),
                _ => {}
            }
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(k.name),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(k.name),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, zero_initialize_workgroup_memory: true },
                cache: None,
            });
            self.layouts.insert(k.name, layout);
            self.pipelines.insert(k.name, pipeline);
        }
    }

    /// Bind groups: one per kernel, and one per scanned array for the scan kernels.
    fn build_bind_groups(&mut self) {
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
        for k in KERNELS {
            let instances: Vec<(String, Vec<(&str, &str)>)> = if k.name.starts_with("scan_") {
                scans.iter().map(|(tag, data, sums)| (format!("{}:{tag}", k.name), vec![("scan_data", *data), ("block_sums", *sums)])).collect()
            } else {
                vec![(k.name.to_string(), vec![])]
            };
            for (key, aliases) in instances {
                let entries: Vec<wgpu::BindGroupEntry> = k
                    .bindings
                    .iter()
                    .enumerate()
                    .map(|(i, (name, access))| {
                        let buffer_name = aliases.iter().find(|(a, _)| a == name).map_or(*name, |(_, b)| *b);
                        let buffer = self.buffers.get(buffer_name).unwrap_or_else(|| panic!("kernel {} binds {buffer_name}, which the engine lacks", k.name));
                        let resource = if *access == Access::Phase {
                            wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer, offset: 0, size: wgpu::BufferSize::new(std::mem::size_of::<Phase>() as u64) })
                        } else {
                            buffer.as_entire_binding()
                        };
                        wgpu::BindGroupEntry { binding: i as u32, resource }
                    })
                    .collect();
                let bg = self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(&key), layout: &self.layouts[k.name], entries: &entries });
                self.bind_groups.insert(key, bg);
            }
        }
    }

    fn dispatch(&self, pass: &mut wgpu::ComputePass, name: &str, group: &str, size: Size, phase: Option<Phase>) {
        pass.set_pipeline(&self.pipelines[name]);
        // A kernel with a phase binding is given its phase; the others none.
        let slot = |p: Phase| self.phases.iter().position(|q| *q == p).expect("every phase of the plans has a uniform slot");
        let offsets: Vec<u32> = phase.map(|p| (slot(p) as u64 * self.phase_stride) as u32).into_iter().collect();
        pass.set_bind_group(0, &self.bind_groups[group], &offsets);
        self.dispatches.set(self.dispatches.get() + 1);
        match size {
            Size::Grains => {
                let (x, y) = groups_for(self.n as u64);
                pass.dispatch_workgroups(x, y, 1);
            }
            Size::One => pass.dispatch_workgroups(1, 1, 1),
            Size::Indirect(slot) => pass.dispatch_workgroups_indirect(&self.buffers["args"], slot * std::mem::size_of::<DispatchArgs>() as u64),
        }
    }

    fn run(&self, pass: &mut wgpu::ComputePass, name: &str, size: Size, phase: Option<Phase>) {
        self.dispatch(pass, name, name, size, phase);
    }

    /// Exclusive scan of an array of `elements`: blocks, the blocks' totals, then the offsets
    /// added back (the last two only when there is more than one block).
    fn scan(&self, pass: &mut wgpu::ComputePass, tag: &str, sums_tag: &str, blocks: u64, elements: u64) {
        self.dispatch(pass, "scan_blocks", &format!("scan_blocks:{tag}"), Size::Indirect(blocks), None);
        // An array of one block is scanned by then: its offset would be 0.
        if elements <= SCAN_BLOCK {
            return;
        }
        self.dispatch(pass, "scan_blocks", &format!("scan_blocks:{sums_tag}"), Size::Indirect(args::ONE), None);
        self.dispatch(pass, "scan_add", &format!("scan_add:{tag}"), Size::Indirect(blocks), None);
    }

    /// `decide_rebuild` and the rebuild kernels, which run with zero workgroups when the
    /// list is still good.
    fn encode_rebuild_if_needed(&self, pass: &mut wgpu::ComputePass) {
        self.run(pass, "decide_rebuild", Size::One, None);
        let keeps_history = self.params.hist_blocks > 0;
        if keeps_history {
            self.run(pass, "save_starts", Size::Indirect(args::GRAIN_STARTS), None);
            self.run(pass, "save_pairs", Size::Indirect(args::OLD_PAIRS), None);
        }
        self.run(pass, "clear_cells", Size::Indirect(args::HASH), None);
        self.run(pass, "hash_cells", Size::Indirect(args::GRAINS), None);
        self.scan(pass, "cell", "cell_sums", args::HASH_BLOCKS, self.params.hash_size as u64);
        self.run(pass, "scatter_cells", Size::Indirect(args::GRAINS), None);
        self.run(pass, "detect_count", Size::Indirect(args::GRAINS), None);
        self.scan(pass, "pairs", "grain_sums", args::GRAIN_BLOCKS, self.n as u64 + 1);
        self.run(pass, "pairs_ready", Size::One, None);
        self.run(pass, "detect_fill", Size::Indirect(args::GRAINS), None);
        if keeps_history {
            self.run(pass, "remap_history", Size::Indirect(args::NEW_PAIRS), None);
        }
        self.run(pass, "reverse_count", Size::Indirect(args::NEW_PAIRS), None);
        self.scan(pass, "rev", "grain_sums", args::GRAIN_BLOCKS, self.n as u64 + 1);
        self.run(pass, "reverse_fill", Size::Indirect(args::NEW_PAIRS), None);
        self.run(pass, "reverse_sort", Size::Indirect(args::GRAINS), None);
    }

    /// `update_bridges` (capillary scenes), `pair_force`, `wall_contacts` (+ `wall_reduce`),
    /// `gather` (and the kick after it), with the durations of `phase`.
    fn encode_forces(&self, pass: &mut wgpu::ComputePass, phase: Phase) {
        if self.history.bridge {
            self.run(pass, "update_bridges", Size::One, None);
        }
        self.run(pass, "pair_force", Size::Indirect(args::PAIRS), Some(phase));
        if self.has_walls {
            self.run(pass, "wall_contacts", Size::Grains, Some(phase));
            self.run(pass, "wall_reduce", Size::One, None);
        }
        self.run(pass, "gather", Size::Grains, Some(phase));
    }

    /// Encodes one entry of a plan.
    fn encode(&self, pass: &mut wgpu::ComputePass, e: &Entry) {
        match e.dispatch {
            Dispatch::Integrate => {
                self.run(pass, "integrate", Size::Grains, Some(e.phase));
                if self.servo.is_some() && e.phase.drift > 0.0 {
                    self.run(pass, "servo_move", Size::One, Some(e.phase));
                }
            }
            Dispatch::RebuildIfNeeded => self.encode_rebuild_if_needed(pass),
            Dispatch::Forces => self.encode_forces(pass, e.phase),
        }
    }

    /// Encodes plan `which` (0 prologue, 1 first step, 2 later steps) and traces its
    /// operations.
    fn encode_plan(&mut self, pass: &mut wgpu::ComputePass, which: usize) {
        for k in 0..self.plans[which].len() {
            self.encode(pass, &self.plans[which][k]);
            for op in self.plans[which][k].ops.clone() {
                self.trace.record(op);
            }
        }
    }

    /// Runs the schedule's prologue (the list built if need be, forces evaluated) where
    /// nothing has evaluated the loads yet: before the first step, or after wetting.
    fn ensure_loads(&mut self) {
        if self.forces_valid {
            return;
        }
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.encode_plan(&mut pass, 0);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.forces_valid = true;
    }

    /// Starts recording the operations encoded (see [`Trace`]).
    pub fn trace_schedule(&mut self) {
        self.trace.start();
    }

    /// The operations encoded since [`Self::trace_schedule`].
    pub fn traced(&self) -> &[Op] {
        self.trace.ops()
    }

    /// Copies buffers out: `(buffer, offset, bytes)` each, returned in order as 4-byte words
    /// (every type the kernels share is 4-byte aligned).
    fn read(&self, parts: &[(&str, u64, u64)]) -> Vec<Vec<u32>> {
        let total: u64 = parts.iter().map(|p| p.2.next_multiple_of(4)).sum();
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: total.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        let mut at = 0;
        for &(name, offset, bytes) in parts {
            encoder.copy_buffer_to_buffer(&self.buffers[name], offset, &staging, at, bytes.next_multiple_of(4));
            at += bytes.next_multiple_of(4);
        }
        self.gpu.queue.submit([encoder.finish()]);
        staging.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("mapping a readback buffer"));
        self.gpu.device.poll(wgpu::PollType::wait_indefinitely()).expect("the GPU finishes");
        let view = staging.slice(..).get_mapped_range().expect("a mapped readback buffer");
        let mut out = Vec::new();
        let mut at = 0usize;
        for &(_, _, bytes) in parts {
            out.push(bytemuck::pod_collect_to_vec(&view[at..at + bytes as usize]));
            at += bytes.next_multiple_of(4) as usize;
        }
        out
    }

    fn read_control(&mut self) -> Control {
        let c = self.read(&[("control", 0, std::mem::size_of::<Control>() as u64)]);
        self.control = *bytemuck::from_bytes(bytemuck::cast_slice(&c[0]));
        self.control
    }

    /// The adapter this engine runs on.
    pub fn adapter(&self) -> &wgpu::AdapterInfo {
        &self.gpu.info
    }

    /// Pairs the pair buffers hold now.
    pub fn pair_capacity(&self) -> u32 {
        self.params.pair_capacity
    }

    /// Checks the flags the last steps raised, and grows the pair buffers when they fill up.
    fn check(&mut self) -> Result<(), SimError> {
        let c = self.read_control();
        if c.overflow_grain != NONE {
            return Err(SimError::Capacity { step: self.step, grain: c.overflow_grain, count: c.overflow_count as usize, capacity: self.params.max_neighbours as usize });
        }
        if c.pair_overflow != 0 {
            return Err(SimError::Capacity {
                step: self.step,
                grain: NONE,
                count: self.params.pair_capacity as usize + 1,
                capacity: self.params.pair_capacity as usize,
            });
        }
        if c.n_pairs as f64 > PAIR_GROWTH_THRESHOLD * self.params.pair_capacity as f64 {
            let binding = self.gpu.limits.max_storage_buffer_binding_size;
            let per_pair = 16 * (self.params.hist_blocks as u64).max(1);
            let grown = (2 * c.n_pairs as u64).min(binding / per_pair);
            if grown > self.params.pair_capacity as u64 {
                self.allocate_pairs(grown);
                self.build_bind_groups();
            }
        }
        Ok(())
    }

    /// Rebuilds the neighbour list at the next step, whatever the displacements.
    pub fn rebuild_next_step(&mut self) {
        self.gpu.queue.write_buffer(&self.buffers["control"], 0, bytemuck::bytes_of(&f32::INFINITY.to_bits()));
    }

    /// The pair list (CSR: starts per grain, partners), read back.
    pub fn pair_list(&mut self) -> (Vec<u32>, Vec<u32>) {
        let n_pairs = self.read_control().n_pairs as u64;
        let parts = self.read(&[("pair_start", 0, 4 * (self.n as u64 + 1)), ("pair_j", 0, 4 * n_pairs)]);
        (parts[0].clone(), parts[1].clone())
    }

    /// Force and torque on each grain from the last force evaluation (N, N m), read back.
    pub fn loads(&self) -> Vec<([f32; 3], [f32; 3])> {
        let a = self.read_vec4s(&["force", "torque"]);
        a[0].iter().zip(&a[1]).map(|(f, t)| ([f[0], f[1], f[2]], [t[0], t[1], t[2]])).collect()
    }

    /// Grain-wall contacts re-evaluated on the host from the GPU's state (the CPU twin's
    /// function in f32), given the grain arrays `[pos, vel, omega, ..]` already read.
    fn wall_contact_records(&self, arrays: &[Vec<[f32; 4]>]) -> Vec<crate::engine::WallContactRecord> {
        use crate::cpu::{wall_contact_records, Body, ForceContext, HistorySlots, Props, WallState};
        use crate::real::Vec3;
        let n_walls = self.wall_names.len();
        let blocks = self.params.hist_blocks as usize;
        let parts = self.read(&[
            ("material", 0, 4 * self.n as u64),
            ("walls", 0, (n_walls * std::mem::size_of::<layout::Wall>()) as u64),
            ("wall_hist", 0, if blocks > 0 { 16 * (self.n as usize * n_walls * blocks) as u64 } else { 0 }),
        ]);
        let walls: &[layout::Wall] = bytemuck::cast_slice(&parts[1]);
        let gpu_hist: &[[f32; 4]] = bytemuck::cast_slice(&parts[2]);
        let v3 = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
        let body: Vec<Body<f32>> = (0..self.n as usize).map(|i| Body { pos: v3(arrays[0][i]), vel: v3(arrays[1][i]), omega: v3(arrays[2][i]) }).collect();
        let prop: Vec<Props<f32>> = (0..self.n as usize).map(|i| Props { radius: arrays[0][i][3], mass: arrays[1][i][3], inertia: arrays[2][i][3], material: parts[0][i] }).collect();
        let states: Vec<WallState<f32>> = walls
            .iter()
            .map(|w| WallState {
                geom: match w.kind {
                    0 => crate::walls::WallGeom::Plane { point: v3(w.point), normal: v3(w.normal) },
                    1 => crate::walls::WallGeom::Cylinder { cx: w.point[0], cy: w.point[1], radius: w.normal[3] },
                    _ => crate::walls::WallGeom::Piston { z: w.point[2] },
                },
                velocity: v3(w.velocity),
                material: w.material,
            })
            .collect();
        let slots = HistorySlots::new(self.history);
        let hist = cpu_history(gpu_hist, &slots);
        let ctx = ForceContext {
            model: &self.model,
            coeffs: &self.coeffs,
            n_materials: self.n_materials,
            slots,
            elapsed: 0.0,
            periodic: crate::periodic::Periodic::default(),
        };
        wall_contact_records(&body, &prop, &(0..self.n).collect::<Vec<u32>>(), &states, &ctx, &hist)
    }

    /// Liquid bridges among the first `n_pairs` pairs, the liquid they hold and the liquid
    /// waiting on the grains (m^3), read back.
    fn liquid_sums(&self, n_pairs: u64) -> (u64, f64, f64) {
        let blocks = self.params.hist_blocks as usize;
        let parts = self.read(&[("hist", 0, 16 * n_pairs * blocks as u64), ("liquid", 0, 4 * self.n as u64)]);
        let hist: &[[f32; 4]] = bytemuck::cast_slice(&parts[0]);
        let liquid: &[f32] = bytemuck::cast_slice(&parts[1]);
        let volumes = hist.iter().skip(blocks - 1).step_by(blocks).map(|b| b[0]).filter(|&v| v > 0.0);
        let (bridges, held) = volumes.fold((0, 0.0), |(n, s), v| (n + 1, s + v as f64));
        (bridges, held, liquid.iter().map(|&l| l as f64).sum())
    }

    /// Reads grain arrays back (vec4 per grain).
    fn read_vec4s(&self, names: &[&str]) -> Vec<Vec<[f32; 4]>> {
        let parts: Vec<(&str, u64, u64)> = names.iter().map(|n| (*n, 0, 16 * self.n as u64)).collect();
        self.read(&parts).into_iter().map(|b| bytemuck::cast_slice(&b).to_vec()).collect()
    }
}

impl Engine for GpuEngine {
    fn backend(&self) -> &'static str {
        "gpu"
    }
    fn precision(&self) -> &'static str {
        "f32"
    }
    fn grain_count(&self) -> usize {
        self.n as usize
    }
    fn steps(&self) -> u64 {
        self.step
    }
    fn time(&self) -> f64 {
        self.time
    }

    fn advance(&mut self, n: u64) -> Result<(), SimError> {
        let mut done = 0;
        while done < n {
            let chunk = STEPS_PER_SUBMIT.min(n - done);
            let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                if self.schedule.needs_loads && !self.forces_valid {
                    self.encode_plan(&mut pass, 0);
                }
                for s in 0..chunk {
                    self.encode_plan(&mut pass, if self.step + s == 0 { 1 } else { 2 });
                }
            }
            self.gpu.queue.submit([encoder.finish()]);
            self.forces_valid = true;
            self.step += chunk;
            self.time += chunk as f64 * self.dt;
            done += chunk;
        }
        self.check()
    }

    fn stats(&mut self) -> Stats {
        self.ensure_loads();
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.run(&mut pass, "reduce_grains", Size::Grains, None);
            self.run(&mut pass, "reduce_pairs", Size::Indirect(args::PAIRS), None);
            self.run(&mut pass, "reduce_final", Size::One, None);
        }
        self.gpu.queue.submit([encoder.finish()]);
        let n_walls = self.wall_names.len();
        let parts = self.read(&[
            ("control", 0, std::mem::size_of::<Control>() as u64),
            ("stats", 0, 2 * STAT_ROW as u64 * 4),
            ("wall_reaction", 0, MAX_WALLS as u64 * 16),
            ("walls", 0, (n_walls.max(1) * std::mem::size_of::<layout::Wall>()) as u64),
            ("servo", 0, std::mem::size_of::<layout::Servo>() as u64),
        ]);
        let control: Control = *bytemuck::from_bytes(bytemuck::cast_slice(&parts[0]));
        let servo: layout::Servo = *bytemuck::from_bytes(bytemuck::cast_slice(&parts[4]));
        self.control = control;
        let s: &[f32] = bytemuck::cast_slice(&parts[1]);
        let reaction: &[[f32; 4]] = bytemuck::cast_slice(&parts[2]);
        let walls: &[layout::Wall] = bytemuck::cast_slice(&parts[3]);
        use layout::stat::{grain as gr, pair as pr};
        let g = |f: usize| s[f] as f64;
        let p = |f: usize| s[STAT_ROW + f] as f64;
        let g_count = |f: usize| s[f].to_bits() as u64;
        let p_count = |f: usize| s[STAT_ROW + f].to_bits() as u64;
        let n = self.n as f64;
        let contacts = p_count(pr::CONTACTS);
        let wall_contacts = g_count(gr::WALL_CONTACTS);
        let contact_ends = 2 * contacts + wall_contacts;
        let rattlers = g_count(gr::RATTLERS);
        let contact_force = p(pr::FORCE) + g(gr::WALL_FORCE);
        let unbalanced_force = crate::engine::unbalanced(g(gr::NET_FORCE), n, contact_force, contact_ends);
        let unbalanced_force_loaded = crate::engine::unbalanced(g(gr::NET_LOADED), n - rattlers as f64, contact_force, contact_ends);
        let (max_overlap, max_overlap_grain) = {
            let (gv, gi) = (g(STAT_ROW - 2), s[STAT_ROW - 1].to_bits());
            let (pv, pi) = (p(STAT_ROW - 2), s[2 * STAT_ROW - 1].to_bits());
            if gv > pv || (gv == pv && gi < pi) { (gv, gi) } else { (pv, pi) }
        };
        let (bridges, liquid_in_bridges, liquid_on_grains) = if self.history.bridge { self.liquid_sums(control.n_pairs as u64) } else { (0, 0.0, 0.0) };
        let piston = self.piston.map(|w| {
            let wall = &walls[w];
            PistonStats {
                z: wall.point[2] as f64,
                velocity: wall.velocity[2] as f64,
                target_pressure: wall.piston[2] as f64,
                pressure: reaction[w][2] as f64 / wall.piston[1] as f64,
            }
        });
        Stats {
            step: self.step,
            time: self.time,
            ke_translational: g(gr::KE_T),
            ke_rotational: g(gr::KE_R),
            elastic_energy: p(pr::ELASTIC) + g(gr::WALL_ELASTIC),
            gravity_energy: g(gr::PE_G),
            piston_ke: self.piston.map_or(0.0, |w| 0.5 * walls[w].piston[0] as f64 * (walls[w].velocity[2] as f64).powi(2)),
            external_work: self.piston.map_or(0.0, |w| walls[w].piston[3] as f64) + servo.work as f64 + servo.work_lo as f64,
            momentum: [0, 1, 2].map(|a| g(gr::MOMENTUM + a)),
            angular_momentum: [0, 1, 2].map(|a| g(gr::ANGULAR + a)),
            pairs: control.n_pairs as u64,
            contacts,
            wall_contacts,
            clamped: p_count(pr::CLAMPED),
            sliding: p_count(pr::SLIDING) + g_count(gr::WALL_SLIDING),
            rolling: p_count(pr::ROLLING) + g_count(gr::WALL_ROLLING),
            coordination: 2.0 * contacts as f64 / n,
            max_overlap,
            max_overlap_grain: if max_overlap_grain == NONE { 0 } else { max_overlap_grain },
            unbalanced_force,
            unbalanced_force_loaded,
            rattlers,
            ke_rattlers: g(gr::KE_RATTLERS),
            non_finite_grain: (control.non_finite != NONE).then_some(control.non_finite),
            rebuilds: control.rebuilds as u64,
            bridges,
            liquid_in_bridges,
            liquid_on_grains,
            walls: (0..n_walls)
                .map(|w| {
                    let servo_plane = self.servo.and_then(|planes| planes.iter().position(|&p| p == w));
                    WallStats {
                        name: self.wall_names[w].clone(),
                        force: [reaction[w][0] as f64, reaction[w][1] as f64, reaction[w][2] as f64],
                        contacts: reaction[w][3].round() as u64,
                        position: servo_plane.map(|k| walls[w].point[k / 2] as f64),
                        pressure: servo_plane.map(|k| servo_pressure(walls, reaction, self.servo.expect("a servo plane"), k)),
                    }
                })
                .collect(),
            piston,
        }
    }

    fn frame(&self, contacts: bool) -> Frame {
        let mut names = vec!["pos", "vel", "omega"];
        if self.track_orientation {
            names.push("quat");
        }
        let arrays = self.read_vec4s(&names);
        let xyz = |v: &[f32; 4]| [v[0] as f64, v[1] as f64, v[2] as f64];
        let contact_records = contacts.then(|| {
            let np = self.control.n_pairs as u64;
            let blocks = self.params.hist_blocks as u64;
            let parts = self.read(&[("pair_i", 0, 4 * np), ("pair_j", 0, 4 * np), ("out_fi", 0, 16 * np), ("out_fj", 0, 16 * np), ("hist", 0, 16 * np * blocks), ("out_tj", 0, 16 * np)]);
            let (pi, pj): (&[u32], &[u32]) = (&parts[0], &parts[1]);
            let fi: &[[f32; 4]] = bytemuck::cast_slice(&parts[2]);
            let fj: &[[f32; 4]] = bytemuck::cast_slice(&parts[3]);
            let hist: &[[f32; 4]] = bytemuck::cast_slice(&parts[4]);
            // out_tj.w: the capillary force.
            let f_c: Vec<f32> = bytemuck::cast_slice::<u32, [f32; 4]>(&parts[5]).iter().map(|t| t[3]).collect();
            let pos = &arrays[0];
            (0..np as usize)
                .filter_map(|k| {
                    let (a, b) = (&pos[pi[k] as usize], &pos[pj[k] as usize]);
                    let d = [(a[0] - b[0]) as f64, (a[1] - b[1]) as f64, (a[2] - b[2]) as f64];
                    let mut d2 = 0.0;
                    for (axis, x) in d.iter().enumerate() {
                        let len = self.params.periodic_len[axis] as f64;
                        let x = if len > 0.0 { x - len * (x / len + 0.5).floor() } else { *x };
                        d2 += x * x;
                    }
                    let h = (a[3] + b[3]) as f64 - d2.sqrt();
                    (h > 0.0 || f_c[k] != 0.0).then(|| ContactRecord {
                        i: pi[k],
                        j: pj[k],
                        overlap: h,
                        normal_force: (fi[k][3] + f_c[k]) as f64,
                        force: xyz(&fi[k]),
                        force_j: xyz(&fj[k]),
                        tangential_spring: if self.history.tangential { xyz(&hist[k * blocks as usize]) } else { [0.0; 3] },
                        rolling_spring: if self.history.rolling { xyz(&hist[k * blocks as usize + self.history.tangential as usize]) } else { [0.0; 3] },
                    })
                })
                .collect()
        });
        let wall_records = (contacts && self.has_walls).then(|| self.wall_contact_records(&arrays)).or(contacts.then(Vec::new));
        Frame {
            time: self.time,
            id: (0..self.n).collect(),
            position: arrays[0].iter().map(xyz).collect(),
            radius: arrays[0].iter().map(|v| v[3] as f64).collect(),
            velocity: arrays[1].iter().map(xyz).collect(),
            angular_velocity: arrays[2].iter().map(xyz).collect(),
            orientation: self.track_orientation.then(|| arrays[3].iter().map(|q| [q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64]).collect()),
            contacts: contact_records,
            wall_contacts: wall_records,
        }
    }

    fn set_servo(&mut self, pressure: Option<f64>, axial_strain_rate: Option<f64>) {
        if self.servo.is_none() {
            return;
        }
        let buffer = &self.buffers["servo"];
        let at = |offset: usize| offset as u64;
        if let Some(p) = pressure {
            self.gpu.queue.write_buffer(buffer, at(std::mem::offset_of!(layout::Servo, pressure)), bytemuck::bytes_of(&(p as f32)));
        }
        let (strain, rate) = axial_strain_rate.map_or((0u32, 0.0f32), |r| (1, r as f32));
        self.gpu.queue.write_buffer(buffer, at(std::mem::offset_of!(layout::Servo, strain_rate)), bytemuck::bytes_of(&rate));
        self.gpu.queue.write_buffer(buffer, at(std::mem::offset_of!(layout::Servo, strain)), bytemuck::bytes_of(&strain));
    }

    fn wet(&mut self, volume: f64) -> anyhow::Result<()> {
        use crate::real::Vec3;
        let crate::model::CohesionLaw::Capillary { theta, .. } = self.model.cohesion else {
            anyhow::bail!("the scene wets the sample but has no capillary cohesion; fix: set model.cohesion = \"capillary\"");
        };
        // The liquid goes to the pairs of the current list.
        self.ensure_loads();
        let (n, np, blocks) = (self.n as u64, self.read_control().n_pairs as u64, self.params.hist_blocks as u64);
        let parts = self.read(&[("pos", 0, 16 * n), ("pair_i", 0, 4 * np), ("pair_j", 0, 4 * np), ("hist", 0, 16 * np * blocks), ("liquid", 0, 4 * n)]);
        let pos: &[[f32; 4]] = bytemuck::cast_slice(&parts[0]);
        let (pi, pj) = (&parts[1], &parts[2]);
        let mut hist: Vec<[f32; 4]> = bytemuck::cast_slice(&parts[3]).to_vec();
        let mut liquid: Vec<f32> = bytemuck::cast_slice(&parts[4]).to_vec();
        // The CPU twin's reduced diameters and gaps (in f32, as its f32 engine has them).
        let v3 = |p: &[f32; 4]| Vec3::new(p[0], p[1], p[2]);
        let d: Vec<f64> = (0..np as usize).map(|k| {
            let (ri, rj) = (pos[pi[k] as usize][3] as f64, pos[pj[k] as usize][3] as f64);
            2.0 * ri * rj / (ri + rj)
        }).collect();
        let gaps: Vec<f64> = (0..np as usize).map(|k| {
            let (a, b) = (&pos[pi[k] as usize], &pos[pj[k] as usize]);
            (self.periodic.min_image(v3(a) - v3(b)).norm() - a[3] - b[3]) as f64
        }).collect();
        let (shares, rest) = crate::model::share_liquid(volume, &d, &gaps, self.params.bridge_cap as f64, theta as f64);
        let last = blocks as usize - 1;
        for (k, v) in shares {
            hist[k * blocks as usize + last][0] += v as f32;
        }
        let rest = (rest / n as f64) as f32;
        for l in &mut liquid {
            *l += rest;
        }
        self.gpu.queue.write_buffer(&self.buffers["hist"], 0, bytemuck::cast_slice(&hist));
        self.gpu.queue.write_buffer(&self.buffers["liquid"], 0, bytemuck::cast_slice(&liquid));
        self.forces_valid = false;
        Ok(())
    }

    fn save(&self) -> Option<crate::checkpoint::EngineState> {
        let mut s = crate::checkpoint::EngineState::default();
        let n_pairs = self.control.n_pairs as u64;
        let per_pair: HashMap<&str, u64> = self.pair_buffers().into_iter().collect();
        let mut names: Vec<&'static str> = self.buffers.keys().copied().filter(|name| !NOT_STATE.contains(name)).collect();
        names.sort_unstable();
        let parts: Vec<(&str, u64, u64)> = names.iter().map(|&name| (name, 0, per_pair.get(name).map_or(self.buffers[name].size(), |b| b * n_pairs))).collect();
        for (name, words) in names.iter().zip(self.read(&parts)) {
            // Two 4-byte words per stored integer, the first in the low half.
            s.put_ints(&format!("gpu:{name}"), words.chunks(2).map(|c| c[0] as u64 | (c.get(1).copied().unwrap_or(0) as u64) << 32));
        }
        s.put_ints("counters", [self.step, self.forces_valid as u64, self.params.pair_capacity as u64]);
        s.put_reals("time", [self.time]);
        Some(s)
    }

    fn restore(&mut self, s: &crate::checkpoint::EngineState) -> anyhow::Result<()> {
        let counters = s.ints("counters", Some(3))?;
        if counters[2] != self.params.pair_capacity as u64 {
            self.allocate_pairs(counters[2]);
            self.build_bind_groups();
        }
        for (key, words) in &s.ints {
            let Some(name) = key.strip_prefix("gpu:") else { continue };
            let buffer = self.buffers.get(name).ok_or_else(|| anyhow::anyhow!("the checkpoint holds a GPU buffer `{name}` this engine lacks; fix: resume with the grains version that wrote it"))?;
            let bytes: Vec<u8> = words.iter().flat_map(|&w| w.to_le_bytes()).collect();
            // A list of an odd number of words was padded with one (beyond the live pairs).
            if bytes.len() as u64 > buffer.size() + 4 {
                anyhow::bail!("the checkpoint's GPU buffer `{name}` holds {} bytes, this scene's {}; fix: resume with the scene the checkpoint was written for", bytes.len(), buffer.size());
            }
            self.gpu.queue.write_buffer(buffer, 0, &bytes[..bytes.len().min(buffer.size() as usize)]);
        }
        (self.step, self.forces_valid) = (counters[0], counters[1] != 0);
        self.time = s.reals("time", 1)?[0];
        self.read_control();
        Ok(())
    }

    fn memory_bytes(&self) -> u64 {
        self.buffers.values().map(wgpu::Buffer::size).sum()
    }

    fn dispatches(&self) -> Option<u64> {
        Some(self.dispatches.get())
    }

    fn place_piston(&mut self, z: f64) {
        if let Some(w) = self.piston {
            let base = (w * std::mem::size_of::<layout::Wall>()) as u64;
            let queue = &self.gpu.queue;
            queue.write_buffer(&self.buffers["walls"], base + std::mem::offset_of!(layout::Wall, point) as u64 + 8, bytemuck::bytes_of(&(z as f32)));
            queue.write_buffer(&self.buffers["walls"], base + std::mem::offset_of!(layout::Wall, velocity) as u64 + 8, bytemuck::bytes_of(&0.0f32));
        }
    }

    fn set_piston_pressure(&mut self, pressure: f64) {
        if let Some(w) = self.piston {
            let offset = (w * std::mem::size_of::<layout::Wall>() + std::mem::offset_of!(layout::Wall, piston) + 8) as u64;
            self.gpu.queue.write_buffer(&self.buffers["walls"], offset, bytemuck::bytes_of(&(pressure as f32)));
        }
    }
}

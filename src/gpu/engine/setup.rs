//! What a scene hands the GPU: the uniform constants, the walls, the pair coefficients, the
//! servo box, the phases, and every buffer but the per-pair ones, filled from the scene.

use super::*;

/// The uniform constants of `scene`, with pair buffers of `pair_capacity` pairs, `hash_size`
/// hash buckets and `hist_blocks` history blocks per contact (the piston's index is the
/// walls', [`walls_of`]).
pub(super) fn params_of(scene: &Scene, pair_capacity: u64, hash_size: u64, hist_blocks: u64) -> Params {
    let model = &scene.model;
    let n = scene.grains.len() as u64;
    let reach = scene.skin + scene.bridges.reach;
    let mut params = Params {
        n_grains: n as u32,
        n_walls: scene.walls.len() as u32,
        n_materials: scene.materials.len() as u32,
        pair_capacity: pair_capacity as u32,
        hash_size: hash_size as u32,
        max_neighbours: scene.max_neighbours as u32,
        r_min: scene.grains.radius.iter().copied().fold(f64::INFINITY, f64::min) as f32,
        piston: NONE,
        hist_blocks: hist_blocks as u32,
        gravity: Vec4::new(scene.gravity[0] as f32, scene.gravity[1] as f32, scene.gravity[2] as f32, 0.0),
        skin: scene.skin as f32,
        reach: reach as f32,
        ..Default::default()
    };
    for a in 0..3 {
        if let Some([lo, hi]) = scene.periodic[a] {
            params.periodic_lo[a] = lo as f32;
            params.periodic_len[a] = (hi - lo) as f32;
        }
    }
    // A grid per size class, with cells as wide as the class's largest pair and the reach
    // (the CPU's, src/state/levels.rs), a whole number of them over a period.
    let mut tops = crate::state::class_tops(scene.grains.radius.iter().copied());
    if tops.is_empty() {
        tops.push(0.0);
    }
    params.classes = tops.len() as u32;
    for (k, top) in tops.into_iter().enumerate() {
        let cutoff = 2.0 * top + reach;
        params.class_cell[k] = Vec4::new(cutoff as f32, cutoff as f32, cutoff as f32, top as f32);
        for a in 0..3 {
            if let Some([lo, hi]) = scene.periodic[a] {
                let dims = ((hi - lo) / cutoff).floor().max(1.0);
                params.class_dims[k][a] = dims as u32;
                params.class_cell[k][a] = ((hi - lo) / dims) as f32;
            }
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
    params
}

/// The walls as the kernels read them, their history placed for `hist_blocks` blocks per
/// contact, the piston's index among them, and the wall history's blocks per grain.
pub(super) fn walls_of(scene: &Scene, hist_blocks: u32) -> (Vec<layout::Wall>, Option<usize>, u32) {
    let mut piston = None;
    let mut hist_at = 0;
    let walls: Vec<layout::Wall> = scene
        .walls
        .iter()
        .enumerate()
        .map(|(w, wall)| {
            let mut g = layout::Wall { material: wall.material as u32, hist_at, turn: Vec4::X, ..Default::default() };
            hist_at += hist_blocks;
            match &wall.shape {
                &WallShape::Plane { point, normal } => {
                    g.kind = layout::wall_kind::PLANE;
                    g.point = Vec4::new(point[0] as f32, point[1] as f32, point[2] as f32, 0.0);
                    g.normal = Vec4::new(normal[0] as f32, normal[1] as f32, normal[2] as f32, 0.0);
                }
                &WallShape::Cylinder { center, radius } => {
                    g.kind = layout::wall_kind::CYLINDER;
                    g.point = Vec4::new(center[0] as f32, center[1] as f32, 0.0, 0.0);
                    g.normal = Vec4::new(0.0, 0.0, 0.0, radius as f32);
                }
                WallShape::Mesh { index, pivot, .. } => {
                    g.kind = layout::wall_kind::MESH;
                    g.normal = Vec4::new(f32::from_bits(*index), pivot[0] as f32, pivot[1] as f32, pivot[2] as f32);
                    hist_at += crate::mesh::MESH_CONTACTS as u32 * (hist_blocks + 1) - hist_blocks;
                }
                &WallShape::Piston { z, pressure, mass, area } => {
                    g.kind = layout::wall_kind::PISTON;
                    g.point = Vec4::new(0.0, 0.0, z as f32, 0.0);
                    g.drive = Vec4::new(mass as f32, area as f32, pressure as f32, 0.0);
                    piston = Some(w);
                }
            }
            if wall.drive.moves() {
                let (v, w) = (wall.drive.velocity, wall.drive.angular_velocity);
                g.flags |= layout::wall_flags::DRIVEN; // as `set_wall_drive` sets it
                g.velocity = Vec4::new(v[0] as f32, v[1] as f32, v[2] as f32, 0.0);
                g.drive = Vec4::new(w[0] as f32, w[1] as f32, w[2] as f32, 0.0);
                if wall.drive.turns {
                    g.flags |= layout::wall_flags::TURNS;
                }
            }
            if !wall.present {
                g.flags |= layout::wall_flags::ABSENT;
            }
            g
        })
        .collect();
    (walls, piston, hist_at)
}

/// The mesh walls' triangles as the kernels read them: each mesh's [`layout::MeshInfo`], the
/// corners (`mesh_data`) and the triangles, cells and ids (`mesh_index`), of `meshes`, the f32
/// surfaces the CPU's twin holds ([`Scene::mesh_surfaces`]).
pub(super) fn meshes_of(meshes: &[crate::mesh::MeshSurface<f32>]) -> (Vec<layout::MeshInfo>, Vec<[f32; 4]>, Vec<u32>) {
    let (mut infos, mut data, mut index) = (Vec::new(), Vec::new(), Vec::new());
    for m in meshes {
        let g = &m.grid;
        let (corners, triangles) = (data.len() as u32, index.len() as u32);
        data.extend(m.vertices.iter().map(|v| [v.x, v.y, v.z, 0.0]));
        for (t, e) in m.triangles.iter().zip(&m.edges) {
            index.extend(t.iter().chain(e));
        }
        let starts = index.len() as u32;
        index.extend(&g.start);
        let ids = index.len() as u32;
        index.extend(&g.ids);
        infos.push(layout::MeshInfo {
            origin: Vec4::new(g.origin.x, g.origin.y, g.origin.z, g.inv_cell),
            dims: UVec4::new(g.dims[0], g.dims[1], g.dims[2], starts),
            bases: UVec4::new(corners, triangles, ids, m.merge_cos.to_bits()),
        });
    }
    (infos, data, index)
}

/// Each pair of materials' coefficients, row-major, as the kernels read them.
pub(super) fn pair_coeffs_of(scene: &Scene) -> Vec<layout::PairCoeffs> {
    scene
        .pair_coeffs::<f32>()
        .into_iter()
        .map(|c| layout::PairCoeffs { v_eff: c.v_eff, g_eff: c.g_eff, mu_s: c.mu_s, mu_k: c.mu_k, tan_roll: c.tan_roll, gamma_n: c.gamma_n, gamma_nt: c.gamma_nt, beta: c.beta })
        .collect()
}

/// The servo box's constants as the kernels read them (zeros without one).
pub(super) fn servo_of(scene: &Scene) -> layout::Servo {
    scene.servo.map_or(layout::Servo::default(), |s| {
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
    })
}

/// The plans' phases, each in its slot of `stride` bytes of the `phase` uniform (the
/// device's uniform offset alignment).
pub(super) fn phase_slots(plans: &Plans, stride: u64) -> (Vec<Phase>, Vec<u8>) {
    let mut phases: Vec<Phase> = Vec::new();
    for e in &plans.entries() {
        if !phases.contains(&e.phase) {
            phases.push(e.phase);
        }
    }
    let mut phase_bytes = vec![0u8; stride as usize * phases.len()];
    for (slot, p) in phases.iter().enumerate() {
        let at = slot * stride as usize;
        phase_bytes[at..at + std::mem::size_of::<Phase>()].copy_from_slice(bytemuck::bytes_of(p));
    }
    (phases, phase_bytes)
}

/// Every buffer of the step but the per-pair ones ([`GpuEngine::allocate_pairs`]), filled from
/// the scene, the constants, the walls, the control record and the phases.
pub(super) fn scene_buffers(device: &wgpu::Device, scene: &Scene, params: &Params, walls: Vec<layout::Wall>, meshes: &[crate::mesh::MeshSurface<f32>], control: &Control, phase_bytes: &[u8]) -> Buffers {
    let g = &scene.grains;
    let (n, hash_size) = (g.len() as u64, params.hash_size as u64);
    let coeffs = pair_coeffs_of(scene);
    let v4 = |a: glam::DVec3, w: f64| [a[0] as f32, a[1] as f32, a[2] as f32, w as f32];
    // The radius negated for a grain out of play (WGSL `in_play`).
    let pos: Vec<[f32; 4]> = (0..g.len()).map(|i| v4(g.position[i], if g.starts_in_play(i) { g.radius[i] } else { -g.radius[i] })).collect();
    // What rounding took off each position (src/position.rs), as the CPU's f32 engine keeps it.
    let residual: Vec<[f32; 4]> = g.position.iter().map(|&x| { let (_, r) = crate::position::split::<f32>(x); [r.x, r.y, r.z, 0.0] }).collect();
    let vel: Vec<[f32; 4]> = (0..g.len()).map(|i| v4(g.velocity[i], g.mass[i])).collect();
    // The inertia in w as the CPU's f32 engine keeps it.
    let inertia = |i: usize| crate::state::Props::<f32>::sphere(g.radius[i], g.mass[i]).inertia;
    let omega: Vec<[f32; 4]> = (0..g.len()).map(|i| { let w = g.angular_velocity[i]; [w[0] as f32, w[1] as f32, w[2] as f32, inertia(i)] }).collect();
    let material: Vec<u32> = g.material.iter().map(|&m| m as u32).collect();
    let periodic = scene.periodic.iter().any(Option::is_some);

    let mut buffers = Buffers::default();
    let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let mut init = |name: Buf, bytes: &[u8], extra: wgpu::BufferUsages| {
        let b = device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(name.name()), contents: bytes, usage: storage | extra });
        buffers.insert(name, b);
    };
    init(Buf::Pos, bytemuck::cast_slice(&pos), wgpu::BufferUsages::empty());
    init(Buf::Residual, bytemuck::cast_slice(&residual), wgpu::BufferUsages::empty());
    init(Buf::Vel, bytemuck::cast_slice(&vel), wgpu::BufferUsages::empty());
    init(Buf::Omega, bytemuck::cast_slice(&omega), wgpu::BufferUsages::empty());
    init(Buf::Material, bytemuck::cast_slice(&material), wgpu::BufferUsages::empty());
    let liquid = vec![0.0f32; if scene.model.history_layout().bridge { g.len() } else { 4 }];
    init(Buf::Liquid, bytemuck::cast_slice(&liquid), wgpu::BufferUsages::empty());
    init(Buf::Coeffs, bytemuck::cast_slice(&coeffs), wgpu::BufferUsages::empty());
    let walls_bytes: Vec<layout::Wall> = if walls.is_empty() { vec![layout::Wall::default()] } else { walls };
    init(Buf::Walls, bytemuck::cast_slice(&walls_bytes), wgpu::BufferUsages::empty());
    init(Buf::Control, bytemuck::bytes_of(control), wgpu::BufferUsages::empty());
    let (infos, data, index) = meshes_of(meshes);
    init(Buf::Meshes, if infos.is_empty() { &[0; 48] } else { bytemuck::cast_slice(&infos) }, wgpu::BufferUsages::empty());
    init(Buf::MeshData, if data.is_empty() { &[0; 16] } else { bytemuck::cast_slice(&data) }, wgpu::BufferUsages::empty());
    init(Buf::MeshIndex, if index.is_empty() { &[0; 16] } else { bytemuck::cast_slice(&index) }, wgpu::BufferUsages::empty());
    let mut dispatch_args = vec![DispatchArgs { x: 0, y: 1, z: 1 }; args::SLOTS as usize];
    (dispatch_args[args::STEP_GRAINS as usize], dispatch_args[args::STEP_ONE as usize]) = (DispatchArgs::items(n), DispatchArgs::ONE);
    init(Buf::Args, bytemuck::cast_slice(&dispatch_args), wgpu::BufferUsages::INDIRECT);
    let quat: Vec<[f32; 4]> = if scene.track_orientation { vec![[1.0, 0.0, 0.0, 0.0]; g.len()] } else { vec![[0.0; 4]] };
    init(Buf::Quat, bytemuck::cast_slice(&quat), wgpu::BufferUsages::empty());
    init(Buf::Params, bytemuck::bytes_of(params), wgpu::BufferUsages::UNIFORM);
    let servo = servo_of(scene);
    init(Buf::Servo, bytemuck::bytes_of(&servo), wgpu::BufferUsages::empty());

    init(Buf::Phase, phase_bytes, wgpu::BufferUsages::UNIFORM);

    let mut zeroed = |name: Buf, bytes: u64| {
        let b = device.create_buffer(&wgpu::BufferDescriptor { label: Some(name.name()), size: bytes.max(16), usage: storage, mapped_at_creation: false });
        buffers.insert(name, b);
    };
    let v = 16 * n;
    for name in [Buf::Force, Buf::Torque, Buf::BuiltAt] {
        zeroed(name, v);
    }
    zeroed(Buf::Image, if periodic { v } else { 16 });
    zeroed(Buf::CellCount, 4 * hash_size);
    zeroed(Buf::CellFill, 4 * hash_size);
    zeroed(Buf::HashSums, 4 * hash_size.div_ceil(2048));
    zeroed(Buf::GrainSums, 4 * (n + 1).div_ceil(2048));
    zeroed(Buf::SpareSum, 4);
    for name in [Buf::PairStart, Buf::RevStart] {
        zeroed(name, 4 * (n + 1));
    }
    let wall_hist = 16 * n * params.wall_blocks as u64;
    zeroed(Buf::WallHist, wall_hist);
    // Per wall: the reaction, then the contacts' stiffness and damping (servo walls).
    let wall_partials = workgroup::rows(n) * 2 * MAX_WALLS as u64 * 16;
    zeroed(Buf::WallPartials, wall_partials);
    // The rebuild's scratch fits the buffers that hold it (REBUILD_SCRATCH).
    debug_assert!(v.max(16) >= 4 * (n + 1) && wall_partials >= 4 * n);
    zeroed(Buf::WallReaction, 2 * MAX_WALLS as u64 * 16);
    zeroed(Buf::GrainRows, workgroup::rows(n) * STAT_ROW as u64 * 4);
    zeroed(Buf::Stats, 2 * STAT_ROW as u64 * 4);
    buffers
}

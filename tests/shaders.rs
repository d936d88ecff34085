//! Without a GPU: naga parses and validates every kernel, the kernel table's bindings match
//! what each shader declares, and the Rust mirrors of the WGSL structures have the same sizes
//! and field offsets.

use grains::gpu::layout;
use grains::gpu::kernels::{Access, CD_KERNELS, KERNELS};
use naga::valid::{Capabilities, ValidationFlags, Validator};
use std::mem::{offset_of, size_of};

fn module(wgsl: &str, name: &str) -> naga::Module {
    naga::front::wgsl::parse_str(wgsl).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(wgsl)))
}

#[test]
fn every_kernel_parses_and_validates() {
    for k in KERNELS.iter().chain(CD_KERNELS) {
        let src = k.wgsl();
        let m = module(&src, k.name);
        Validator::new(ValidationFlags::all(), Capabilities::default())
            .validate(&m)
            .unwrap_or_else(|e| panic!("{}: {}", k.name, e.emit_to_string(&src)));
        assert!(m.entry_points.iter().any(|e| e.name == k.name), "{}: the entry point must carry the kernel's name", k.name);
        let first = k.source.lines().next().unwrap_or("");
        assert!(first.starts_with("// One "), "{}: the first line says what one invocation does: {first}", k.name);
    }
}

/// The global variable a pointer expression of `f` goes through, if any.
fn root(f: &naga::Function, mut e: naga::Handle<naga::Expression>) -> Option<naga::Handle<naga::GlobalVariable>> {
    loop {
        match f.expressions[e] {
            naga::Expression::Access { base, .. } | naga::Expression::AccessIndex { base, .. } => e = base,
            naga::Expression::GlobalVariable(g) => return Some(g),
            _ => return None,
        }
    }
}

/// Every statement of `block`, nested blocks included.
fn each_statement(block: &naga::Block, visit: &mut impl FnMut(&naga::Statement)) {
    for st in block.iter() {
        visit(st);
        match st {
            naga::Statement::Block(b) => each_statement(b, visit),
            naga::Statement::If { accept, reject, .. } => {
                each_statement(accept, visit);
                each_statement(reject, visit);
            }
            naga::Statement::Loop { body, continuing, .. } => {
                each_statement(body, visit);
                each_statement(continuing, visit);
            }
            naga::Statement::Switch { cases, .. } => cases.iter().for_each(|c| each_statement(&c.body, visit)),
            _ => {}
        }
    }
}

/// Every function of `m`, entry points included.
fn functions(m: &naga::Module) -> impl Iterator<Item = &naga::Function> {
    m.functions.iter().map(|(_, f)| f).chain(m.entry_points.iter().map(|e| &e.function))
}

/// The global variables some function of `m` loads from (reads, or reads and modifies with an
/// atomic): the root of every pointer a `Load` or an atomic goes through. Functions the kernel
/// never calls count too, so a binding they load is taken as loaded (the safe side).
fn loaded_globals(m: &naga::Module) -> std::collections::HashSet<naga::Handle<naga::GlobalVariable>> {
    let mut out = std::collections::HashSet::new();
    for f in functions(m) {
        for (_, e) in f.expressions.iter() {
            if let naga::Expression::Load { pointer } = e {
                out.extend(root(f, *pointer));
            }
        }
        each_statement(&f.body, &mut |st| {
            if let naga::Statement::Atomic { pointer, .. } = st {
                out.extend(root(f, *pointer));
            }
        });
    }
    out
}

/// The global variables some function of `m` stores to.
fn stored_globals(m: &naga::Module) -> std::collections::HashSet<naga::Handle<naga::GlobalVariable>> {
    let mut out = std::collections::HashSet::new();
    for f in functions(m) {
        each_statement(&f.body, &mut |st| {
            if let naga::Statement::Store { pointer, .. } = st {
                out.extend(root(f, *pointer));
            }
        });
    }
    out
}

/// Each kernel's bindings in the table as its shader declares them, in order, with their use:
/// a read-write binding that no function loads is `Write` (the traffic count takes it once),
/// one that some function loads is `ReadWrite`; every storage binding is loaded or stored.
#[test]
fn the_kernel_table_matches_each_shaders_bindings() {
    for k in KERNELS.iter().chain(CD_KERNELS) {
        let m = module(&k.wgsl(), k.name);
        let loaded = loaded_globals(&m);
        let stored = stored_globals(&m);
        // A storage binding no function loads or stores would be bound and counted as traffic
        // for nothing (or, as once, a clear someone forgot); uniforms are bound by convention.
        for (h, v) in m.global_variables.iter().filter(|(_, v)| v.binding.is_some() && matches!(v.space, naga::AddressSpace::Storage { .. })) {
            assert!(loaded.contains(&h) || stored.contains(&h), "{}: storage binding {:?} is declared but never loaded or stored", k.name, v.name);
        }
        let mut declared: Vec<(u32, String, Access)> = m
            .global_variables
            .iter()
            .filter_map(|(h, v)| {
                let b = v.binding.as_ref()?;
                assert_eq!(b.group, 0, "{}: one bind group", k.name);
                let access = match v.space {
                    naga::AddressSpace::Uniform if v.name.as_deref() == Some("phase") => Access::Phase,
                    naga::AddressSpace::Uniform => Access::Uniform,
                    naga::AddressSpace::Storage { access } if access.contains(naga::StorageAccess::STORE) => {
                        if loaded.contains(&h) { Access::ReadWrite } else { Access::Write }
                    }
                    naga::AddressSpace::Storage { .. } => Access::Read,
                    other => panic!("{}: unexpected address space {other:?}", k.name),
                };
                Some((b.binding, v.name.clone().unwrap_or_default(), access))
            })
            .collect();
        declared.sort_by_key(|d| d.0);
        let table: Vec<(u32, String, Access)> = k.bindings.iter().enumerate().map(|(i, (n, a))| (i as u32, n.name().to_string(), *a)).collect();
        assert_eq!(declared, table, "{}: shader bindings vs the kernel table", k.name);
    }
}

/// Size and member offsets of a WGSL struct, by naga's layouter.
fn wgsl_layout(m: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(m.to_ctx()).unwrap();
    let (handle, ty) = m.types.iter().find(|(_, t)| t.name.as_deref() == Some(name)).unwrap_or_else(|| panic!("no struct {name}"));
    let naga::TypeInner::Struct { members, span } = &ty.inner else { panic!("{name} is not a struct") };
    assert_eq!(layouter[handle].size, *span);
    (*span, members.iter().map(|mm| (mm.name.clone().unwrap_or_default(), mm.offset)).collect())
}

macro_rules! check_struct {
    ($m:expr, $ty:ty, $name:literal, [$($field:ident),* $(,)?]) => {{
        let (size, members) = wgsl_layout($m, $name);
        assert_eq!(size as usize, size_of::<$ty>(), "{} size", $name);
        let rust: Vec<(String, u32)> = vec![$((stringify!($field).to_string(), offset_of!($ty, $field) as u32)),*];
        assert_eq!(members, rust, "{} members and offsets", $name);
    }};
}

#[test]
fn rust_mirrors_match_the_wgsl_structures() {
    let src = grains::gpu::kernels::shared("types");
    let m = module(&format!("{src}\n@group(0) @binding(0) var<storage, read_write> c: Control;\n@compute @workgroup_size(1) fn main() {{ atomicStore(&c.max_disp2, 0u); }}"), "types");
    check_struct!(&m, layout::Params, "Params", [
        n_grains, n_walls, n_materials, pair_capacity, hash_size, max_neighbours, piston, hist_blocks,
        gravity, periodic_lo, periodic_len, normal, damping, tangential, rolling, cohesion,
        skin, reach, kt_law, rolling_as_written, r_min, classes, wall_blocks, _pad2, class_cell, class_dims
    ]);
    check_struct!(&m, layout::Phase, "Phase", [kick, drift, elapsed, then_kick]);
    check_struct!(&m, layout::PairCoeffs, "PairCoeffs", [v_eff, g_eff, mu_s, mu_k, tan_roll, gamma_n, gamma_nt, beta]);
    check_struct!(&m, layout::Wall, "Wall", [kind, material, flags, hist_at, point, normal, velocity, drive, turn]);
    check_struct!(&m, layout::Control, "Control", [max_disp2, rebuild, rebuilds, n_pairs, overflow_grain, overflow_count, pair_overflow, non_finite, rebuild_checks, mesh_overflow]);
    check_struct!(&m, layout::MeshInfo, "MeshInfo", [origin, dims, bases]);
    check_struct!(&m, layout::DispatchArgs, "DispatchArgs", [x, y, z]);
    check_struct!(&m, layout::Servo, "Servo", [walls_lo, walls_hi, pressure, gain, max_speed, strain_rate, relaxation, work, work_lo, strain]);
    // Constants the host relies on.
    let constant = |name: &str| -> u32 {
        let (_, c) = m.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).unwrap_or_else(|| panic!("no const {name}"));
        match m.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref e => panic!("{name}: {e:?}"),
        }
    };
    assert_eq!(constant("WG"), layout::WG);
    assert_eq!(constant("MAX_WALLS") as usize, layout::MAX_WALLS);
    assert_eq!(constant("MAX_CLASSES") as usize, layout::MAX_CLASSES);
    assert_eq!(constant("STAT_ROW") as usize, layout::STAT_ROW);
    assert_eq!(constant("RATTLER_CONTACTS") as u64, grains::engine::RATTLER_CONTACTS);
    assert_eq!(constant("SCAN_BLOCK") as u64, layout::SCAN_BLOCK);
    use layout::normal_slot;
    for (name, slot) in [("NORMAL_SLOT_NONE", normal_slot::NONE), ("NORMAL_SLOT_TANGENTIAL_W", normal_slot::TANGENTIAL_W), ("NORMAL_SLOT_ROLLING_W", normal_slot::ROLLING_W), ("NORMAL_SLOT_BRIDGE_Y", normal_slot::BRIDGE_Y), ("NORMAL_SLOT_OWN", normal_slot::OWN)] {
        assert_eq!(constant(name), slot, "{name}");
    }
    for (name, flag) in [("WALL_DRIVEN", layout::wall_flags::DRIVEN), ("WALL_ABSENT", layout::wall_flags::ABSENT), ("WALL_TURNS", layout::wall_flags::TURNS)] {
        assert_eq!(constant(name), flag, "{name}");
    }
    for (name, kind) in [("WALL_PLANE", layout::wall_kind::PLANE), ("WALL_CYLINDER", layout::wall_kind::CYLINDER), ("WALL_PISTON", layout::wall_kind::PISTON), ("WALL_MESH", layout::wall_kind::MESH)] {
        assert_eq!(constant(name), kind, "{name}");
    }
    use layout::stat::{grain, pair};
    let grain_fields = [("G_KE_T", grain::KE_T), ("G_KE_R", grain::KE_R), ("G_PE_G", grain::PE_G), ("G_MOMENTUM", grain::MOMENTUM), ("G_ANGULAR", grain::ANGULAR), ("G_NET_FORCE", grain::NET_FORCE), ("G_WALL_FORCE", grain::WALL_FORCE), ("G_WALL_CONTACTS", grain::WALL_CONTACTS), ("G_WALL_ELASTIC", grain::WALL_ELASTIC), ("G_WALL_SLIDING", grain::WALL_SLIDING), ("G_WALL_ROLLING", grain::WALL_ROLLING), ("G_RATTLERS", grain::RATTLERS), ("G_KE_RATTLERS", grain::KE_RATTLERS), ("G_NET_LOADED", grain::NET_LOADED)];
    let pair_fields = [("P_CONTACTS", pair::CONTACTS), ("P_CLAMPED", pair::CLAMPED), ("P_ELASTIC", pair::ELASTIC), ("P_FORCE", pair::FORCE), ("P_SLIDING", pair::SLIDING), ("P_ROLLING", pair::ROLLING)];
    for (name, field) in grain_fields.iter().chain(&pair_fields) {
        assert_eq!(constant(name) as usize, *field, "{name}");
        assert!(*field < layout::STAT_ROW - 2, "{name} lies before the (largest, grain) pair");
    }
    assert_eq!(constant("NONE"), layout::NONE);
    for (name, slot) in [("ARGS_GRAINS", layout::args::GRAINS), ("ARGS_HASH", layout::args::HASH), ("ARGS_HASH_BLOCKS", layout::args::HASH_BLOCKS), ("ARGS_GRAIN_BLOCKS", layout::args::GRAIN_BLOCKS), ("ARGS_ONE", layout::args::ONE), ("ARGS_OLD_PAIRS", layout::args::OLD_PAIRS), ("ARGS_PAIRS", layout::args::PAIRS), ("ARGS_NEW_PAIRS", layout::args::NEW_PAIRS), ("ARGS_GRAIN_STARTS", layout::args::GRAIN_STARTS), ("ARGS_STEP_GRAINS", layout::args::STEP_GRAINS), ("ARGS_STEP_ONE", layout::args::STEP_ONE), ("ARGS_SLOTS", layout::args::SLOTS)] {
        assert_eq!(constant(name) as u64, slot, "{name}");
    }
}

#[test]
fn contact_dynamics_mirrors_match_the_wgsl_structures() {
    let src = format!("{}\n{}", grains::gpu::kernels::shared("types"), grains::gpu::kernels::shared("cd"));
    let m = module(&format!("{src}\n@group(0) @binding(0) var<storage, read_write> c: array<CdContact>;\n@group(0) @binding(1) var<uniform> p: CdParams;\n@group(0) @binding(2) var<uniform> k: CdColour;\n@group(0) @binding(3) var<storage, read_write> s: CdControl;\n@compute @workgroup_size(1) fn main() {{ s.iterations = p.n_contacts + k.start + c[0].a; }}"), "cd");
    check_struct!(&m, layout::CdContact, "CdContact", [a, b, to_wall, _pad0, n, radius_a, radius_b, mu, w_n, w_t, inv_mass_a, inv_inertia_a, inv_mass_b, inv_inertia_b, inv_w_n, inv_w_t, _pad1]);
    check_struct!(&m, layout::CdParams, "CdParams", [n_contacts, tail, n_blocks, max_iterations, tolerance2, relaxation, _pad1, _pad2]);
    check_struct!(&m, layout::CdColour, "CdColour", [start, end, _pad0, _pad1]);
    check_struct!(&m, layout::CdControl, "CdControl", [iterations, converged, done, _pad0, sweep_norm2, _pad1, _pad2, _pad3]);
    let (_, c) = m.constants.iter().find(|(_, c)| c.name.as_deref() == Some("MEASURE_BLOCK")).expect("MEASURE_BLOCK");
    match m.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => assert_eq!(v as usize, grains::cd::MEASURE_BLOCK),
        ref e => panic!("MEASURE_BLOCK: {e:?}"),
    }
}

/// The laws' codes reach the kernels from the registries, name for name, and every law a
/// registry lists has WGSL that names it: a law added in Rust alone would run on the GPU as
/// another.
#[test]
fn every_registered_law_has_its_code_and_a_branch_in_the_shaders() {
    let src = grains::gpu::kernels::StepKernel::PairForce.kernel().wgsl();
    let m = module(&src, "pair_force");
    let prelude = grains::model::wgsl_codes();
    // The model's WGSL without the prelude and without comments: where a law must be named.
    let own: String = src.replace(&prelude, "").lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n");
    let codes = grains::model::law_codes();
    assert!(codes.len() >= 17, "{} codes", codes.len());
    for (name, code) in &codes {
        let (_, c) = m.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name.as_str())).unwrap_or_else(|| panic!("no WGSL const {name}"));
        match m.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => assert_eq!(v, *code, "{name}"),
            ref e => panic!("{name}: {e:?}"),
        }
        assert!(own.contains(name.as_str()), "{name} has a registry row but no WGSL names it");
    }
}

/// The mesh kernels' region codes and slot counts are the CPU twin's (`src/mesh`).
#[test]
fn mesh_constants_match_the_cpu_twin() {
    let k = KERNELS.iter().find(|k| k.name == "gather").expect("the gather kernel");
    let src = k.wgsl();
    let m = module(&src, k.name);
    let constant = |name: &str| -> u32 {
        let (_, c) = m.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).unwrap_or_else(|| panic!("no const {name}"));
        match m.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref e => panic!("{name}: {e:?}"),
        }
    };
    use grains::mesh::closest::{EDGE, FACE, VERTEX};
    assert_eq!([constant("MESH_FACE"), constant("MESH_EDGE"), constant("MESH_VERTEX")], [FACE, EDGE, VERTEX]);
    assert_eq!(constant("MESH_CONTACTS") as usize, grains::mesh::MESH_CONTACTS);
    assert_eq!(constant("RAW_CONTACTS") as usize, grains::mesh::RAW_CONTACTS);
    assert!(constant("MESH_SLOT_NEW") as usize > grains::mesh::MESH_CONTACTS, "a new slot's mark must lie above every contact index");
}

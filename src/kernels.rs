//! The kernel table: every compute kernel of a step, its WGSL source, the shared files it
//! includes, and its bindings in binding order. The GPU engine builds its pipelines and bind
//! groups from it; `tests/shaders.rs` checks it against naga's reflection of each shader.
//! The CPU engine's twins carry the same names (`src/cpu/`: `hash_cells`, `detect_pairs`,
//! `remap_history`, `pair_force`, `wall_contacts`, `gather`, `integrate::{kick, drift}`; the
//! GPU's `integrate` runs a kick and the drift after it as one dispatch, and its `gather` the
//! wall contacts, as the CPU's gather sweep does);
//! the GPU-only kernels (scans, scatter, reverse list, reductions) are what a CPU does
//! serially in a loop.

/// How a kernel uses a binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// `var<uniform>`.
    Uniform,
    /// `var<uniform>` at a dynamic offset (the step phase).
    Phase,
    /// `var<storage, read>`.
    Read,
    /// `var<storage, read_write>`.
    ReadWrite,
    /// `var<storage, read_write>` that the kernel only stores to, never loads (WGSL has no
    /// write-only storage): the traffic count takes its bytes once.
    Write,
}

/// A kernel: one WGSL file, one entry point of the same name.
#[derive(Clone, Copy, Debug)]
pub struct Kernel {
    /// Entry point and file name (`shaders/<name>.wgsl`).
    pub name: &'static str,
    /// The kernel's WGSL.
    pub source: &'static str,
    /// Shared files prepended, in order (`shaders/shared/<name>.wgsl`).
    pub includes: &'static [&'static str],
    /// Bindings of group 0, in binding order.
    pub bindings: &'static [(&'static str, Access)],
}

/// A shared WGSL file by name.
pub fn shared(name: &str) -> &'static str {
    match name {
        "types" => include_str!("../shaders/shared/types.wgsl"),
        "dispatch" => include_str!("../shaders/shared/dispatch.wgsl"),
        "grid" => include_str!("../shaders/shared/grid.wgsl"),
        "model" => include_str!("../shaders/shared/model.wgsl"),
        "model/normal" => include_str!("../shaders/shared/model/normal.wgsl"),
        "model/damping" => include_str!("../shaders/shared/model/damping.wgsl"),
        "model/tangential" => include_str!("../shaders/shared/model/tangential.wgsl"),
        "model/rolling" => include_str!("../shaders/shared/model/rolling.wgsl"),
        "model/twisting" => include_str!("../shaders/shared/model/twisting.wgsl"),
        "model/cohesion" => include_str!("../shaders/shared/model/cohesion.wgsl"),
        "neighbours" => include_str!("../shaders/shared/neighbours.wgsl"),
        "walls" => include_str!("../shaders/shared/walls.wgsl"),
        "reduce" => include_str!("../shaders/shared/reduce.wgsl"),
        "kick" => include_str!("../shaders/shared/kick.wgsl"),
        "piston" => include_str!("../shaders/shared/piston.wgsl"),
        "drift" => include_str!("../shaders/shared/drift.wgsl"),
        "position" => include_str!("../shaders/shared/position.wgsl"),
        "cd" => include_str!("../shaders/shared/cd.wgsl"),
        other => panic!("no shared WGSL file {other}"),
    }
}

/// The contact model's files, one per slot, mirroring `src/model/<slot>/`.
pub const MODEL_SLOTS: &[&str] = &["model/normal", "model/damping", "model/tangential", "model/rolling", "model/twisting", "model/cohesion"];

impl Kernel {
    /// The full WGSL of the kernel: its includes, then its own file. The contact model
    /// (`model`) is every slot's law codes, written from the registries
    /// ([`crate::model::wgsl_codes`]), each slot's file ([`MODEL_SLOTS`],
    /// `shaders/shared/model/<slot>.wgsl`), then `shaders/shared/model.wgsl`, which composes
    /// them.
    pub fn wgsl(&self) -> String {
        let mut s = String::new();
        for inc in self.includes {
            if *inc == "model" {
                s.push_str(&crate::model::wgsl_codes());
                for slot in MODEL_SLOTS {
                    s.push_str(shared(slot));
                    s.push('\n');
                }
            }
            s.push_str(shared(inc));
            s.push('\n');
        }
        s.push_str(self.source);
        s
    }
}

use Access::{Phase, Read, ReadWrite, Uniform, Write};

const BASE: &[&str] = &["types", "dispatch"];
const PISTON: &[&str] = &["types", "dispatch", "piston"];
const INTEGRATE: &[&str] = &["types", "dispatch", "kick", "piston", "position", "drift"];
const GRID: &[&str] = &["types", "dispatch", "position", "grid"];
const DETECT: &[&str] = &["types", "dispatch", "position", "grid", "neighbours"];
const FORCES: &[&str] = &["types", "dispatch", "position", "grid", "model"];
const GATHER: &[&str] = &["types", "dispatch", "position", "grid", "model", "walls", "kick", "drift"];
const CD: &[&str] = &["types", "dispatch", "cd"];
const STATS: &[&str] = &["types", "dispatch", "position", "grid", "model", "walls", "reduce"];

macro_rules! kernel {
    ($name:literal, $inc:expr, [$($b:literal: $a:expr),* $(,)?]) => {
        Kernel { name: $name, source: include_str!(concat!("../shaders/", $name, ".wgsl")), includes: $inc, bindings: &[$(($b, $a)),*] }
    };
}

/// Declares an enum of kernels and their table from one list, so that a kernel is named by a
/// variant (a misspelt one does not compile) and its row stands at the variant's index.
macro_rules! kernel_table {
    ($(#[$enum_doc:meta])* $enum:ident, $(#[$table_doc:meta])* $table:ident, $($id:ident = $name:literal, $inc:expr, [$($b:literal: $a:expr),* $(,)?];)*) => {
        $(#[$enum_doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum $enum {
            $(
                #[doc = concat!("`shaders/", $name, ".wgsl`.")]
                $id,
            )*
        }

        $(#[$table_doc])*
        pub const $table: &[Kernel] = &[$(kernel!($name, $inc, [$($b: $a),*])),*];

        impl $enum {
            /// Every kernel, in the order of the table.
            pub const ALL: &[$enum] = &[$($enum::$id),*];

            /// The kernel's row.
            pub fn kernel(self) -> &'static Kernel {
                &$table[self as usize]
            }

            /// Its entry point and file name.
            pub fn name(self) -> &'static str {
                self.kernel().name
            }
        }
    };
}

kernel_table! {
    /// A kernel of the step, by name: its row in [`KERNELS`].
    StepKernel,
    /// Every kernel of the step, in the order a rebuilding step runs them.
    KERNELS,
    Integrate = "integrate", INTEGRATE, ["params": Uniform, "phase": Phase, "pos": ReadWrite, "residual": ReadWrite, "vel": ReadWrite, "omega": ReadWrite, "force": Read, "torque": Read, "built_at": Read, "quat": ReadWrite, "walls": ReadWrite, "wall_reaction": Read, "control": ReadWrite];
    ServoMove = "servo_move", BASE, ["params": Uniform, "phase": Phase, "walls": ReadWrite, "wall_reaction": Read, "servo": ReadWrite];
    DecideRebuild = "decide_rebuild", BASE, ["params": Uniform, "control": ReadWrite, "args": ReadWrite];
    SaveStarts = "save_starts", BASE, ["params": Uniform, "pair_start": Read, "old_start": Write];
    SavePairs = "save_pairs", BASE, ["params": Uniform, "pair_j": Read, "hist": Read, "old_j": Write, "old_hist0": Write, "old_hist1": Write, "old_hist2": Write, "control": Read];
    ClearCells = "clear_cells", BASE, ["params": Uniform, "cell_count": Write, "cell_fill": Write];
    HashCells = "hash_cells", GRID, ["params": Uniform, "pos": ReadWrite, "residual": ReadWrite, "image": ReadWrite, "built_at": Write, "cell_of": Write, "cell_count": ReadWrite, "control": ReadWrite, "pair_start": Write, "rev_start": Write];
    ScanBlocks = "scan_blocks", BASE, ["params": Uniform, "scan_data": ReadWrite, "block_sums": Write];
    ScanAdd = "scan_add", BASE, ["params": Uniform, "scan_data": ReadWrite, "block_sums": ReadWrite];
    ScatterCells = "scatter_cells", BASE, ["params": Uniform, "cell_of": Read, "cell_count": Read, "cell_fill": ReadWrite, "cell_grains": Write];
    DetectCount = "detect_count", DETECT, ["params": Uniform, "pos": Read, "residual": Read, "cell_count": Read, "cell_grains": Read, "pair_start": Write, "control": ReadWrite, "rev_fill": Write];
    PairsReady = "pairs_ready", BASE, ["params": Uniform, "pair_start": Read, "control": ReadWrite, "args": Write];
    DetectFill = "detect_fill", DETECT, ["params": Uniform, "pos": Read, "residual": Read, "cell_count": Read, "cell_grains": Read, "pair_start": Read, "pair_i": Write, "pair_j": ReadWrite];
    RemapHistory = "remap_history", BASE, ["params": Uniform, "pair_i": Read, "pair_j": Read, "old_start": Read, "old_j": Read, "old_hist0": Read, "old_hist1": Read, "old_hist2": Read, "hist": Write, "control": Read];
    ReverseCount = "reverse_count", BASE, ["params": Uniform, "pair_j": Read, "rev_start": ReadWrite, "control": Read];
    ReverseFill = "reverse_fill", BASE, ["params": Uniform, "pair_j": Read, "rev_start": Read, "rev_fill": ReadWrite, "rev_pair": Write, "control": Read];
    ReverseSort = "reverse_sort", BASE, ["params": Uniform, "rev_start": Read, "rev_pair": ReadWrite];
    FindBridgeEvents = "find_bridge_events", FORCES, ["params": Uniform, "pos": Read, "residual": Read, "pair_i": Read, "pair_j": Read, "hist": Read, "bridge_event": Write, "control": Read];
    UpdateBridges = "update_bridges", FORCES, ["params": Uniform, "pair_i": Read, "pair_j": Read, "bridge_event": Read, "hist": ReadWrite, "liquid": ReadWrite, "control": Read];
    PairForce = "pair_force", FORCES, ["params": Uniform, "phase": Phase, "pos": Read, "residual": Read, "vel": Read, "omega": Read, "material": Read, "coeffs": Read, "pair_i": Read, "pair_j": Read, "hist": ReadWrite, "out_fi": Write, "out_fj": Write, "out_ti": Write, "out_tj": Write, "control": Read];
    Gather = "gather", GATHER, ["params": Uniform, "phase": Phase, "vel": ReadWrite, "omega": ReadWrite, "pair_start": Read, "rev_start": Read, "rev_pair": Read, "out_fi": Read, "out_fj": Read, "out_ti": Read, "out_tj": Read, "pos": ReadWrite, "residual": ReadWrite, "material": Read, "coeffs": Read, "walls": Read, "wall_hist": ReadWrite, "wall_partials": Write, "force": Write, "torque": Write, "built_at": Read, "quat": ReadWrite, "control": ReadWrite];
    WallReduce = "wall_reduce", PISTON, ["params": Uniform, "phase": Phase, "wall_partials": Read, "wall_reaction": ReadWrite, "walls": ReadWrite];
    ReduceGrains = "reduce_grains", STATS, ["params": Uniform, "pos": Read, "residual": Read, "vel": Read, "omega": Read, "force": Read, "torque": Read, "image": Read, "material": Read, "coeffs": Read, "walls": Read, "grain_rows": Write];
    ReducePairs = "reduce_pairs", STATS, ["params": Uniform, "pos": Read, "residual": Read, "material": Read, "coeffs": Read, "pair_i": Read, "pair_j": Read, "out_fi": Read, "out_ti": Read, "control": Read, "pair_rows": Write];
    ReduceFinal = "reduce_final", STATS, ["params": Uniform, "grain_rows": Read, "pair_rows": Read, "control": Read, "stats": Write];
}

kernel_table! {
    /// A kernel of contact dynamics' sweeps ([`crate::gpu::GpuSweeps`]), by name: its row in
    /// [`CD_KERNELS`].
    CdKernel,
    /// Contact dynamics' sweep kernels, in the order a sweep runs them.
    CD_KERNELS,
    CdSweepColour = "cd_sweep_colour", CD, ["cd": Uniform, "phase": Phase, "contacts": Read, "impulse": ReadWrite, "vel": ReadWrite, "omega": ReadWrite, "measure": Write, "sweeps": Read];
    CdSweepTail = "cd_sweep_tail", CD, ["cd": Uniform, "contacts": Read, "impulse": ReadWrite, "vel": ReadWrite, "omega": ReadWrite, "wall_vel": ReadWrite, "measure": Write, "sweeps": Read];
    CdMeasure = "cd_measure", CD, ["cd": Uniform, "measure": Read, "blocks": Write, "sweeps": Read];
    CdDecide = "cd_decide", CD, ["cd": Uniform, "blocks": Read, "sweeps": ReadWrite];
}


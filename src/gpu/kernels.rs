//! The kernel table: every compute kernel of a step, its WGSL source, the shared files it
//! includes, and its bindings in binding order. The GPU engine builds its pipelines and bind
//! groups from it; `tests/shaders.rs` checks it against naga's reflection of each shader.
//! The CPU engine's twins carry the same names (`src/cpu/`: `hash_cells`, `detect_pairs`,
//! `remap_history`, `pair_force`, `wall_contacts`, `gather`, `integrate::{kick, drift}`; the
//! GPU's `integrate` runs a kick and the drift after it as one dispatch, and its `gather` the
//! wall contacts, as the CPU's gather sweep does);
//! the GPU-only kernels (scans, scatter, reverse list, reductions) are what a CPU does
//! serially in a loop.

/// Declares the buffers the kernels bind, each named as their WGSL names it.
macro_rules! buffers {
    ($($id:ident = $name:literal,)*) => {
        /// A buffer a kernel binds, named by its WGSL binding (`var ... <name>`) and the
        /// engines' buffer of that name, so that a misspelt buffer does not compile; the
        /// step's and the sweeps' solvers each hold one buffer per name they use (a rebuild's
        /// scratch and a scan's arrays are bound to another's buffer, `gpu/engine.rs`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Buf {
            $(
                #[doc = concat!("`", $name, "`.")]
                $id,
            )*
        }

        impl Buf {
            /// Every buffer name.
            pub const ALL: &[Buf] = &[$(Buf::$id),*];

            /// The name as the WGSL binds it (and as checkpoints store the buffer).
            pub fn name(self) -> &'static str {
                match self { $(Buf::$id => $name),* }
            }

            /// The buffer of that name, if there is one.
            pub fn of_name(name: &str) -> Option<Buf> {
                Buf::ALL.iter().copied().find(|b| b.name() == name)
            }
        }
    };
}

buffers! {
    Params = "params",
    Phase = "phase",
    Pos = "pos",
    Residual = "residual",
    Vel = "vel",
    Omega = "omega",
    Force = "force",
    Torque = "torque",
    BuiltAt = "built_at",
    Quat = "quat",
    Walls = "walls",
    WallReaction = "wall_reaction",
    Control = "control",
    Servo = "servo",
    Args = "args",
    PairStart = "pair_start",
    OldStart = "old_start",
    PairJ = "pair_j",
    Hist = "hist",
    OldJ = "old_j",
    OldHist0 = "old_hist0",
    OldHist1 = "old_hist1",
    OldHist2 = "old_hist2",
    CellCount = "cell_count",
    CellFill = "cell_fill",
    Image = "image",
    CellOf = "cell_of",
    RevStart = "rev_start",
    ScanData = "scan_data",
    BlockSums = "block_sums",
    CellGrains = "cell_grains",
    RevFill = "rev_fill",
    PairI = "pair_i",
    RevPair = "rev_pair",
    BridgeEvent = "bridge_event",
    Liquid = "liquid",
    Material = "material",
    Coeffs = "coeffs",
    OutFi = "out_fi",
    OutFj = "out_fj",
    OutTi = "out_ti",
    OutTj = "out_tj",
    WallHist = "wall_hist",
    Meshes = "meshes",
    MeshData = "mesh_data",
    MeshIndex = "mesh_index",
    WallPartials = "wall_partials",
    GrainRows = "grain_rows",
    PairRows = "pair_rows",
    Stats = "stats",
    Cd = "cd",
    Contacts = "contacts",
    Impulse = "impulse",
    Measure = "measure",
    Sweeps = "sweeps",
    WallVel = "wall_vel",
    Blocks = "blocks",
    HashSums = "hash_sums",
    GrainSums = "grain_sums",
    SpareSum = "spare_sum",
}

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
    pub bindings: &'static [(Buf, Access)],
}

/// A shared WGSL file by name.
pub fn shared(name: &str) -> &'static str {
    match name {
        "types" => include_str!("../../shaders/shared/types.wgsl"),
        "dispatch" => include_str!("../../shaders/shared/dispatch.wgsl"),
        "grid" => include_str!("../../shaders/shared/grid.wgsl"),
        "model" => include_str!("../../shaders/shared/model.wgsl"),
        "model/normal" => include_str!("../../shaders/shared/model/normal.wgsl"),
        "model/damping" => include_str!("../../shaders/shared/model/damping.wgsl"),
        "model/tangential" => include_str!("../../shaders/shared/model/tangential.wgsl"),
        "model/rolling" => include_str!("../../shaders/shared/model/rolling.wgsl"),
        "model/twisting" => include_str!("../../shaders/shared/model/twisting.wgsl"),
        "model/cohesion" => include_str!("../../shaders/shared/model/cohesion.wgsl"),
        "neighbours" => include_str!("../../shaders/shared/neighbours.wgsl"),
        "turn" => include_str!("../../shaders/shared/turn.wgsl"),
        "walls" => include_str!("../../shaders/shared/walls.wgsl"),
        "mesh" => include_str!("../../shaders/shared/mesh.wgsl"),
        "reduce" => include_str!("../../shaders/shared/reduce.wgsl"),
        "kick" => include_str!("../../shaders/shared/kick.wgsl"),
        "piston" => include_str!("../../shaders/shared/piston.wgsl"),
        "drift" => include_str!("../../shaders/shared/drift.wgsl"),
        "position" => include_str!("../../shaders/shared/position.wgsl"),
        "cd" => include_str!("../../shaders/shared/cd.wgsl"),
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
    /// them. The neighbour search gets [`crate::state::OWNER_DOUBLINGS`], the mesh walls
    /// [`crate::mesh::MESH_CONTACTS`] and [`crate::mesh::RAW_CONTACTS`].
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
            if *inc == "mesh" {
                s.push_str(&format!("const MESH_CONTACTS: u32 = {}u;\nconst RAW_CONTACTS: u32 = {}u;\n", crate::mesh::MESH_CONTACTS, crate::mesh::RAW_CONTACTS));
            }
            if *inc == "neighbours" {
                s.push_str(&format!("const OWNER_DOUBLINGS: u32 = {}u;\n", crate::state::OWNER_DOUBLINGS));
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
const PISTON: &[&str] = &["types", "dispatch", "turn", "piston"];
const INTEGRATE: &[&str] = &["types", "dispatch", "kick", "turn", "piston", "position", "drift"];
const GRID: &[&str] = &["types", "dispatch", "position", "grid"];
const DETECT: &[&str] = &["types", "dispatch", "position", "grid", "neighbours"];
const FORCES: &[&str] = &["types", "dispatch", "position", "grid", "model"];
const GATHER: &[&str] = &["types", "dispatch", "position", "grid", "model", "turn", "walls", "mesh", "kick", "drift"];
const CD: &[&str] = &["types", "dispatch", "cd"];
const STATS: &[&str] = &["types", "dispatch", "position", "grid", "model", "turn", "walls", "reduce"];
const GRAIN_STATS: &[&str] = &["types", "dispatch", "position", "grid", "model", "turn", "walls", "mesh", "reduce"];

macro_rules! kernel {
    ($name:literal, $inc:expr, [$($b:ident: $a:expr),* $(,)?]) => {
        Kernel { name: $name, source: include_str!(concat!("../../shaders/", $name, ".wgsl")), includes: $inc, bindings: &[$((Buf::$b, $a)),*] }
    };
}

/// Declares an enum of kernels and their table from one list, so that a kernel is named by a
/// variant (a misspelt one does not compile) and its row stands at the variant's index.
macro_rules! kernel_table {
    ($(#[$enum_doc:meta])* $enum:ident, $(#[$table_doc:meta])* $table:ident, $($id:ident = $name:literal, $inc:expr, [$($b:ident: $a:expr),* $(,)?];)*) => {
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
    Integrate = "integrate", INTEGRATE, [Params: Uniform, Phase: Phase, Pos: ReadWrite, Residual: ReadWrite, Vel: ReadWrite, Omega: ReadWrite, Force: Read, Torque: Read, BuiltAt: Read, Quat: ReadWrite, Walls: ReadWrite, WallReaction: Read, Control: ReadWrite];
    ServoMove = "servo_move", BASE, [Params: Uniform, Phase: Phase, Walls: ReadWrite, WallReaction: Read, Servo: ReadWrite];
    DecideRebuild = "decide_rebuild", BASE, [Params: Uniform, Control: ReadWrite, Args: ReadWrite];
    SaveStarts = "save_starts", BASE, [Params: Uniform, PairStart: Read, OldStart: Write];
    SavePairs = "save_pairs", BASE, [Params: Uniform, PairJ: Read, Hist: Read, OldJ: Write, OldHist0: Write, OldHist1: Write, OldHist2: Write, Control: Read];
    ClearCells = "clear_cells", BASE, [Params: Uniform, CellCount: Write, CellFill: Write];
    HashCells = "hash_cells", GRID, [Params: Uniform, Pos: ReadWrite, Residual: ReadWrite, Image: ReadWrite, BuiltAt: Write, CellOf: Write, CellCount: ReadWrite, Control: ReadWrite, PairStart: Write, RevStart: Write];
    ScanBlocks = "scan_blocks", BASE, [Params: Uniform, ScanData: ReadWrite, BlockSums: Write];
    ScanAdd = "scan_add", BASE, [Params: Uniform, ScanData: ReadWrite, BlockSums: ReadWrite];
    ScatterCells = "scatter_cells", BASE, [Params: Uniform, CellOf: Read, CellCount: Read, CellFill: ReadWrite, CellGrains: Write];
    DetectCount = "detect_count", DETECT, [Params: Uniform, Pos: Read, Residual: Read, CellCount: Read, CellGrains: Read, PairStart: Write, Control: ReadWrite, RevFill: Write];
    PairsReady = "pairs_ready", BASE, [Params: Uniform, PairStart: Read, Control: ReadWrite, Args: Write];
    DetectFill = "detect_fill", DETECT, [Params: Uniform, Pos: Read, Residual: Read, CellCount: Read, CellGrains: Read, PairStart: Read, PairI: Write, PairJ: ReadWrite];
    RemapHistory = "remap_history", BASE, [Params: Uniform, PairI: Read, PairJ: Read, OldStart: Read, OldJ: Read, OldHist0: Read, OldHist1: Read, OldHist2: Read, Hist: Write, Control: Read];
    ReverseCount = "reverse_count", BASE, [Params: Uniform, PairJ: Read, RevStart: ReadWrite, Control: Read];
    ReverseFill = "reverse_fill", BASE, [Params: Uniform, PairJ: Read, RevStart: Read, RevFill: ReadWrite, RevPair: Write, Control: Read];
    ReverseSort = "reverse_sort", BASE, [Params: Uniform, RevStart: Read, RevPair: ReadWrite];
    FindBridgeEvents = "find_bridge_events", FORCES, [Params: Uniform, Pos: Read, Residual: Read, PairI: Read, PairJ: Read, Hist: Read, BridgeEvent: Write, Control: Read];
    UpdateBridges = "update_bridges", FORCES, [Params: Uniform, PairI: Read, PairJ: Read, BridgeEvent: Read, Hist: ReadWrite, Liquid: ReadWrite, Control: Read];
    PairForce = "pair_force", FORCES, [Params: Uniform, Phase: Phase, Pos: Read, Residual: Read, Vel: Read, Omega: Read, Material: Read, Coeffs: Read, PairI: Read, PairJ: Read, Hist: ReadWrite, OutFi: Write, OutFj: Write, OutTi: Write, OutTj: Write, Control: Read];
    Gather = "gather", GATHER, [Params: Uniform, Phase: Phase, Vel: ReadWrite, Omega: ReadWrite, PairStart: Read, RevStart: Read, RevPair: Read, OutFi: Read, OutFj: Read, OutTi: Read, OutTj: Read, Pos: ReadWrite, Residual: ReadWrite, Material: Read, Coeffs: Read, Walls: Read, WallHist: ReadWrite, WallPartials: Write, Force: Write, Torque: Write, BuiltAt: Read, Quat: ReadWrite, Control: ReadWrite, Meshes: Read, MeshData: Read, MeshIndex: Read];
    WallReduce = "wall_reduce", PISTON, [Params: Uniform, Phase: Phase, WallPartials: Read, WallReaction: ReadWrite, Walls: ReadWrite];
    ReduceGrains = "reduce_grains", GRAIN_STATS, [Params: Uniform, Pos: Read, Residual: Read, Vel: Read, Omega: Read, Force: Read, Torque: Read, Image: Read, Material: Read, Coeffs: Read, Walls: Read, GrainRows: Write, Meshes: Read, MeshData: Read, MeshIndex: Read];
    ReducePairs = "reduce_pairs", STATS, [Params: Uniform, Pos: Read, Residual: Read, Material: Read, Coeffs: Read, PairI: Read, PairJ: Read, OutFi: Read, OutTi: Read, Control: Read, PairRows: Write];
    ReduceFinal = "reduce_final", STATS, [Params: Uniform, GrainRows: Read, PairRows: Read, Control: Read, Stats: Write];
}

kernel_table! {
    /// A kernel of contact dynamics' sweeps ([`super::GpuSweeps`]), by name: its row in
    /// [`CD_KERNELS`].
    CdKernel,
    /// Contact dynamics' sweep kernels, in the order a sweep runs them.
    CD_KERNELS,
    CdSweepColour = "cd_sweep_colour", CD, [Cd: Uniform, Phase: Phase, Contacts: Read, Impulse: ReadWrite, Vel: ReadWrite, Omega: ReadWrite, Measure: Write, Sweeps: Read];
    CdSweepTail = "cd_sweep_tail", CD, [Cd: Uniform, Contacts: Read, Impulse: ReadWrite, Vel: ReadWrite, Omega: ReadWrite, WallVel: ReadWrite, Measure: Write, Sweeps: Read];
    CdMeasure = "cd_measure", CD, [Cd: Uniform, Measure: Read, Blocks: Write, Sweeps: Read];
    CdDecide = "cd_decide", CD, [Cd: Uniform, Blocks: Read, Sweeps: ReadWrite];
}


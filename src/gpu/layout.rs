//! Structures that cross to the GPU, `#[repr(C)]` and Pod. Keep in sync with
//! `shaders/shared/types.wgsl`; `tests/shaders.rs` checks sizes and offsets against naga's
//! reflection of the WGSL.

use bytemuck::{Pod, Zeroable};
use glam::{UVec4, Vec4};

/// Scene-wide constants (WGSL `Params`, a uniform).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct Params {
    /// Grains.
    pub n_grains: u32,
    /// Walls (at most [`MAX_WALLS`]).
    pub n_walls: u32,
    /// Materials.
    pub n_materials: u32,
    /// Pairs the pair buffers hold.
    pub pair_capacity: u32,
    /// Hash buckets (a power of two).
    pub hash_size: u32,
    /// Pairs a grain may own.
    pub max_neighbours: u32,
    /// Wall index of the piston, or [`NONE`].
    pub piston: u32,
    /// vec4 history blocks per contact.
    pub hist_blocks: u32,
    /// Gravity (m/s^2).
    pub gravity: Vec4,
    /// Lower bound of each periodic axis (m).
    pub periodic_lo: Vec4,
    /// Period per axis (m), 0 where it does not wrap.
    pub periodic_len: Vec4,
    /// The normal law's constants ([`crate::model::NormalSetup::gpu_block`]).
    pub normal: Vec4,
    /// The damping law's ([`crate::model::DampingLaw::gpu_block`]).
    pub damping: Vec4,
    /// The tangential law's ([`crate::model::TangentialLaw::gpu_block`]).
    pub tangential: Vec4,
    /// The rolling law's ([`crate::model::RollingLaw::gpu_block`]).
    pub rolling: Vec4,
    /// The cohesion law's ([`crate::model::CohesionLaw::gpu_block`]), the largest bridge
    /// volume (m^3) in `w`.
    pub cohesion: Vec4,
    /// Verlet skin (m).
    pub skin: f32,
    /// Distance beyond contact that pair detection reaches (m): the skin, plus the rupture
    /// distance of the largest liquid bridge in capillary scenes.
    pub reach: f32,
    /// Tangential stiffness: [`crate::model::tangential::STIFFNESS_CODES`]: `STIFFNESS_MINDLIN` or `STIFFNESS_RATIO`
    /// (`tangential[0]` times the normal secant stiffness).
    pub kt_law: u32,
    /// Oquendo et al.'s rolling friction: 0 a torque pair, 1 eqs. 8-9 on each grain as written.
    pub rolling_as_written: u32,
    /// The smallest grain's radius (m), for the pairs a grain may own
    /// ([`crate::state::owner_capacity`]).
    pub r_min: f32,
    /// Size classes of the neighbour search, 1 to [`MAX_CLASSES`]
    /// ([`crate::state::class_tops`]).
    pub classes: u32,
    /// vec4 blocks of wall history per grain ([`Wall::hist_at`]).
    pub wall_blocks: u32,
    /// Padding.
    pub _pad2: u32,
    /// Per size class: its grid's cell edge per axis (m) in xyz, its largest radius (m) in w.
    pub class_cell: [Vec4; MAX_CLASSES],
    /// Per size class: its grid's cells per wrapping axis, 0 where the axis does not wrap.
    pub class_dims: [UVec4; MAX_CLASSES],
}

/// What changes between dispatches of one step (WGSL `Phase`, uniform with dynamic offset).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Phase {
    /// Kick duration (s); 0: no kick.
    pub kick: f32,
    /// Drift duration (s); 0: no drift.
    pub drift: f32,
    /// Time since the previous force evaluation (s).
    pub elapsed: f32,
    /// A force evaluation's dispatches that run the next step's kick and drift too (a run of
    /// steps carries each step's first sweep into the step before: [`crate::gpu::plan`]): that
    /// kick's duration (s), the drift's being `drift`; 0 otherwise.
    pub then_kick: f32,
}

/// Coefficients of a pair of materials (WGSL `PairCoeffs`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PairCoeffs {
    /// Pa.
    pub v_eff: f32,
    /// Pa.
    pub g_eff: f32,
    /// -.
    pub mu_s: f32,
    /// -.
    pub mu_k: f32,
    /// -.
    pub tan_roll: f32,
    /// s^-1 m^-1/2.
    pub gamma_n: f32,
    /// s^-1.
    pub gamma_nt: f32,
    /// -.
    pub beta: f32,
}

/// The vec4 history blocks a contact keeps on the GPU, in order: the tangential spring with
/// the sliding flag in w, the rolling spring, the bridge volume in x (last: `find_bridge_events`
/// and `update_bridges` read it there); the normal velocity at the previous evaluation takes
/// a spare component of one of them ([`normal_slot`]), or a block of its own where there is
/// none. At most three, which the rebuild's scratch holds (`remap_history`).
pub fn history_blocks(layout: crate::model::HistoryLayout) -> u32 {
    let own = normal_slot(layout) == normal_slot::OWN;
    [layout.tangential, layout.rolling, layout.bridge, own].into_iter().filter(|&b| b).count() as u32
}

/// Where a contact's normal velocity sits in its GPU history blocks (WGSL `NORMAL_SLOT`).
pub fn normal_slot(layout: crate::model::HistoryLayout) -> u32 {
    if !layout.normal {
        normal_slot::NONE
    } else if layout.tangential && !layout.sliding {
        normal_slot::TANGENTIAL_W
    } else if layout.rolling {
        normal_slot::ROLLING_W
    } else if layout.bridge {
        normal_slot::BRIDGE_Y
    } else {
        normal_slot::OWN
    }
}

/// The places of [`normal_slot`].
pub mod normal_slot {
    /// No normal velocity kept.
    pub const NONE: u32 = 0;
    /// The tangential block's w (free where there is no sliding flag).
    pub const TANGENTIAL_W: u32 = 1;
    /// The rolling block's w.
    pub const ROLLING_W: u32 = 2;
    /// The bridge block's y.
    pub const BRIDGE_Y: u32 = 3;
    /// A block of its own, x.
    pub const OWN: u32 = 4;
}

/// Wall kinds (WGSL `WALL_*`).
pub mod wall_kind {
    /// A plane.
    pub const PLANE: u32 = 0;
    /// A vertical cylinder.
    pub const CYLINDER: u32 = 1;
    /// The oedometer's piston.
    pub const PISTON: u32 = 2;
    /// A triangle mesh ([`super::MeshInfo`]).
    pub const MESH: u32 = 3;
}

/// A wall's flags (WGSL `WALL_*` flags), bits of [`Wall::flags`].
pub mod wall_flags {
    /// A prescribed motion moves it (velocity, the drive's spin).
    pub const DRIVEN: u32 = 1;
    /// A stage has taken it away: it touches no grain.
    pub const ABSENT: u32 = 2;
    /// Its spin turns it (a plane's normal, a mesh's `turn`): set by the first drive that
    /// turns it ([`crate::walls::turns_with`]), and kept.
    pub const TURNS: u32 = 4;
}

/// A wall (WGSL `Wall`), of kind [`wall_kind`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct Wall {
    /// A [`wall_kind`].
    pub kind: u32,
    /// Material index.
    pub material: u32,
    /// Its [`wall_flags`]: DRIVEN where a prescribed motion moves it (`velocity`, `drive`'s
    /// spin), ABSENT while a stage has taken it away.
    pub flags: u32,
    /// Its first vec4 block in a grain's wall history: `hist_blocks` per wall before it, a
    /// mesh's [`crate::mesh::MESH_CONTACTS`] slots of `hist_blocks + 1`.
    pub hist_at: u32,
    /// Plane point; cylinder axis (x, y); piston (0, 0, z); a mesh's shift (m).
    pub point: Vec4,
    /// Plane unit normal; cylinder w = radius; a mesh's index in `meshes` in x's bits and the
    /// point it turns about, where the scene put it, in y, z, w (m).
    pub normal: Vec4,
    /// Velocity (m/s).
    pub velocity: Vec4,
    /// Piston: mass (kg), area (m^2), target pressure (Pa), external work (J); other walls:
    /// angular velocity (rad/s) about the axis through the pivot, work on the grains (J).
    pub drive: Vec4,
    /// A turning mesh's rotation from where the scene put it ([`crate::turn`], scalar first);
    /// the identity for every other wall.
    pub turn: Vec4,
}

/// The servo box's control state (WGSL `Servo`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Servo {
    /// Wall indices of the x_min, x_max, y_min, y_max planes.
    pub walls_lo: UVec4,
    /// Wall indices of the z_min, z_max planes (z, w unused).
    pub walls_hi: UVec4,
    /// Target pressure (Pa).
    pub pressure: f32,
    /// Wall speed per pressure error (m/(s Pa)).
    pub gain: f32,
    /// Largest wall speed (m/s).
    pub max_speed: f32,
    /// Strain rate of the z planes (1/s, closing positive) when `strain` is 1.
    pub strain_rate: f32,
    /// Fraction of the largest stable gain kept where the contacts are stiff.
    pub relaxation: f32,
    /// Work the planes did on the grains (J).
    pub work: f32,
    /// Its rounding error (J).
    pub work_lo: f32,
    /// 1 when the z planes are strain-controlled.
    pub strain: u32,
}

/// Flags and counters (WGSL `Control`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct Control {
    /// Bits of the largest squared displacement since the build.
    pub max_disp2: u32,
    /// 1 while the current step rebuilds.
    pub rebuild: u32,
    /// Rebuilds so far.
    pub rebuilds: u32,
    /// Pairs listed.
    pub n_pairs: u32,
    /// Lowest grain over the neighbour capacity, or [`NONE`].
    pub overflow_grain: u32,
    /// Its pair count.
    pub overflow_count: u32,
    /// 1 when a rebuild found more pairs than the buffers hold and stopped the run there.
    pub pair_overflow: u32,
    /// Lowest grain with a non-finite position, or [`NONE`].
    pub non_finite: u32,
    /// `decide_rebuild` runs so far (wrapping).
    pub rebuild_checks: u32,
    /// Lowest grain touching a mesh at more places than it keeps, or [`NONE`].
    pub mesh_overflow: u32,
}

/// A mesh wall's triangles as the kernels read them (WGSL `MeshInfo`): its grid
/// ([`crate::mesh::grid::TriangleGrid`]) and where its parts begin in `mesh_data` (corners,
/// vec4) and `mesh_index` (per triangle 3 corners and 3 edges, then the cells' starts, then the
/// triangle ids).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct MeshInfo {
    /// The grid's lower corner (m); w: the inverse of its cell side (1/m).
    pub origin: Vec4,
    /// Cells along x, y, z; w: where the cells' starts begin in `mesh_index`.
    pub dims: UVec4,
    /// Its first corner in `mesh_data`, its first triangle in `mesh_index`, where its ids
    /// begin in `mesh_index`; w: the merge cosine's bits.
    pub bases: UVec4,
}

/// Indirect dispatch arguments (WGSL `DispatchArgs`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct DispatchArgs {
    /// Workgroups along x.
    pub x: u32,
    /// Along y.
    pub y: u32,
    /// Along z.
    pub z: u32,
}

impl DispatchArgs {
    /// One workgroup.
    pub const ONE: Self = DispatchArgs { x: 1, y: 1, z: 1 };

    /// The workgroups for `n` items (WGSL `groups_for`).
    pub fn items(n: u64) -> Self {
        let (x, y) = crate::workgroup::groups(n);
        DispatchArgs { x, y, z: 1 }
    }

    /// The scan's workgroups over `n` elements (WGSL `blocks` in `decide_rebuild`).
    pub fn scan_blocks(n: u64) -> Self {
        DispatchArgs { x: n.div_ceil(SCAN_BLOCK) as u32, y: 1, z: 1 }
    }
}

/// "No grain" / "no wall" (WGSL `NONE`).
pub const NONE: u32 = u32::MAX;
pub use crate::workgroup::WG;
pub use crate::state::MAX_CLASSES;

/// Walls a GPU scene may have (WGSL `MAX_WALLS`).
pub const MAX_WALLS: usize = 8;
/// Reals per statistics row (WGSL `STAT_ROW`).
pub const STAT_ROW: usize = 20;
/// Fields of the statistics rows (WGSL `G_*`, `P_*`): sums of f32, except the counts, whose
/// u32 bits sit in their f32 slots and are summed as integers (WGSL `G_COUNTS`, `P_COUNTS`).
pub mod stat {
    /// A grain row.
    pub mod grain {
        /// Translational kinetic energy (J).
        pub const KE_T: usize = 0;
        /// Rotational kinetic energy (J).
        pub const KE_R: usize = 1;
        /// Gravitational energy (J).
        pub const PE_G: usize = 2;
        /// Momentum, 3 fields (kg m/s).
        pub const MOMENTUM: usize = 3;
        /// Angular momentum, 3 fields (kg m^2/s).
        pub const ANGULAR: usize = 6;
        /// |net force| (N).
        pub const NET_FORCE: usize = 9;
        /// |wall force| (N).
        pub const WALL_FORCE: usize = 10;
        /// Wall contacts (count).
        pub const WALL_CONTACTS: usize = 11;
        /// Elastic energy of the wall contacts (J).
        pub const WALL_ELASTIC: usize = 12;
        /// Wall contacts sliding (count).
        pub const WALL_SLIDING: usize = 13;
        /// Wall contacts rolling (count).
        pub const WALL_ROLLING: usize = 14;
        /// Rattlers (count).
        pub const RATTLERS: usize = 15;
        /// Kinetic energy of the rattlers (J).
        pub const KE_RATTLERS: usize = 16;
        /// |net force| of the loaded grains (N).
        pub const NET_LOADED: usize = 17;
    }
    /// A pair row.
    pub mod pair {
        /// Touching pairs (count).
        pub const CONTACTS: usize = 0;
        /// Clamped contacts (count).
        pub const CLAMPED: usize = 1;
        /// Elastic energy (J).
        pub const ELASTIC: usize = 2;
        /// 2 |contact force| (N).
        pub const FORCE: usize = 3;
        /// Sliding contacts (count).
        pub const SLIDING: usize = 4;
        /// Rolling contacts (count).
        pub const ROLLING: usize = 5;
    }
}

/// Elements one workgroup of the scan handles (WGSL `SCAN_BLOCK`).
pub const SCAN_BLOCK: u64 = 2048;
/// Largest element count the two-level scan handles: a block of block totals.
pub const MAX_SCAN: u64 = SCAN_BLOCK * SCAN_BLOCK;
/// Indirect-argument slots (WGSL `ARGS_*`).
pub mod args {
    /// One invocation per grain, if rebuilding.
    pub const GRAINS: u64 = 0;
    /// One per hash bucket, if rebuilding.
    pub const HASH: u64 = 1;
    /// Scan blocks over the buckets, if rebuilding.
    pub const HASH_BLOCKS: u64 = 2;
    /// Scan blocks over n_grains + 1, if rebuilding.
    pub const GRAIN_BLOCKS: u64 = 3;
    /// One workgroup, if rebuilding.
    pub const ONE: u64 = 4;
    /// One per pair being replaced, if rebuilding.
    pub const OLD_PAIRS: u64 = 5;
    /// One per current pair, always.
    pub const PAIRS: u64 = 6;
    /// One per new pair, if rebuilding.
    pub const NEW_PAIRS: u64 = 7;
    /// One per entry of n_grains + 1, if rebuilding.
    pub const GRAIN_STARTS: u64 = 8;
    /// One per grain, until a pair buffer overflow stops the steps.
    pub const STEP_GRAINS: u64 = 9;
    /// One workgroup, until a pair buffer overflow stops the steps.
    pub const STEP_ONE: u64 = 10;
    /// Slots.
    pub const SLOTS: u64 = 11;
}

/// A contact of contact dynamics' sweeps (WGSL `CdContact`, `shaders/shared/cd.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CdContact {
    /// First body: a grain.
    pub a: u32,
    /// Second body: a grain, or a wall's index when `to_wall` is 1.
    pub b: u32,
    /// 1 when `b` is a wall.
    pub to_wall: u32,
    /// Padding.
    pub _pad0: u32,
    /// Unit normal from `a` to `b` (xyz); w: `u_min` (m/s).
    pub n: Vec4,
    /// m.
    pub radius_a: f32,
    /// m (0 for a wall).
    pub radius_b: f32,
    /// Friction coefficient.
    pub mu: f32,
    /// Normal Delassus diagonal (1/kg).
    pub w_n: f32,
    /// Tangential Delassus diagonal (1/kg).
    pub w_t: f32,
    /// 1/kg.
    pub inv_mass_a: f32,
    /// 1/(kg m^2).
    pub inv_inertia_a: f32,
    /// 1/kg.
    pub inv_mass_b: f32,
    /// 1/(kg m^2).
    pub inv_inertia_b: f32,
    /// `1 / w_n` (kg).
    pub inv_w_n: f32,
    /// `1 / w_t` (kg).
    pub inv_w_t: f32,
    /// Padding.
    pub _pad1: f32,
}

/// The sweeps' constants (WGSL `CdParams`, a uniform).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CdParams {
    /// Contacts.
    pub n_contacts: u32,
    /// First contact of the serial tail.
    pub tail: u32,
    /// Blocks of the convergence measure.
    pub n_blocks: u32,
    /// Sweeps at most.
    pub max_iterations: u32,
    /// Square of the quadratic norm at which the sweeps stop (-).
    pub tolerance2: f32,
    /// Over-relaxation factor (-; 1: plain Gauss-Seidel).
    pub relaxation: f32,
    /// Padding.
    pub _pad1: f32,
    /// Padding.
    pub _pad2: f32,
}

/// A colour's contacts `start..end` (WGSL `CdColour`, a uniform at a dynamic offset).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CdColour {
    /// First contact.
    pub start: u32,
    /// One past the last.
    pub end: u32,
    /// Padding.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
}

/// Where the sweeps stand (WGSL `CdControl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CdControl {
    /// Sweeps run.
    pub iterations: u32,
    /// 1: the sweeps' quadratic norm fell to the tolerance.
    pub converged: u32,
    /// 1: converged or at the cap.
    pub done: u32,
    /// Padding.
    pub _pad0: u32,
    /// Square of the last sweep's quadratic norm (-).
    pub sweep_norm2: f32,
    /// Padding.
    pub _pad1: f32,
    /// Padding.
    pub _pad2: f32,
    /// Padding.
    pub _pad3: f32,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::HistoryLayout;

    /// Every layout a model can ask for (the sliding flag only with both springs: Oquendo et al.'s
    /// law) fits the rebuild's three scratch buffers of history blocks (`remap_history`), and
    /// its normal velocity has a place.
    #[test]
    fn every_history_fits_three_blocks() {
        for bits in 0..32u32 {
            let [tangential, sliding, rolling, bridge, normal] = std::array::from_fn(|k| bits >> k & 1 == 1);
            if sliding && !(tangential && rolling) {
                continue;
            }
            let layout = HistoryLayout { tangential, normal, sliding, rolling, bridge };
            assert!(history_blocks(layout) <= 3, "{layout:?}");
            assert_eq!(normal_slot(layout) == normal_slot::NONE, !normal, "{layout:?}");
        }
    }
}

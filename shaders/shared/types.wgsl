// Structures shared by the kernels. Keep in sync with src/gpu/layout.rs (a test compares
// sizes and offsets through naga's reflection).

// Scene-wide constants of one engine (uniform).
struct Params {
    n_grains: u32,
    n_walls: u32,
    n_materials: u32,
    pair_capacity: u32,
    hash_size: u32,
    max_neighbours: u32,
    piston: u32,          // wall index of the piston, or 0xffffffff
    hist_blocks: u32,     // vec4 history blocks per contact (tangential with the sliding flag in w, rolling, bridge volume in x)
    gravity: vec4<f32>,   // m/s^2 (xyz)
    periodic_lo: vec4<f32>,
    periodic_len: vec4<f32>, // period per axis (m); 0 where the axis does not wrap
    // One block per slot of the contact model, its laws' constants (src/model/):
    normal: vec4<f32>,     // the normal law's (src/model/normal/<law>.rs gpu_block): x k_n (N/m, linear) or gamma (J/m^2, dmt)
    damping: vec4<f32>,    // x: viscous c_n (N s/m)
    tangential: vec4<f32>, // x: k_t / (F_el / h) when kt_law is STIFFNESS_RATIO; y: eta_t / eta_n (Hertz-Mindlin dashpot); z: Oquendo et al.'s spring damping, fraction of critical
    rolling: vec4<f32>,    // sds: x k_r (N/m), y gamma_r (N s/m), z mu_r (-)
    cohesion: vec4<f32>,   // capillary: x kappa = 2 pi gamma cos(theta) (N/m), y theta (rad), z decay-length c (-), w largest bridge volume (m^3)
    skin: f32,            // m
    reach: f32,           // distance beyond contact that pair detection reaches (m)
    kt_law: u32,          // STIFFNESS_MINDLIN or STIFFNESS_RATIO (tangential.x x the normal secant stiffness)
    rolling_as_written: u32, // Oquendo et al.'s rolling friction: 0 torque pair, 1 eqs. 8-9 on each grain
    r_min: f32,           // the smallest grain's radius (m), for owner_capacity
    classes: u32,         // size classes of the neighbour search, 1 to MAX_CLASSES (src/state/levels.rs class_tops)
    wall_blocks: u32,     // vec4 blocks of wall history per grain: hist_blocks per wall, a mesh's slots (Wall.hist_at)
    _pad2: u32,
    class_cell: array<vec4<f32>, MAX_CLASSES>, // per size class: its grid's cell edge per axis (m) in xyz, its largest radius (m) in w
    class_dims: array<vec4<u32>, MAX_CLASSES>, // per size class: its grid's cells per wrapping axis; 0 where the axis does not wrap
}

// What changes between the dispatches of one step (uniform, dynamic offset).
struct Phase {
    kick: f32,     // kick duration (s); 0: no kick
    drift: f32,    // drift duration (s); 0: no drift
    elapsed: f32,  // time since the previous force evaluation (s), for the springs
    then_kick: f32, // an evaluation carrying the next step's kick (s) and drift (`drift`); 0 otherwise
}

// Coefficients of a pair of materials, [material_i * n_materials + material_j].
struct PairCoeffs {
    v_eff: f32,
    g_eff: f32,
    mu_s: f32,
    mu_k: f32,
    tan_roll: f32,
    gamma_n: f32,
    gamma_nt: f32,
    beta: f32,
}

// Whether a grain whose pos is p is in play: one out of play (waiting at an inlet, or gone
// through an outlet) keeps its slot with its radius stored negated (src/state/arrays.rs
// Props::in_play). It is in no cell and no pair, touches no wall, feels no gravity, does not
// move and counts in no statistic.
fn in_play(p: vec4<f32>) -> bool {
    return p.w > 0.0;
}

// Wall kinds (src/gpu/layout.rs wall_kind).
const WALL_PLANE: u32 = 0u;
const WALL_CYLINDER: u32 = 1u;
const WALL_PISTON: u32 = 2u;
const WALL_MESH: u32 = 3u;

// Wall flags (src/gpu/layout.rs wall_flags), bits of Wall.flags.
const WALL_DRIVEN: u32 = 1u;
const WALL_ABSENT: u32 = 2u;
const WALL_TURNS: u32 = 4u;

// Where a contact's normal velocity sits in its history blocks (src/gpu/layout.rs normal_slot).
const NORMAL_SLOT_NONE: u32 = 0u;
const NORMAL_SLOT_TANGENTIAL_W: u32 = 1u;
const NORMAL_SLOT_ROLLING_W: u32 = 2u;
const NORMAL_SLOT_BRIDGE_Y: u32 = 3u;
const NORMAL_SLOT_OWN: u32 = 4u;

// Sum of two per-wall rows: xyz as f32; w a u32 count (its bits; 0 in the stiffness rows).
fn add_wall_row(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(a.xyz + b.xyz, bitcast<f32>(bitcast<u32>(a.w) + bitcast<u32>(b.w)));
}

// A wall of kind WALL_*.
struct Wall {
    kind: u32,
    material: u32,
    flags: u32,          // WALL_DRIVEN: a prescribed motion moves it (velocity, drive.xyz); WALL_ABSENT: a stage took it away;
                         // WALL_TURNS: its spin turns it (a plane's normal, a mesh's turn)
    hist_at: u32,        // its first block in a grain's wall history (wall_hist[i * params.wall_blocks + hist_at])
    point: vec4<f32>,    // plane: a point; cylinder: axis (x, y); piston: (0, 0, z); mesh: its shift from the scene's place
    normal: vec4<f32>,   // plane: unit normal into the domain; cylinder: w = radius; mesh: x = bits of its index in
                         // `meshes`, yzw = the point it turns about, where the scene put it (m)
    velocity: vec4<f32>, // m/s
    drive: vec4<f32>,    // piston: mass (kg), area (m^2), target pressure (Pa), external work (J);
                         // other walls: angular velocity (rad/s) about the axis through the
                         // pivot, work on the grains (J)
    turn: vec4<f32>,     // a turning mesh's rotation from the scene's place (turn.wgsl); the identity otherwise
}

// The servo box's control state.
struct Servo {
    walls_lo: vec4<u32>, // wall indices of the x_min, x_max, y_min, y_max planes
    walls_hi: vec4<u32>, // z_min, z_max (z, w unused)
    pressure: f32,       // target pressure (Pa)
    gain: f32,           // wall speed per pressure error (m/(s Pa))
    max_speed: f32,      // m/s
    strain_rate: f32,    // z planes' strain rate (1/s, closing positive) when strain != 0
    relaxation: f32,     // fraction of the largest stable gain kept where contacts are stiff
    work: f32,           // work the planes did on the grains (J), and its rounding error
    work_lo: f32,
    strain: u32,         // 1: the z planes are strain-controlled
}

// Flags and counters the host reads back with the statistics.
struct Control {
    max_disp2: atomic<u32>,    // bits of the largest squared displacement since the build (f32 >= 0)
    rebuild: u32,              // 1 while this step rebuilds
    rebuilds: u32,
    n_pairs: u32,
    overflow_grain: atomic<u32>, // lowest grain over the neighbour capacity, or 0xffffffff
    overflow_count: atomic<u32>, // its pair count
    pair_overflow: u32,        // 1 when a rebuild found more pairs than the buffers hold: it
                               // stopped before writing its list, and every step after it runs
                               // no kernel until the host grows the buffers and goes on
    non_finite: atomic<u32>,   // lowest grain with a non-finite position, or 0xffffffff
    rebuild_checks: u32,       // decide_rebuild runs so far (the host finds the one that stopped)
    mesh_overflow: atomic<u32>, // lowest grain touching a mesh at more places than it keeps, or 0xffffffff
}

// A mesh wall's triangles (src/mesh/grid.rs): the grid over its box in its own frame, and
// where its corners (mesh_data), triangles (mesh_index: 3 corners, then 3 edges), cells' starts
// and triangle ids (mesh_index) begin.
struct MeshInfo {
    origin: vec4<f32>,   // the grid's lower corner (m); w: the inverse of the cell side (1/m)
    dims: vec4<u32>,     // cells along x, y, z; w: where its cells' starts begin in mesh_index
    bases: vec4<u32>,    // its first corner in mesh_data, its first triangle's in mesh_index (6 u32 each), where its ids begin; w: bits of the merge cosine
}

// Workgroup-size indirect dispatch arguments.
struct DispatchArgs {
    x: u32,
    y: u32,
    z: u32,
}

const NONE: u32 = 0xffffffffu;
const WG: u32 = 64u;

// Slots of the indirect dispatch buffer. "if rebuilding" slots are zero on other steps.
const ARGS_GRAINS: u32 = 0u;        // one invocation per grain, if rebuilding
const ARGS_HASH: u32 = 1u;          // one per hash bucket, if rebuilding
const ARGS_HASH_BLOCKS: u32 = 2u;   // scan blocks over the buckets, if rebuilding
const ARGS_GRAIN_BLOCKS: u32 = 3u;  // scan blocks over n_grains + 1, if rebuilding
const ARGS_ONE: u32 = 4u;           // one workgroup, if rebuilding
const ARGS_OLD_PAIRS: u32 = 5u;     // one per pair of the list being replaced, if rebuilding
const ARGS_PAIRS: u32 = 6u;         // one per current pair, always
const ARGS_NEW_PAIRS: u32 = 7u;     // one per new pair, if rebuilding
const ARGS_GRAIN_STARTS: u32 = 8u;  // one per entry of n_grains + 1, if rebuilding
const ARGS_STEP_GRAINS: u32 = 9u;   // one per grain, until a pair buffer overflow stops the steps
const ARGS_STEP_ONE: u32 = 10u;     // one workgroup, until a pair buffer overflow stops the steps
const ARGS_SLOTS: u32 = 11u;

const MAX_WALLS: u32 = 8u;
// Size classes of the neighbour search (src/state/levels.rs MAX_CLASSES).
const MAX_CLASSES: u32 = 8u;
// Elements one workgroup of the scan handles (src/gpu/layout.rs SCAN_BLOCK).
const SCAN_BLOCK: u32 = 2048u;
// Grains with fewer contacts are rattlers (src/engine.rs RATTLER_CONTACTS).
const RATTLER_CONTACTS: u32 = 2u;
// Per-workgroup rows of the statistics reduction: sums, then (largest overlap, its grain).
const STAT_ROW: u32 = 20u;
const STAT_MAX: u32 = 18u;
const STAT_ARG: u32 = 19u;
// Fields of a grain row (src/gpu/layout.rs `stat::grain`).
const G_KE_T: u32 = 0u;            // translational kinetic energy (J)
const G_KE_R: u32 = 1u;            // rotational kinetic energy (J)
const G_PE_G: u32 = 2u;            // gravitational energy (J)
const G_MOMENTUM: u32 = 3u;        // 3 fields (kg m/s)
const G_ANGULAR: u32 = 6u;         // 3 fields (kg m^2/s)
const G_NET_FORCE: u32 = 9u;       // |net force| (N)
const G_WALL_FORCE: u32 = 10u;     // |wall force| (N)
const G_WALL_CONTACTS: u32 = 11u;  // count
const G_WALL_ELASTIC: u32 = 12u;   // J
const G_WALL_SLIDING: u32 = 13u;   // count
const G_WALL_ROLLING: u32 = 14u;   // count
const G_RATTLERS: u32 = 15u;       // count
const G_KE_RATTLERS: u32 = 16u;    // J
const G_NET_LOADED: u32 = 17u;     // |net force| of loaded grains (N)
// Fields of a pair row (src/gpu/layout.rs `stat::pair`).
const P_CONTACTS: u32 = 0u;        // count
const P_CLAMPED: u32 = 1u;         // count
const P_ELASTIC: u32 = 2u;         // J
const P_FORCE: u32 = 3u;           // 2 |contact force| (N)
const P_SLIDING: u32 = 4u;         // count
const P_ROLLING: u32 = 5u;         // count
// The fields of each row that hold u32 counts (bit f: field f), summed as integers so that
// they stay exact past 2^24.
const G_COUNTS: u32 = (1u << G_WALL_CONTACTS) | (1u << G_WALL_SLIDING) | (1u << G_WALL_ROLLING) | (1u << G_RATTLERS);
const P_COUNTS: u32 = (1u << P_CONTACTS) | (1u << P_CLAMPED) | (1u << P_SLIDING) | (1u << P_ROLLING);

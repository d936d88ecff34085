// Contact sub-models composed as src/model/contact.rs composes them, each slot's laws in
// shaders/shared/model/<slot>.wgsl (the WGSL twins of src/model/<slot>/). Conventions: n
// points from j to i; h > 0 in contact; forces and torques are "on i" unless named _j.

// The laws' codes (NORMAL_HERTZ, DAMPING_NONE, ...) are written before this file from each
// slot's registry (src/model/<slot>/mod.rs SLOT; src/model/mod.rs wgsl_codes).

// Laws chosen per scene (pipeline-overridable constants, so unused branches fold away).
override NORMAL_LAW: u32 = NORMAL_HERTZ;
override DAMPING_LAW: u32 = DAMPING_NONE;
override TANGENTIAL_LAW: u32 = TANGENTIAL_NONE;
override ROLLING_LAW: u32 = ROLLING_NONE;
override TWISTING_LAW: u32 = TWISTING_NONE;
override COHESION_LAW: u32 = COHESION_NONE;    // capillary: a bridge volume per pair
override HAS_TANGENTIAL_HISTORY: bool = false;
override HAS_ROLLING_HISTORY: bool = false;
// The no-pull clamp (src/model/mod.rs ContactModel::limit_damping).
override LIMIT_DAMPING: bool = true;
// Where damped laws keep the normal velocity of the previous evaluation (src/model/mod.rs
// HistoryLayout::normal) in a contact's history blocks: NORMAL_SLOT_*.
override NORMAL_SLOT: u32 = NORMAL_SLOT_NONE;
// Each evaluation's forces stand for the kicks half a step either side of it (velocity
// Verlet; src/schedule.rs Schedule::centred_kicks): the window the normal force is a mean over.
override CENTRED_KICKS: bool = false;

struct Geometry {
    n: vec3<f32>,
    h: f32,
    r_eff: f32,
    m_eff: f32,
    rp_i: f32,
    rp_j: f32,
    rp_eff: f32,
}

struct Kinematics {
    v_i: vec3<f32>,
    v_j: vec3<f32>,
    w_i: vec3<f32>,
    w_j: vec3<f32>,
}

struct Bodies {
    m_i: f32,
    inertia_i: f32,
    m_j: f32,
    inertia_j: f32,
    j_is_wall: bool,
}

struct ContactForce {
    f_i: vec3<f32>,
    f_j: vec3<f32>,
    t_i: vec3<f32>,
    t_j: vec3<f32>,
    f_n: f32,
    clamped: bool,
    regime: u32,
}

// Tangential regimes, the codes of src/model/mod.rs `Regime`.
const REGIME_STATIC: u32 = 0u;
const REGIME_SLIDING: u32 = 1u;
const REGIME_ROLLING: u32 = 2u;
// Added to the regime in a pair's record (out_ti.w) when its normal force was clamped at zero.
const CLAMPED_FLAG: u32 = 4u;

struct History {
    tangential: vec3<f32>,
    v_n: f32,             // driven normal velocity at the previous evaluation (m/s)
    sliding: bool,
    rolling: vec3<f32>,
    bridge: f32,          // liquid bridge volume (m^3)
}

// A history with no springs and no bridge.
fn empty_history() -> History {
    var h: History;
    h.tangential = vec3<f32>(0.0);
    h.v_n = 0.0;
    h.sliding = false;
    h.rolling = vec3<f32>(0.0);
    h.bridge = 0.0;
    return h;
}

// History blocks a contact keeps at most (src/gpu/layout.rs history_blocks).
const MAX_HISTORY_BLOCKS: u32 = 3u;

// A contact's history from its params.hist_blocks blocks: the tangential spring with the
// sliding flag in w, the rolling spring, the bridge volume in x, and the normal velocity where
// NORMAL_SLOT puts it (src/gpu/layout.rs history_blocks).
fn history_of_blocks(blocks: array<vec4<f32>, MAX_HISTORY_BLOCKS>) -> History {
    var at = blocks;
    var h = empty_history();
    var b = 0u;
    if (HAS_TANGENTIAL_HISTORY) {
        h.tangential = at[b].xyz;
        if (NORMAL_SLOT == NORMAL_SLOT_TANGENTIAL_W) { h.v_n = at[b].w; } else { h.sliding = at[b].w != 0.0; }
        b += 1u;
    }
    if (HAS_ROLLING_HISTORY) {
        h.rolling = at[b].xyz;
        if (NORMAL_SLOT == NORMAL_SLOT_ROLLING_W) { h.v_n = at[b].w; }
        b += 1u;
    }
    if (COHESION_LAW == COHESION_CAPILLARY) {
        h.bridge = at[b].x;
        if (NORMAL_SLOT == NORMAL_SLOT_BRIDGE_Y) { h.v_n = at[b].y; }
        b += 1u;
    }
    if (NORMAL_SLOT == NORMAL_SLOT_OWN) { h.v_n = at[b].x; }
    return h;
}

// history_of_blocks undone.
fn blocks_of_history(h: History) -> array<vec4<f32>, MAX_HISTORY_BLOCKS> {
    var out: array<vec4<f32>, MAX_HISTORY_BLOCKS>;
    var b = 0u;
    if (HAS_TANGENTIAL_HISTORY) {
        var w = select(0.0, 1.0, h.sliding);
        if (NORMAL_SLOT == NORMAL_SLOT_TANGENTIAL_W) { w = h.v_n; }
        out[b] = vec4<f32>(h.tangential, w);
        b += 1u;
    }
    if (HAS_ROLLING_HISTORY) {
        var w = 0.0;
        if (NORMAL_SLOT == NORMAL_SLOT_ROLLING_W) { w = h.v_n; }
        out[b] = vec4<f32>(h.rolling, w);
        b += 1u;
    }
    if (COHESION_LAW == COHESION_CAPILLARY) {
        var y = 0.0;
        if (NORMAL_SLOT == NORMAL_SLOT_BRIDGE_Y) { y = h.v_n; }
        out[b] = vec4<f32>(h.bridge, y, 0.0, 0.0);
        b += 1u;
    }
    if (NORMAL_SLOT == NORMAL_SLOT_OWN) { out[b] = vec4<f32>(h.v_n, 0.0, 0.0, 0.0); }
    return out;
}

fn geometry_grain_grain(d: vec3<f32>, dist: f32, r_i: f32, r_j: f32, m_i: f32, m_j: f32) -> Geometry {
    var g: Geometry;
    g.h = r_i + r_j - dist;
    g.n = d * (1.0 / dist);
    let inv_sum = 1.0 / (r_i + r_j);
    g.rp_i = r_i - g.h * r_j * inv_sum;
    g.rp_j = r_j - g.h * r_i * inv_sum;
    g.r_eff = r_i * r_j * inv_sum;
    g.m_eff = m_i * m_j / (m_i + m_j);
    g.rp_eff = g.rp_i * g.rp_j / (g.rp_i + g.rp_j);
    return g;
}

fn geometry_grain_wall(n: vec3<f32>, dist: f32, r_i: f32, m_i: f32) -> Geometry {
    var g: Geometry;
    g.n = n;
    g.h = r_i - dist;
    g.r_eff = r_i;
    g.m_eff = m_i;
    g.rp_i = r_i - g.h;
    g.rp_j = 0.0;
    g.rp_eff = g.rp_i;
    return g;
}

// The window (s) of kicks an evaluation `elapsed` (s) after the previous one stands for.
fn kick_window(elapsed: f32) -> f32 {
    return select(0.0, elapsed, CENTRED_KICKS);
}

// Exponents (p, q) of the overlap in F_el ~ h^p and eta ~ h^q (src/model/window.rs): the
// restitution dashpot goes as the root of the tangent stiffness, q = (p - 1) / 2.
fn overlap_exponents() -> vec2<f32> {
    let p = normal_exponent();
    var q = 0.0;
    if (DAMPING_LAW == DAMPING_PAPERS) { q = 0.5; }
    if (DAMPING_LAW == DAMPING_RESTITUTION) { q = (p - 1.0) * 0.5; }
    return vec2<f32>(p, q);
}

// The mean over a window of `window` (s) of the normal force of a contact lasting `span` (s)
// of it, its overlap falling linearly to zero from h_far (m), dashpot velocity u (m/s).
fn mean_over(c: PairCoeffs, g: Geometry, h_far: f32, span: f32, u: f32, window: f32) -> f32 {
    var far = g;
    far.h = h_far;
    let f_el = normal_elastic(c, far).x;
    let eta = normal_damping(c, far);
    let pq = overlap_exponents();
    return span / window * (f_el / (pq.x + 1.0) - eta * u / (pq.y + 1.0));
}

// The normal force (N) of a touching contact over the window centred on this evaluation,
// before the clamp (src/model/window.rs windowed_normal_force): dv is the change of the
// driven normal velocity since the previous evaluation.
fn windowed_normal_force(c: PairCoeffs, g: Geometry, f_el: f32, eta: f32, v_n: f32, dv: f32, window: f32) -> f32 {
    if (DAMPING_LAW == DAMPING_NONE || window == 0.0) {
        return f_el - eta * v_n;
    }
    let half = 0.5 * window;
    let approach = -v_n;
    if (approach * window > g.h) {
        let span = g.h / approach + half;
        return mean_over(c, g, approach * span, span, v_n, window);
    }
    let u = v_n + 0.5 * dv;
    let w = v_n + dv;
    if (w * half > g.h) {
        let span = g.h / w + half;
        return mean_over(c, g, w * span, span, u, window);
    }
    return f_el - eta * u;
}

// The normal velocity the contact forces drive (src/model/window.rs driven_normal_velocity).
fn driven_normal_velocity(k: Kinematics, n: vec3<f32>, j_is_wall: bool) -> f32 {
    if (j_is_wall) {
        return dot(k.v_i, n);
    }
    return dot(k.v_i - k.v_j, n);
}

// Whether a contact that has parted can still pull within the window (src/cpu/pair_force.rs
// ForceContext::ends_pull).
fn ends_pull(window: f32) -> bool {
    return !LIMIT_DAMPING && DAMPING_LAW != DAMPING_NONE && window > 0.0;
}

// The normal force (N) of a contact without the clamp on the evaluation after it parted, g.h
// <= 0 (src/model/window.rs parted_normal_force).
fn parted_normal_force(c: PairCoeffs, g: Geometry, v_n: f32, window: f32) -> f32 {
    let half = 0.5 * window;
    if (!ends_pull(window) || !(v_n * half > -g.h)) {
        return 0.0;
    }
    let span = g.h / v_n + half;
    return mean_over(c, g, v_n * span, span, v_n, window);
}

fn contact_force(c: PairCoeffs, g: Geometry, k: Kinematics, b: Bodies, hist: ptr<function, History>, elapsed_step: f32) -> ContactForce {
    var out: ContactForce;
    let v_n = dot(k.v_i - k.v_j, g.n);
    let el = normal_elastic(c, g);
    let eta_n = normal_damping(c, g);
    let driven = driven_normal_velocity(k, g.n, b.j_is_wall);
    let f_total = windowed_normal_force(c, g, el.x, eta_n, v_n, driven - (*hist).v_n, kick_window(elapsed_step));
    (*hist).v_n = driven;
    out.clamped = LIMIT_DAMPING && f_total < 0.0;
    var f_signed = f_total;
    if (out.clamped) {
        f_signed = 0.0;
    }
    // The friction limits take the normal force's magnitude (unclamped, the dashpot can pull);
    // under an adhesive law, LAMMPS' |F_el - F_po + 2 F_po| (the dashpot left out).
    var f_n = abs(f_signed);
    if (normal_adhesive()) {
        let pull = normal_pull_off(g);
        f_signed -= pull;
        f_n = abs(el.x + pull);
    }
    out.f_n = f_signed;
    out.f_i = g.n * f_signed;
    out.f_j = -out.f_i;
    let elapsed = since_touch(*hist, g.h, v_n, elapsed_step);
    out.t_i = vec3<f32>(0.0);
    out.t_j = vec3<f32>(0.0);

    out.regime = REGIME_STATIC;
    if (TANGENTIAL_LAW == TANGENTIAL_OQUENDO) {
        let t = oquendo_tangential(c, g, k, b, f_n, tangential_stiffness(c, g, el.y), hist, elapsed);
        out.f_i += t.f_i;
        out.f_j += t.f_j;
        out.t_i += t.t_i;
        out.t_j += t.t_j;
        out.regime = t.regime;
    }
    if (TANGENTIAL_LAW == TANGENTIAL_MINDLIN) {
        let t = mindlin_tangential(c, g, k, f_n, tangential_stiffness(c, g, el.y), eta_n * params.tangential.y, hist, elapsed);
        out.f_i += t.f_i;
        out.f_j += t.f_j;
        out.t_i += t.t_i;
        out.t_j += t.t_j;
        out.regime = t.regime;
    }
    if (ROLLING_LAW == ROLLING_SDS) {
        let tau = rolling_sds(g, k, f_n, hist, elapsed);
        out.t_i += tau;
        out.t_j -= tau;
    }
    if (TWISTING_LAW == TWISTING_OQUENDO) {
        let tau = twisting_torque(c, g, k);
        out.t_i += tau;
        out.t_j -= tau;
    }
    return out;
}

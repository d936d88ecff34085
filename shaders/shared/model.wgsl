// Contact sub-models, the WGSL twins of src/model/*.rs. Conventions: n points from j to i;
// h > 0 in contact; forces and torques are "on i" unless named _j.

// The laws' codes (src/model/laws.rs `code`, checked by tests/shaders.rs; the normal slot's
// are written from its registry, src/model/normal/mod.rs).
const DAMPING_NONE: u32 = 0u;
const DAMPING_PAPERS: u32 = 1u;
const DAMPING_RESTITUTION: u32 = 2u;
const DAMPING_VISCOUS: u32 = 3u;
const TANGENTIAL_NONE: u32 = 0u;
const TANGENTIAL_OQUENDO: u32 = 1u;
const TANGENTIAL_MINDLIN: u32 = 2u;
const STIFFNESS_MINDLIN: u32 = 0u;
const STIFFNESS_RATIO: u32 = 1u;
const ROLLING_NONE: u32 = 0u;
const ROLLING_SDS: u32 = 1u;
const TWISTING_NONE: u32 = 0u;
const TWISTING_OQUENDO: u32 = 1u;
const COHESION_NONE: u32 = 0u;
const COHESION_CAPILLARY: u32 = 1u;

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

// What update_bridges does at a pair (find_bridge_events marks it): its bridge ruptures, or
// it touches without one and one forms if its grains hold liquid.
const BRIDGE_RUPTURE: u32 = 1u;
const BRIDGE_TOUCH: u32 = 2u;

// Capillary bridges (src/model/capillary.rs): whether the gap delta (m) lies within the
// rupture distance (1 + theta/2) V^(1/3) (m), tested on the cubes as the CPU does.
fn within_rupture(v_b: f32, delta: f32) -> bool {
    let k = 1.0 + params.cohesion.y * 0.5;
    return delta <= 0.0 || delta * delta * delta <= k * k * k * v_b;
}

// Decay length of the capillary force across the gap (m), Richefeu et al. (2009) eq. 8.
fn decay_length(r_i: f32, r_j: f32, v_b: f32) -> f32 {
    let ratio = max(r_i / r_j, r_j / r_i);
    return params.cohesion.z * 0.70710678118654752 * sqrt((1.0 / r_i + 1.0 / r_j) / ratio * v_b);
}

// Capillary normal force (N, tensile negative) of a bridge of volume v_b at gap delta (m).
fn capillary_force(r_i: f32, r_j: f32, v_b: f32, delta: f32) -> f32 {
    if (v_b <= 0.0) {
        return 0.0;
    }
    let f0 = -params.cohesion.x * sqrt(r_i * r_j);
    if (delta < 0.0) {
        return f0;
    }
    if (within_rupture(v_b, delta)) {
        return f0 * exp(-(delta / decay_length(r_i, r_j, v_b)));
    }
    return 0.0;
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

// Damping coefficient eta (kg/s): the damping force on i is -eta v_n n.
fn normal_damping(c: PairCoeffs, g: Geometry) -> f32 {
    if (DAMPING_LAW == DAMPING_PAPERS) {
        return g.m_eff * c.gamma_n * sqrt(g.h);
    }
    if (DAMPING_LAW == DAMPING_RESTITUTION) {
        return normal_restitution_damping(c, g);
    }
    if (DAMPING_LAW == DAMPING_VISCOUS) {
        return params.damping.x;
    }
    return 0.0;
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

fn rotate_into_plane(s: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let len2 = dot(s, s);
    if (len2 == 0.0) {
        return s;
    }
    let p = s - n * dot(s, n);
    let p2 = dot(p, p);
    if (p2 == 0.0) {
        return vec3<f32>(0.0);
    }
    return p * sqrt(len2 / p2);
}

fn contact_tangential_velocity(g: Geometry, k: Kinematics) -> vec3<f32> {
    let v_p = k.v_i - k.v_j - cross(k.w_i * g.rp_i + k.w_j * g.rp_j, g.n);
    return v_p - g.n * dot(v_p, g.n);
}

fn tangential_stiffness(c: PairCoeffs, g: Geometry, k_secant: f32) -> f32 {
    if (params.kt_law == STIFFNESS_RATIO) {
        return params.tangential.x * k_secant;
    }
    return 8.0 * c.g_eff * sqrt(g.r_eff * g.h);
}

// An elastic-plastic spring (src/model/tangential.rs elastic_plastic): the force -k s - eta v
// within `stick`, else `slip` along itself with the spring rescaled to match.
struct ElasticPlastic {
    force: vec3<f32>,
    spring: vec3<f32>,
    slipped: bool,
}

fn elastic_plastic(s: vec3<f32>, v: vec3<f32>, k: f32, eta: f32, stick: f32, slip: f32) -> ElasticPlastic {
    var out: ElasticPlastic;
    let damp = v * eta;
    let f = -(s * k) - damp;
    let mag = sqrt(dot(f, f));
    out.slipped = mag > stick;
    if (out.slipped) {
        out.force = f * (slip / mag);
        if (k > 0.0) { out.spring = (out.force + damp) * (-1.0 / k); } else { out.spring = vec3<f32>(0.0); }
    } else {
        out.force = f;
        out.spring = s;
    }
    return out;
}

// Oquendo et al. eqs. 8-9 for one grain, fr = |F_n| tan(theta_r) t on the cap: (force, torque).
fn rolling_regime(fr: vec3<f32>, m: f32, inertia: f32, rp: f32, n: vec3<f32>, out_f: ptr<function, vec3<f32>>, out_t: ptr<function, vec3<f32>>) {
    let mr2 = m * rp * rp;
    *out_f = fr * (-1.0 / (1.0 + inertia / mr2));
    *out_t = cross(fr, n) * (rp / (1.0 + mr2 / inertia));
}

// The time the springs advance by (src/model/tangential.rs since_touch): `elapsed`, or on the
// evaluation that finds a contact new, the time since its surfaces met.
fn since_touch(hist: History, h: f32, v_n: f32, elapsed: f32) -> f32 {
    let approach = -v_n;
    let is_new = all(hist.tangential == vec3<f32>(0.0)) && all(hist.rolling == vec3<f32>(0.0));
    if (is_new && approach * elapsed > h) {
        return h / approach;
    }
    return elapsed;
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
        // Oquendo et al.'s regimes (src/model/tangential.rs oquendo_tangential).
        let k_t = tangential_stiffness(c, g, el.y);
        let v_t = contact_tangential_velocity(g, k);
        let xi = rotate_into_plane((*hist).tangential, g.n) + v_t * elapsed;
        let mobility_i = 1.0 / b.m_i + g.rp_i * g.rp_i / b.inertia_i;
        var mobility_j = 0.0;
        if (!b.j_is_wall) { mobility_j = 1.0 / b.m_j + g.rp_j * g.rp_j / b.inertia_j; }
        let eta_t = 2.0 * params.tangential.z * sqrt(k_t / (mobility_i + mobility_j));
        var mu = max(c.mu_s, c.mu_k);
        if ((*hist).sliding) { mu = c.mu_k; }
        let t = elastic_plastic(xi, v_t, k_t, eta_t, mu * f_n, c.mu_k * f_n);
        (*hist).tangential = t.spring;
        (*hist).sliding = t.slipped;
        let f_t = t.force;
        var f_i = f_t;
        var f_j = -f_t;
        var t_i = -(cross(g.n, f_t) * g.rp_i);
        var t_j = -(cross(g.n, f_t) * g.rp_j);
        if (t.slipped && mu * f_n > 0.0) { out.regime = REGIME_SLIDING; }
        if (t.slipped) {
            (*hist).rolling = vec3<f32>(0.0);
        } else {
            let v_r = cross(k.w_i - k.w_j, g.n) * g.rp_eff;
            let psi = rotate_into_plane((*hist).rolling, g.n) + v_r * elapsed;
            var mobility = 1.0 / b.inertia_i;
            if (!b.j_is_wall) { mobility = 1.0 / b.inertia_i + 1.0 / b.inertia_j; }
            let mobility_r = g.rp_eff * g.rp_eff * mobility;
            let eta_r = 2.0 * params.tangential.z * sqrt(k_t / mobility_r);
            let limit_r = f_n * c.tan_roll;
            let r = elastic_plastic(psi, v_r, k_t, eta_r, limit_r, limit_r);
            (*hist).rolling = r.spring;
            if (params.rolling_as_written == 0u) {
                let tau = cross(g.n, r.force) * g.rp_eff;
                t_i += tau;
                t_j -= tau;
            } else {
                let fr = -r.force;
                var rf_i = vec3<f32>(0.0);
                var rf_j = vec3<f32>(0.0);
                var rt_i = vec3<f32>(0.0);
                var rt_j = vec3<f32>(0.0);
                rolling_regime(fr, b.m_i, b.inertia_i, g.rp_i, g.n, &rf_i, &rt_i);
                if (b.j_is_wall) {
                    rf_j = -rf_i;
                } else {
                    rolling_regime(fr, b.m_j, b.inertia_j, g.rp_j, -g.n, &rf_j, &rt_j);
                }
                f_i += rf_i;
                f_j += rf_j;
                t_i += rt_i;
                t_j += rt_j;
            }
            if (r.slipped && limit_r > 0.0) { out.regime = REGIME_ROLLING; }
        }
        out.f_i += f_i;
        out.f_j += f_j;
        out.t_i += t_i;
        out.t_j += t_j;
    }
    if (TANGENTIAL_LAW == TANGENTIAL_MINDLIN) {
        let k_t = tangential_stiffness(c, g, el.y);
        let v_t = contact_tangential_velocity(g, k);
        (*hist).tangential = rotate_into_plane((*hist).tangential, g.n) + v_t * elapsed;
        let damp = v_t * (eta_n * params.tangential.y);
        var f_t = -((*hist).tangential * k_t) - damp;
        let limit = c.mu_s * f_n;
        let mag2 = dot(f_t, f_t);
        if (mag2 > limit * limit) {
            f_t = f_t * (limit / sqrt(mag2));
            if (k_t > 0.0) { (*hist).tangential = (f_t + damp) * (-1.0 / k_t); } else { (*hist).tangential = vec3<f32>(0.0); }
            out.regime = REGIME_SLIDING;
        }
        out.f_i += f_t;
        out.f_j -= f_t;
        out.t_i -= cross(g.n, f_t) * g.rp_i;
        out.t_j -= cross(g.n, f_t) * g.rp_j;
    }
    if (ROLLING_LAW == ROLLING_SDS) {
        let v_rl = cross(k.w_i - k.w_j, g.n) * g.r_eff;
        (*hist).rolling = rotate_into_plane((*hist).rolling, g.n) + v_rl * elapsed;
        let damp = v_rl * params.rolling.y;
        var f_r = -((*hist).rolling * params.rolling.x) - damp;
        let limit = params.rolling.z * f_n;
        let mag2 = dot(f_r, f_r);
        if (mag2 > limit * limit) {
            f_r = f_r * (limit / sqrt(mag2));
            if (params.rolling.x > 0.0) { (*hist).rolling = (f_r + damp) * (-1.0 / params.rolling.x); } else { (*hist).rolling = vec3<f32>(0.0); }
        }
        let tau = cross(g.n, f_r) * g.r_eff;
        out.t_i += tau;
        out.t_j -= tau;
    }
    if (TWISTING_LAW == TWISTING_OQUENDO) {
        let w_n = g.n * dot(k.w_i - k.w_j, g.n);
        let tau = w_n * (-4.0 * 3.14159265358979 * c.gamma_nt * g.m_eff * g.r_eff * g.h);
        out.t_i += tau;
        out.t_j -= tau;
    }
    return out;
}

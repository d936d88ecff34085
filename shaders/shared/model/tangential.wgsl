// The tangential slot, the WGSL twin of src/model/tangential/: the springs' shared geometry,
// Oquendo et al.'s regimes (oquendo.rs) and the Hertz-Mindlin history law (mindlin.rs). A
// law's code is TANGENTIAL_<NAME>, written from the slot's registry.

// Forces and torques of a tangential law on both partners, and the contact's regime
// (src/model/tangential/oquendo.rs TangentialOut).
struct TangentialOut {
    f_i: vec3<f32>,
    f_j: vec3<f32>,
    t_i: vec3<f32>,
    t_j: vec3<f32>,
    regime: u32,
}

// A world-frame spring rotated into the tangent plane of n, its length kept
// (src/model/tangential/mod.rs rotate_into_plane).
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
    switch (params.kt_law) {
        case STIFFNESS_MINDLIN: {
            return 8.0 * c.g_eff * sqrt(g.r_eff * g.h);
        }
        case STIFFNESS_RATIO, default: {
            return params.tangential.x * k_secant;
        }
    }
}

// An elastic-plastic spring (src/model/tangential/oquendo.rs elastic_plastic): the force -k s - eta v
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

// The time the springs advance by (src/model/tangential/mod.rs since_touch): `elapsed`, or on the
// evaluation that finds a contact new, the time since its surfaces met.
fn since_touch(hist: History, h: f32, v_n: f32, elapsed: f32) -> f32 {
    let approach = -v_n;
    let is_new = all(hist.tangential == vec3<f32>(0.0)) && all(hist.rolling == vec3<f32>(0.0));
    if (is_new && approach * elapsed > h) {
        return h / approach;
    }
    return elapsed;
}

// Oquendo et al.'s regimes (src/model/tangential/oquendo.rs oquendo_tangential) at normal
// force magnitude f_n (N) and spring stiffness k_t (N/m); the springs advance by `elapsed` (s).
fn oquendo_tangential(c: PairCoeffs, g: Geometry, k: Kinematics, b: Bodies, f_n: f32, k_t: f32, hist: ptr<function, History>, elapsed: f32) -> TangentialOut {
    var out: TangentialOut;
    out.regime = REGIME_STATIC;
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
    out.f_i = f_i;
    out.f_j = f_j;
    out.t_i = t_i;
    out.t_j = t_j;
    return out;
}

// Hertz-Mindlin with history (src/model/tangential/mindlin.rs mindlin_tangential): the spring
// force -k_t xi - eta_t v_t capped at mu_s f_n, the spring reset to the cap when it slips.
fn mindlin_tangential(c: PairCoeffs, g: Geometry, k: Kinematics, f_n: f32, k_t: f32, eta_t: f32, hist: ptr<function, History>, elapsed: f32) -> TangentialOut {
    var out: TangentialOut;
    out.regime = REGIME_STATIC;
    let v_t = contact_tangential_velocity(g, k);
    (*hist).tangential = rotate_into_plane((*hist).tangential, g.n) + v_t * elapsed;
    let damp = v_t * eta_t;
    var f_t = -((*hist).tangential * k_t) - damp;
    let limit = c.mu_s * f_n;
    let mag2 = dot(f_t, f_t);
    if (mag2 > limit * limit) {
        f_t = f_t * (limit / sqrt(mag2));
        if (k_t > 0.0) { (*hist).tangential = (f_t + damp) * (-1.0 / k_t); } else { (*hist).tangential = vec3<f32>(0.0); }
        out.regime = REGIME_SLIDING;
    }
    out.f_i = f_t;
    out.f_j = -f_t;
    out.t_i = -(cross(g.n, f_t) * g.rp_i);
    out.t_j = -(cross(g.n, f_t) * g.rp_j);
    return out;
}

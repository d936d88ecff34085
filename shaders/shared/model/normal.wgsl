// The normal slot, the WGSL twin of src/model/normal/: one set of functions per law, and the
// slot's dispatch on NORMAL_LAW. The laws' codes (NORMAL_HERTZ, NORMAL_LINEAR, NORMAL_DMT, ...)
// are written before this file from the registry (src/model/normal/mod.rs wgsl_codes); each
// law's constants are its block params.normal (its gpu_block). Forces compressive positive.

// Hertz (src/model/normal/hertz.rs): F_el = 4/3 V_eff sqrt(R_eff) h^(3/2); returns the force
// (N) and the secant stiffness F/h (N/m).
fn hertz_elastic(c: PairCoeffs, g: Geometry) -> vec2<f32> {
    let k = 4.0 / 3.0 * c.v_eff * sqrt(g.r_eff * g.h);
    return vec2<f32>(k * g.h, k);
}

// Hertz's tangent stiffness dF/dh = 2 V_eff sqrt(R_eff h) (N/m).
fn hertz_stiffness(c: PairCoeffs, g: Geometry) -> f32 {
    return 2.0 * c.v_eff * sqrt(g.r_eff * g.h);
}

// The restitution dashpot shaped to Hertz: 2 sqrt(5/6) beta sqrt(S_n m_eff) (kg/s).
fn hertz_restitution_damping(c: PairCoeffs, g: Geometry) -> f32 {
    let s_n = 2.0 * c.v_eff * sqrt(g.r_eff * g.h);
    return 2.0 * sqrt(5.0 / 6.0) * c.beta * sqrt(s_n * g.m_eff);
}

// Hertz's elastic energy 8/15 sqrt(R_eff) V_eff h^(5/2) (J).
fn hertz_potential(c: PairCoeffs, r_eff: f32, h: f32) -> f32 {
    return 8.0 / 15.0 * sqrt(r_eff) * c.v_eff * h * h * sqrt(h);
}

// DMT (src/model/normal/dmt.rs): Hertz less the pull-off 4 pi gamma R_eff (N), gamma =
// params.normal.x (J/m^2).
fn dmt_pull_off(r_eff: f32) -> f32 {
    return 4.0 * 3.141592653589793 * params.normal.x * r_eff;
}

// Elastic normal force (N) and secant stiffness F/h (N/m).
fn normal_elastic(c: PairCoeffs, g: Geometry) -> vec2<f32> {
    if (NORMAL_LAW == NORMAL_LINEAR) {
        return vec2<f32>(params.normal.x * g.h, params.normal.x);
    }
    return hertz_elastic(c, g);
}

// Normal tangent stiffness dF_el/dh (N/m).
fn normal_stiffness(c: PairCoeffs, g: Geometry) -> f32 {
    if (NORMAL_LAW == NORMAL_LINEAR) {
        return params.normal.x;
    }
    return hertz_stiffness(c, g);
}

// The coefficient (kg/s) of damping = "restitution"'s dashpot, shaped to the law.
fn normal_restitution_damping(c: PairCoeffs, g: Geometry) -> f32 {
    if (NORMAL_LAW == NORMAL_LINEAR) {
        return 2.0 * c.beta * sqrt(params.normal.x * g.m_eff);
    }
    return hertz_restitution_damping(c, g);
}

// The exponent p of the overlap in F_el ~ h^p.
fn normal_exponent() -> f32 {
    if (NORMAL_LAW == NORMAL_LINEAR) {
        return 1.0;
    }
    return 1.5;
}

// An adhesive law's pull-off force (N, positive) while the surfaces touch; 0 otherwise
// (normal_adhesive() false: the law never pulls).
fn normal_adhesive() -> bool {
    return NORMAL_LAW == NORMAL_DMT;
}

fn normal_pull_off(g: Geometry) -> f32 {
    return dmt_pull_off(g.r_eff);
}

// Elastic energy (J) of a normal spring with overlap h, zero at touch.
fn normal_potential(c: PairCoeffs, r_eff: f32, h: f32) -> f32 {
    if (NORMAL_LAW == NORMAL_LINEAR) {
        return 0.5 * params.normal.x * h * h;
    }
    if (NORMAL_LAW == NORMAL_DMT) {
        return hertz_potential(c, r_eff, h) - dmt_pull_off(r_eff) * h;
    }
    return hertz_potential(c, r_eff, h);
}

// The damping slot, the WGSL twin of src/model/damping/. A law's code is DAMPING_<NAME>,
// written from the slot's registry.

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

// The twisting slot, the WGSL twin of src/model/twisting/. A law's code is TWISTING_<NAME>,
// written from the slot's registry.

// Twisting torque on i (N m) of Oquendo et al. eq. 2 (src/model/twisting/oquendo.rs
// twisting_torque): -4 pi gamma_nt m_eff R_eff h w_n; on j, its opposite.
fn twisting_torque(c: PairCoeffs, g: Geometry, k: Kinematics) -> vec3<f32> {
    let w_n = g.n * dot(k.w_i - k.w_j, g.n);
    return w_n * (-4.0 * 3.14159265358979 * c.gamma_nt * g.m_eff * g.r_eff * g.h);
}

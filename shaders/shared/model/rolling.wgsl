// The rolling slot, the WGSL twin of src/model/rolling/. A law's code is ROLLING_<NAME>,
// written from the slot's registry.

// Rolling torque on i (N m) of LAMMPS' `rolling sds` (src/model/rolling/sds.rs rolling_sds):
// the rolling spring (the history's) grows by v_rl elapsed, its force -k_r psi - gamma_r v_rl
// is capped at mu_r f_n, and the torque on i is R_eff n x F_r; on j, its opposite.
fn rolling_sds(g: Geometry, k: Kinematics, f_n: f32, hist: ptr<function, History>, elapsed: f32) -> vec3<f32> {
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
    return cross(g.n, f_r) * g.r_eff;
}

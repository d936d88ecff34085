// The drift of a grain (needs `turn`, `pos`, `residual`, `vel`, `omega`, `quat`, `built_at`,
// `control`).
override TRACK_ORIENTATION: bool = false;

// Grain i by tau (s): x += v tau, compensated (the sum's rounding kept in residual), its
// orientation by Omelyan's norm-preserving update; records how far it has moved since the
// last build.
fn drift_grain(i: u32, tau: f32) {
    let p = pos[i];
    let moved = advance(p.xyz, residual[i], vel[i].xyz * tau);
    let x = moved.s;
    pos[i] = vec4<f32>(x, p.w);
    residual[i] = vec4<f32>(moved.e, 0.0);
    if (TRACK_ORIENTATION) {
        quat[i] = rotate(quat[i], omega[i].xyz, tau);
    }
    let d = x - built_at[i].xyz;
    atomicMax(&control.max_disp2, bitcast<u32>(dot(d, d)));
}

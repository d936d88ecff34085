// The drift of a grain (needs `pos`, `residual`, `vel`, `omega`, `quat`, `built_at`, `control`).
override TRACK_ORIENTATION: bool = false;

// q + (tau/2 (0, w) * q - 2 a q) / (1 + a), a = tau^2 |w|^2 / 16; quaternions scalar first
// (x = scalar).
fn rotate(q: vec4<f32>, w: vec3<f32>, tau: f32) -> vec4<f32> {
    let a = tau * tau * dot(w, w) / 16.0;
    let h = 0.5 * tau;
    let qv = q.yzw;
    let s = -dot(w, qv);
    let v = w * q.x + cross(w, qv);
    let inv = 1.0 / (1.0 + a);
    return q + (h * vec4<f32>(s, v) - 2.0 * a * q) * inv;
}

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

// The kick of a grain (needs `vel`, `omega`).

// Grain i under load (f, t) for tau (s): v += f/m tau, w += t/I tau.
fn kick_grain(i: u32, f: vec3<f32>, t: vec3<f32>, tau: f32) {
    let v = vel[i];
    let w = omega[i];
    vel[i] = vec4<f32>(v.xyz + f * (tau / v.w), v.w);
    omega[i] = vec4<f32>(w.xyz + t * (tau / w.w), w.w);
}

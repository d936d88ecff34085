// The kick (needs `vel`, `omega`, `walls`, `wall_reaction`).

// Grain i under load (f, t) for tau (s): v += f/m tau, w += t/I tau.
fn kick_grain(i: u32, f: vec3<f32>, t: vec3<f32>, tau: f32) {
    let v = vel[i];
    let w = omega[i];
    vel[i] = vec4<f32>(v.xyz + f * (tau / v.w), v.w);
    omega[i] = vec4<f32>(w.xyz + t * (tau / w.w), w.w);
}

// The piston for tau (s), by the grains' push minus its target pressure times its area.
fn kick_piston(tau: f32) {
    let p = walls[params.piston].piston;
    let push = wall_reaction[params.piston].z - p.z * p.y;
    walls[params.piston].velocity.z += push * tau / p.x;
}

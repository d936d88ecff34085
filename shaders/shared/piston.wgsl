// The piston's kick (needs `params`, `walls`, `wall_reaction`).

// The piston for tau (s), by the grains' push minus its target pressure times its area.
fn kick_piston(tau: f32) {
    let p = walls[params.piston].piston;
    let push = wall_reaction[params.piston].z - p.z * p.y;
    walls[params.piston].velocity.z += push * tau / p.x;
}

// The piston kicked by `kick` (s), then drifted by `drift` (s) booking the work of its target
// pressure; a zero duration skips that half.
fn move_piston(kick: f32, drift: f32) {
    if (kick > 0.0) {
        kick_piston(kick);
    }
    if (drift > 0.0) {
        let dz = walls[params.piston].velocity.z * drift;
        walls[params.piston].point.z += dz;
        let p = walls[params.piston].piston;
        walls[params.piston].piston.w -= p.z * p.y * dz;
    }
}

// The piston's kick (needs `params`, `walls`, `wall_reaction`).

// The piston for tau (s), by the grains' push minus its target pressure times its area.
fn kick_piston(tau: f32) {
    let p = walls[params.piston].piston;
    let push = wall_reaction[params.piston].z - p.z * p.y;
    walls[params.piston].velocity.z += push * tau / p.x;
}

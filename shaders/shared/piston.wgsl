// The piston's kick and drift, and the driven walls' drift (needs `params`, `walls`,
// `wall_reaction`).

// The piston for tau (s), by the grains' push minus its target pressure times its area.
fn kick_piston(tau: f32) {
    let p = walls[params.piston].drive;
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
        let p = walls[params.piston].drive;
        walls[params.piston].drive.w -= p.z * p.y * dz;
    }
}

// The driven walls drifted by `drift` (s) at their velocity (a cylinder, infinite along z, in x
// and y) and turned by their spin where it turns them (a plane's normal, kept of unit length; a
// mesh's rotation; src/walls.rs WallGeom::turned), booking the work they do on the grains in
// drive.w: their velocity against the grains' push, plus their spin's power; a zero duration
// skips it.
fn move_walls(drift: f32) {
    if (drift <= 0.0) {
        return;
    }
    for (var w = 0u; w < params.n_walls; w++) {
        if ((walls[w].flags & WALL_DRIVEN) == 0u) {
            continue;
        }
        let v = walls[w].velocity.xyz;
        if (walls[w].kind == WALL_CYLINDER) {
            walls[w].point = vec4<f32>(walls[w].point.xy + v.xy * drift, walls[w].point.zw);
        } else {
            walls[w].point = vec4<f32>(walls[w].point.xyz + v * drift, walls[w].point.w);
        }
        let spin = walls[w].drive.xyz;
        if ((walls[w].flags & WALL_TURNS) != 0u && any(spin != vec3<f32>(0.0))) {
            if (walls[w].kind == WALL_PLANE) {
                let n = turn_apply(rotate(vec4<f32>(1.0, 0.0, 0.0, 0.0), spin, drift), walls[w].normal.xyz);
                walls[w].normal = vec4<f32>(n * (1.0 / sqrt(dot(n, n))), walls[w].normal.w);
            } else {
                walls[w].turn = rotate(walls[w].turn, spin, drift);
            }
        }
        walls[w].drive.w += (wall_reaction[MAX_WALLS + w].z - dot(wall_reaction[w].xyz, v)) * drift;
    }
}

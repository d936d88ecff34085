// One invocation kicks one grain by phase.kick (v += F/m tau, w += T/I tau), then drifts it by
// phase.drift (x += v tau, compensated: the sum's rounding kept in residual; its orientation by Omelyan's norm-preserving update) and records
// how far it has moved since the last build; a zero duration skips that half, so a kick and
// the drift after it are one dispatch. Invocation 0 does the same to the piston and books
// the work of its target pressure.
override TRACK_ORIENTATION: bool = false;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<uniform> phase: Phase;
@group(0) @binding(2) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> residual: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> omega: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> force: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> torque: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> built_at: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> quat: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> walls: array<Wall>;
@group(0) @binding(11) var<storage, read> wall_reaction: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> control: Control;

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

@compute @workgroup_size(64)
fn integrate(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i == 0u && params.piston != NONE) {
        if (phase.kick > 0.0) {
            kick_piston(phase.kick);
        }
        if (phase.drift > 0.0) {
            let dz = walls[params.piston].velocity.z * phase.drift;
            walls[params.piston].point.z += dz;
            let p = walls[params.piston].piston;
            walls[params.piston].piston.w -= p.z * p.y * dz;
        }
    }
    if (i >= params.n_grains) {
        return;
    }
    if (phase.kick > 0.0) {
        kick_grain(i, force[i].xyz, torque[i].xyz, phase.kick);
    }
    if (phase.drift > 0.0) {
        let p = pos[i];
        let moved = advance(p.xyz, residual[i], vel[i].xyz * phase.drift);
        let x = moved.s;
        pos[i] = vec4<f32>(x, p.w);
        residual[i] = vec4<f32>(moved.e, 0.0);
        if (TRACK_ORIENTATION) {
            quat[i] = rotate(quat[i], omega[i].xyz, phase.drift);
        }
        let d = x - built_at[i].xyz;
        atomicMax(&control.max_disp2, bitcast<u32>(dot(d, d)));
    }
}

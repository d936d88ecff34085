// One invocation kicks one grain by phase.kick (v += F/m tau, w += T/I tau), then drifts it by
// phase.drift (x += v tau, compensated: the sum's rounding kept in residual; its orientation by Omelyan's norm-preserving update) and records
// how far it has moved since the last build; a zero duration skips that half, so a kick and
// the drift after it are one dispatch. Invocation 0 does the same to the piston and books
// the work of its target pressure, and drifts the driven walls.
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

@compute @workgroup_size(64)
fn integrate(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i == 0u) {
        if (params.piston != NONE) {
            move_piston(phase.kick, phase.drift);
        }
        move_walls(phase.drift);
    }
    if (i >= params.n_grains) {
        return;
    }
    if (phase.kick > 0.0) {
        kick_grain(i, force[i].xyz, torque[i].xyz, phase.kick);
    }
    if (phase.drift > 0.0) {
        drift_grain(i, phase.drift);
    }
}

// One invocation kicks one grain: v += F/m tau, w += T/I tau; invocation 0 also kicks the
// piston with the grains' push minus the target pressure times its area.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<uniform> phase: Phase;
@group(0) @binding(2) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> omega: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> force: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> torque: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> walls: array<Wall>;
@group(0) @binding(7) var<storage, read> wall_reaction: array<vec4<f32>>;

@compute @workgroup_size(64)
fn kick(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i == 0u && params.piston != NONE) {
        let p = walls[params.piston].piston;
        let push = wall_reaction[params.piston].z - p.z * p.y;
        walls[params.piston].velocity.z += push * phase.tau / p.x;
    }
    if (i >= params.n_grains) {
        return;
    }
    let v = vel[i];
    let w = omega[i];
    vel[i] = vec4<f32>(v.xyz + force[i].xyz * (phase.tau / v.w), v.w);
    omega[i] = vec4<f32>(w.xyz + torque[i].xyz * (phase.tau / w.w), w.w);
}

// One invocation (the first) solves the serial tail, the wall contacts and any uncoloured
// pair, one after the other in order: a moving wall is one body for all its contacts.

@group(0) @binding(0) var<uniform> cd: CdParams;
@group(0) @binding(1) var<storage, read> contacts: array<CdContact>;
@group(0) @binding(2) var<storage, read_write> impulse: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> omega: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> wall_vel: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> measure: array<vec2<f32>>;
@group(0) @binding(7) var<storage, read> sweeps: CdControl;

@compute @workgroup_size(WG)
fn cd_sweep_tail(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (sweeps.done != 0u || flat_index(wid, lid, nwg) != 0u) {
        return;
    }
    for (var k = cd.tail; k < cd.n_contacts; k++) {
        let c = contacts[k];
        let a = Motion(vel[c.a].xyz, omega[c.a].xyz);
        var b: Motion;
        if (c.to_wall != 0u) {
            b = Motion(wall_vel[c.b].xyz, vec3<f32>(0.0));
        } else {
            b = Motion(vel[c.b].xyz, omega[c.b].xyz);
        }
        let s = solve_contact(c, impulse[k].xyz, a, b, cd.relaxation);
        impulse[k] = vec4<f32>(s.r, 0.0);
        vel[c.a] = vec4<f32>(s.a.vel, 0.0);
        omega[c.a] = vec4<f32>(s.a.omega, 0.0);
        if (c.to_wall != 0u) {
            wall_vel[c.b] = vec4<f32>(s.b.vel, 0.0);
        } else {
            vel[c.b] = vec4<f32>(s.b.vel, 0.0);
            omega[c.b] = vec4<f32>(s.b.omega, 0.0);
        }
        measure[k] = s.measure;
    }
}

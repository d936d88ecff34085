// One invocation solves one contact of a colour and applies its impulse's change to its two
// grains; no two contacts of a colour share a grain, so the colour's invocations are
// independent and give the bits of solving them one after the other.

@group(0) @binding(0) var<uniform> cd: CdParams;
@group(0) @binding(1) var<uniform> phase: CdColour;
@group(0) @binding(2) var<storage, read> contacts: array<CdContact>;
@group(0) @binding(3) var<storage, read_write> impulse: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> omega: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> measure: array<vec2<f32>>;
@group(0) @binding(7) var<storage, read> sweeps: CdControl;

@compute @workgroup_size(WG)
fn cd_sweep_colour(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = phase.start + flat_index(wid, lid, nwg);
    if (sweeps.done != 0u || k >= phase.end) {
        return;
    }
    let c = contacts[k];
    let r_old = impulse[k].xyz;
    let a = Motion(vel[c.a].xyz, omega[c.a].xyz);
    let b = Motion(vel[c.b].xyz, omega[c.b].xyz);
    if (stays_open(c, r_old, a, b)) {
        measure[k] = vec2<f32>(0.0);
        return;
    }
    let s = solve_contact(c, r_old, a, b, cd.relaxation);
    impulse[k] = vec4<f32>(s.r, 0.0);
    vel[c.a] = vec4<f32>(s.a.vel, 0.0);
    omega[c.a] = vec4<f32>(s.a.omega, 0.0);
    vel[c.b] = vec4<f32>(s.b.vel, 0.0);
    omega[c.b] = vec4<f32>(s.b.omega, 0.0);
    measure[k] = s.measure;
}

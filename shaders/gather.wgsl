// One invocation sums the load on one grain in a fixed order: gravity, the pairs it owns,
// the pairs where it is partner, its wall contacts. No float atomics. force.w counts the
// grain's pairs that push (f_n > 0), for the statistics' rattlers. With phase.kick > 0 it
// then kicks the grain (and invocation 0 the piston) under that load: the kick after an
// evaluation, in the same dispatch. A partner's force is out_fj where the pair pass stores it
// (PARTNER_FORCE_STORED), else the owner's reversed: subtracting out_fi adds the same bits.
override PARTNER_FORCE_STORED: bool;
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> pair_start: array<u32>;
@group(0) @binding(3) var<storage, read> rev_start: array<u32>;
@group(0) @binding(4) var<storage, read> rev_pair: array<u32>;
@group(0) @binding(5) var<storage, read> out_fi: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> out_fj: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> out_ti: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> out_tj: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read> wall_force: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read> wall_torque: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> force: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> torque: array<vec4<f32>>;
@group(0) @binding(13) var<uniform> phase: Phase;
@group(0) @binding(14) var<storage, read_write> omega: array<vec4<f32>>;
@group(0) @binding(15) var<storage, read_write> walls: array<Wall>;
@group(0) @binding(16) var<storage, read> wall_reaction: array<vec4<f32>>;

@compute @workgroup_size(64)
fn gather(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i == 0u && params.piston != NONE && phase.kick > 0.0) {
        kick_piston(phase.kick);
    }
    if (i >= params.n_grains) {
        return;
    }
    var f = params.gravity.xyz * vel[i].w;
    var t = vec3<f32>(0.0);
    var pushing = 0.0;
    let end = min(pair_start[i + 1u], params.pair_capacity);
    for (var k = pair_start[i]; k < end; k++) {
        f += out_fi[k].xyz;
        t += out_ti[k].xyz;
        pushing += select(0.0, 1.0, out_fi[k].w > 0.0);
    }
    for (var s = rev_start[i]; s < rev_start[i + 1u]; s++) {
        let k = rev_pair[s];
        if (PARTNER_FORCE_STORED) {
            f += out_fj[k].xyz;
        } else {
            f -= out_fi[k].xyz;
        }
        t += out_tj[k].xyz;
        pushing += select(0.0, 1.0, out_fi[k].w > 0.0);
    }
    let load = f + wall_force[i].xyz;
    let moment = t + wall_torque[i].xyz;
    force[i] = vec4<f32>(load, pushing);
    torque[i] = vec4<f32>(moment, 0.0);
    if (phase.kick > 0.0) {
        kick_grain(i, load, moment, phase.kick);
    }
}

// One invocation computes the force of one listed pair, once, in canonical order (owner =
// lower id = i), reading and writing its history (history_of_blocks: the tangential block's w
// is the sliding flag, the bridge block's x the liquid volume, and the normal velocity at the
// previous evaluation takes a spare component). Its record: out_fi the force on i and the
// normal force, out_ti the torque on i and its tangential regime (plus CLAMPED_FLAG when the
// normal force was clamped), out_tj the torque on j and its capillary force, and out_fj the
// force on j only where the law's force on j is not the force on i reversed
// (PARTNER_FORCE_STORED; the gather subtracts out_fi otherwise). A pair that does not touch
// forgets its springs and exerts only the capillary force of its bridge, if it has one within
// reach, and the end of a contact that parted within the window (parted_normal_force).
override PARTNER_FORCE_STORED: bool;
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<uniform> phase: Phase;
@group(0) @binding(2) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> residual: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> vel: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> omega: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> material: array<u32>;
@group(0) @binding(7) var<storage, read> coeffs: array<PairCoeffs>;
@group(0) @binding(8) var<storage, read> pair_i: array<u32>;
@group(0) @binding(9) var<storage, read> pair_j: array<u32>;
@group(0) @binding(10) var<storage, read_write> hist: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> out_fi: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> out_fj: array<vec4<f32>>;
@group(0) @binding(13) var<storage, read_write> out_ti: array<vec4<f32>>;
@group(0) @binding(14) var<storage, read_write> out_tj: array<vec4<f32>>;
@group(0) @binding(15) var<storage, read> control: Control;

fn load_history(k: u32) -> History {
    var blocks: array<vec4<f32>, MAX_HISTORY_BLOCKS>;
    for (var b = 0u; b < params.hist_blocks; b++) { blocks[b] = hist[k * params.hist_blocks + b]; }
    return history_of_blocks(blocks);
}

fn store_history(k: u32, h: History) {
    let blocks = blocks_of_history(h);
    for (var b = 0u; b < params.hist_blocks; b++) { hist[k * params.hist_blocks + b] = blocks[b]; }
}

@compute @workgroup_size(64)
fn pair_force(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = flat_index(wid, lid, nwg);
    if (k >= control.n_pairs) {
        return;
    }
    let i = pair_i[k];
    let j = pair_j[k];
    let pi = pos[i];
    let pj = pos[j];
    let d = separation(pi.xyz, residual[i], pj.xyz, residual[j]);
    let dist2 = dot(d, d);
    let reach = pi.w + pj.w;
    if (dist2 >= reach * reach) {
        // The springs are forgotten, the bridge kept.
        var open = empty_history();
        var f_c = 0.0;
        var n = vec3<f32>(0.0);
        if (COHESION_LAW == COHESION_CAPILLARY) {
            open.bridge = load_history(k).bridge;
            let dist = sqrt(dist2);
            f_c = capillary_force(pi.w, pj.w, open.bridge, dist - reach);
            n = d * (1.0 / dist);
        }
        store_history(k, open);
        var f_i = n * f_c;
        var f_j = n * (-f_c);
        var f_n = 0.0;
        let window = kick_window(phase.elapsed);
        if (ends_pull(window)) {
            let g = geometry_grain_grain(d, sqrt(dist2), pi.w, pj.w, vel[i].w, vel[j].w);
            f_n = parted_normal_force(coeffs[material[i] * params.n_materials + material[j]], g, dot(vel[i].xyz - vel[j].xyz, g.n), window);
            f_i += g.n * f_n;
            f_j -= g.n * f_n;
        }
        out_fi[k] = vec4<f32>(f_i, f_n);
        if (PARTNER_FORCE_STORED) {
            out_fj[k] = vec4<f32>(f_j, 0.0);
        }
        out_ti[k] = vec4<f32>(0.0);
        out_tj[k] = vec4<f32>(0.0, 0.0, 0.0, f_c);
        return;
    }
    let vi = vel[i];
    let vj = vel[j];
    let wi = omega[i];
    let wj = omega[j];
    let g = geometry_grain_grain(d, sqrt(dist2), pi.w, pj.w, vi.w, vj.w);
    let kin = Kinematics(vi.xyz, vj.xyz, wi.xyz, wj.xyz);
    let bodies = Bodies(vi.w, wi.w, vj.w, wj.w, false);
    let c = coeffs[material[i] * params.n_materials + material[j]];
    var h = load_history(k);
    var f = contact_force(c, g, kin, bodies, &h, phase.elapsed);
    store_history(k, h);
    var f_c = 0.0;
    if (COHESION_LAW == COHESION_CAPILLARY) {
        f_c = capillary_force(pi.w, pj.w, h.bridge, -g.h);
        f.f_i += g.n * f_c;
        f.f_j -= g.n * f_c;
    }
    out_fi[k] = vec4<f32>(f.f_i, f.f_n);
    if (PARTNER_FORCE_STORED) {
        out_fj[k] = vec4<f32>(f.f_j, 0.0);
    }
    out_ti[k] = vec4<f32>(f.t_i, f32(f.regime + select(0u, CLAMPED_FLAG, f.clamped)));
    out_tj[k] = vec4<f32>(f.t_j, f_c);
}

// One invocation adds one pair to its workgroup's statistics row: touching pairs, clamped
// contacts, elastic energy, |contact force| (counted for both grains), sliding and rolling
// contacts, and the largest overlap over the smaller radius.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> residual: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> material: array<u32>;
@group(0) @binding(4) var<storage, read> coeffs: array<PairCoeffs>;
@group(0) @binding(5) var<storage, read> pair_i: array<u32>;
@group(0) @binding(6) var<storage, read> pair_j: array<u32>;
@group(0) @binding(7) var<storage, read> out_fi: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> out_ti: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read> control: Control;
@group(0) @binding(10) var<storage, read_write> pair_rows: array<f32>;

var<workgroup> row: array<f32, WG * STAT_ROW>;

@compute @workgroup_size(64)
fn reduce_pairs(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = flat_index(wid, lid, nwg);
    clear_row(lid);
    if (k < control.n_pairs) {
        let r = lid * STAT_ROW;
        let i = pair_i[k];
        let j = pair_j[k];
        let pi = pos[i];
        let pj = pos[j];
        let h = pi.w + pj.w - length(separation(pi.xyz, residual[i], pj.xyz, residual[j]));
        if (h > 0.0) {
            let c = coeffs[material[i] * params.n_materials + material[j]];
            row[r + P_CONTACTS] = count_field(1u);
            // The regime, plus CLAMPED_FLAG for a normal force clamped at zero (pair_force).
            let code = u32(out_ti[k].w);
            let regime = code % CLAMPED_FLAG;
            row[r + P_CLAMPED] = count_field(code / CLAMPED_FLAG);
            row[r + P_ELASTIC] = normal_potential(c, pi.w * pj.w / (pi.w + pj.w), h);
            row[r + P_FORCE] = 2.0 * length(out_fi[k].xyz);
            row[r + P_SLIDING] = count_field(select(0u, 1u, regime == REGIME_SLIDING));
            row[r + P_ROLLING] = count_field(select(0u, 1u, regime == REGIME_ROLLING));
            row[r + STAT_MAX] = h / min(pi.w, pj.w);
            row[r + STAT_ARG] = bitcast<f32>(i);
        }
    }
    reduce_rows(lid, P_COUNTS);
    if (lid == 0u) {
        let out = (wid.y * nwg.x + wid.x) * STAT_ROW;
        for (var f = 0u; f < STAT_ROW; f++) {
            pair_rows[out + f] = row[f];
        }
    }
}

// One invocation keeps one pair of the list being replaced: its partner and its history.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_j: array<u32>;
@group(0) @binding(2) var<storage, read> hist: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> old_j: array<u32>;
@group(0) @binding(4) var<storage, read_write> old_hist: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> control: Control;

@compute @workgroup_size(64)
fn save_pairs(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = flat_index(wid, lid, nwg);
    if (k >= control.n_pairs) {
        return;
    }
    old_j[k] = pair_j[k];
    for (var b = 0u; b < params.hist_blocks; b++) {
        old_hist[k * params.hist_blocks + b] = hist[k * params.hist_blocks + b];
    }
}

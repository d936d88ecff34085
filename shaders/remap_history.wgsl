// One invocation finds one new pair in the replaced list (same owner, same partner id, as
// DEM-Engine's persistent map matches them) and carries its history over, or zeroes it. The
// replaced list sits where `save_pairs` left it.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_i: array<u32>;
@group(0) @binding(2) var<storage, read> pair_j: array<u32>;
@group(0) @binding(3) var<storage, read> old_start: array<u32>;
@group(0) @binding(4) var<storage, read> old_j: array<u32>;
@group(0) @binding(5) var<storage, read> old_hist0: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> old_hist1: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> old_hist2: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> hist: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read> control: Control;

@compute @workgroup_size(64)
fn remap_history(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = flat_index(wid, lid, nwg);
    if (k >= control.n_pairs) {
        return;
    }
    let i = pair_i[k];
    let j = pair_j[k];
    // Binary search of the owner's sorted old partners.
    var lo = old_start[i];
    var hi = old_start[i + 1u];
    var found = NONE;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        let v = old_j[mid];
        if (v == j) {
            found = mid;
            break;
        }
        if (v < j) { lo = mid + 1u; } else { hi = mid; }
    }
    for (var b = 0u; b < params.hist_blocks; b++) {
        var h = vec4<f32>(0.0);
        if (found != NONE) {
            if (b == 0u) {
                h = old_hist0[found];
            } else if (b == 1u) {
                h = old_hist1[found];
            } else {
                h = old_hist2[found];
            }
        }
        hist[k * params.hist_blocks + b] = h;
    }
}

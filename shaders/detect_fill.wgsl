// One invocation lists the pairs one grain owns, in ascending partner id, so that the list
// does not depend on the order grains landed in their buckets.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> residual: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> cell_count: array<u32>;
@group(0) @binding(4) var<storage, read> cell_grains: array<u32>;
@group(0) @binding(5) var<storage, read> pair_start: array<u32>;
@group(0) @binding(6) var<storage, read_write> pair_i: array<u32>;
@group(0) @binding(7) var<storage, read_write> pair_j: array<u32>;

@compute @workgroup_size(64)
fn detect_fill(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i >= params.n_grains) {
        return;
    }
    let start = pair_start[i];
    let end = min(pair_start[i + 1u], params.pair_capacity);
    if (start >= end) {
        return;
    }
    var it = search(i);
    for (var slot = start; slot < end; slot++) {
        let j = next_partner(&it);
        if (j == NONE) {
            break;
        }
        // Insertion into the sorted run pair_j[start..slot).
        var at = slot;
        while (at > start && pair_j[at - 1u] > j) {
            pair_j[at] = pair_j[at - 1u];
            at -= 1u;
        }
        pair_j[at] = j;
        pair_i[slot] = i;
    }
}

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
    let pi = pos[i];
    let b = neighbour_buckets(pi.xyz);
    var slot = start;
    for (var k = 0u; k < b.n; k++) {
        let r = bucket_range(b.h[k]);
        for (var s = r.x; s < r.y; s++) {
            let j = cell_grains[s];
            if (slot < end && owns(i, j, pi)) {
                // Insertion into the sorted run pair_j[start..slot).
                var at = slot;
                while (at > start && pair_j[at - 1u] > j) {
                    pair_j[at] = pair_j[at - 1u];
                    at -= 1u;
                }
                pair_j[at] = j;
                pair_i[slot] = i;
                slot += 1u;
            }
        }
    }
}

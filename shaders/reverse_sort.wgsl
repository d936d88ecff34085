// One invocation sorts the pairs where one grain is partner by pair index, so that the
// gather sums them in a fixed order.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> rev_start: array<u32>;
@group(0) @binding(2) var<storage, read_write> rev_pair: array<u32>;

@compute @workgroup_size(64)
fn reverse_sort(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i >= params.n_grains) {
        return;
    }
    let start = rev_start[i];
    let end = rev_start[i + 1u];
    for (var s = start + 1u; s < end; s++) {
        let v = rev_pair[s];
        var at = s;
        while (at > start && rev_pair[at - 1u] > v) {
            rev_pair[at] = rev_pair[at - 1u];
            at -= 1u;
        }
        rev_pair[at] = v;
    }
}

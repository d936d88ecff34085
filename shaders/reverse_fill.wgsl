// One invocation files one pair under its partner (in no fixed order; reverse_sort fixes it).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_j: array<u32>;
@group(0) @binding(2) var<storage, read> rev_start: array<u32>;
@group(0) @binding(3) var<storage, read_write> rev_fill: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> rev_pair: array<u32>;
@group(0) @binding(5) var<storage, read> control: Control;

@compute @workgroup_size(64)
fn reverse_fill(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = flat_index(wid, lid, nwg);
    if (k < control.n_pairs) {
        let j = pair_j[k];
        rev_pair[rev_start[j] + atomicAdd(&rev_fill[j], 1u)] = k;
    }
}

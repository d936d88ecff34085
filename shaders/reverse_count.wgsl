// One invocation counts one pair towards its partner's list of pairs where it is partner.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_j: array<u32>;
@group(0) @binding(2) var<storage, read_write> rev_start: array<atomic<u32>>;
@group(0) @binding(3) var<storage, read> control: Control;

@compute @workgroup_size(64)
fn reverse_count(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = flat_index(wid, lid, nwg);
    if (k < control.n_pairs) {
        atomicAdd(&rev_start[pair_j[k]], 1u);
    }
}

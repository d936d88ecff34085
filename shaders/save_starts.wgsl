// One invocation keeps one entry of the pair starts of the list being replaced.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_start: array<u32>;
@group(0) @binding(2) var<storage, read_write> old_start: array<u32>;

@compute @workgroup_size(64)
fn save_starts(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i <= params.n_grains) {
        old_start[i] = pair_start[i];
    }
}

// One invocation clears one hash bucket's count and fill cursor (start of a rebuild).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> cell_count: array<u32>;
@group(0) @binding(2) var<storage, read_write> cell_fill: array<u32>;

@compute @workgroup_size(64)
fn clear_cells(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let h = flat_index(wid, lid, nwg);
    if (h < params.hash_size) {
        cell_count[h] = 0u;
        cell_fill[h] = 0u;
    }
}

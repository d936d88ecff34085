// One invocation places one grain into its bucket's range of the sorted grain array (the
// order within a bucket is not fixed; detect_pairs sorts what it finds).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> cell_of: array<u32>;
@group(0) @binding(2) var<storage, read> cell_count: array<u32>;
@group(0) @binding(3) var<storage, read_write> cell_fill: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> cell_grains: array<u32>;

@compute @workgroup_size(64)
fn scatter_cells(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i >= params.n_grains) {
        return;
    }
    let h = cell_of[i];
    if (h == NONE) {
        return; // out of play
    }
    let slot = cell_count[h] + atomicAdd(&cell_fill[h], 1u);
    cell_grains[slot] = i;
}

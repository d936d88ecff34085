// One invocation starts the rebuild for one grain: wraps it into the periodic cell (counting
// images), marks its position as built, and counts it into its hash bucket.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> image: array<vec4<i32>>;
@group(0) @binding(3) var<storage, read_write> built_at: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> cell_of: array<u32>;
@group(0) @binding(5) var<storage, read_write> cell_count: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> control: Control;
@group(0) @binding(7) var<storage, read_write> pair_start: array<u32>;
@group(0) @binding(8) var<storage, read_write> rev_start: array<u32>;
@group(0) @binding(9) var<storage, read_write> rev_fill: array<u32>;

@compute @workgroup_size(64)
fn hash_cells(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i == 0u) {
        pair_start[params.n_grains] = 0u;
        rev_start[params.n_grains] = 0u;
    }
    if (i >= params.n_grains) {
        return;
    }
    rev_start[i] = 0u;
    rev_fill[i] = 0u;
    var p = pos[i];
    if (any(p.xyz != p.xyz) || any(abs(p.xyz) > vec3<f32>(3.0e38))) {
        atomicMin(&control.non_finite, i);
    }
    var moved = vec3<i32>(0);
    for (var a = 0u; a < 3u; a++) {
        let len = params.periodic_len[a];
        if (len > 0.0) {
            let lo = params.periodic_lo[a];
            var n = floor((p[a] - lo) / len);
            var y = p[a] - len * n;
            if (y >= lo + len) {
                y = lo;
                n += 1.0;
            }
            p[a] = y;
            moved[a] = i32(n);
        }
    }
    if (params.periodic_dims.x + params.periodic_dims.y + params.periodic_dims.z > 0u) {
        pos[i] = p;
        image[i] = image[i] + vec4<i32>(moved, 0);
    }
    built_at[i] = p;
    let h = cell_hash(cell_coords(p.xyz));
    cell_of[i] = h;
    atomicAdd(&cell_count[h], 1u);
}

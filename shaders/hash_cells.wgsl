// One invocation starts the rebuild for one grain: wraps it into the periodic cell (counting
// images), marks its position as built, and counts it into the hash bucket of its cell in its
// size class's grid.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> residual: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> image: array<vec4<i32>>;
@group(0) @binding(4) var<storage, read_write> built_at: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> cell_of: array<u32>;
@group(0) @binding(6) var<storage, read_write> cell_count: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> control: Control;
@group(0) @binding(8) var<storage, read_write> pair_start: array<u32>;
@group(0) @binding(9) var<storage, read_write> rev_start: array<u32>;

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
    var p = pos[i];
    var r = residual[i];
    if (any(p.xyz != p.xyz) || any(abs(p.xyz) > vec3<f32>(3.0e38))) {
        atomicMin(&control.non_finite, i);
    }
    var moved = vec3<i32>(0);
    // The CPU twin's compensated wrap (src/position.rs wrap): the shift's rounding goes to the
    // residual.
    // Per axis as vectors: the axes that do not wrap shift by 0 and are left as they were.
    let wraps = params.periodic_len.xyz > vec3<f32>(0.0);
    let len = select(vec3<f32>(1.0), params.periodic_len.xyz, wraps);
    let lo = params.periodic_lo.xyz;
    var n = select(vec3<f32>(0.0), floor((p.xyz - lo) / len), wraps);
    let shifted = two_sum(p.xyz, -(len * n), r.w);
    var y = two_sum(shifted.s, keep(r.xyz + shifted.e, r.w), r.w);
    // Rounding can land exactly on lo + len; that is lo, one period further.
    let over = wraps & (y.s >= lo + len);
    let down = two_sum(y.s, -len, r.w);
    let y2 = two_sum(down.s, keep(y.e + down.e, r.w), r.w);
    y = TwoSum(select(y.s, y2.s, over), select(y.e, y2.e, over));
    n += select(vec3<f32>(0.0), vec3<f32>(1.0), over);
    p = vec4<f32>(select(p.xyz, y.s, wraps), p.w);
    r = vec4<f32>(select(r.xyz, y.e, wraps), r.w);
    moved = vec3<i32>(n);
    if (any(wraps)) {
        pos[i] = p;
        residual[i] = r;
        image[i] = image[i] + vec4<i32>(moved, 0);
    }
    built_at[i] = p;
    if (!in_play(p)) {
        cell_of[i] = NONE;
        return;
    }
    let k = class_of(p.w);
    let h = cell_hash(cell_coords(p.xyz, k), k);
    cell_of[i] = h;
    atomicAdd(&cell_count[h], 1u);
}

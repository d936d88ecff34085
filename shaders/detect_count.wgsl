// One invocation counts the pairs one grain owns (partners of higher id within reach) and
// flags a grain over its neighbour capacity (owner_capacity). It also clears the grain's counter for
// reverse_fill: rev_fill lives in cell_fill's buffer, which scatter_cells uses until then.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> residual: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> cell_count: array<u32>;
@group(0) @binding(4) var<storage, read> cell_grains: array<u32>;
@group(0) @binding(5) var<storage, read_write> pair_start: array<u32>;
@group(0) @binding(6) var<storage, read_write> control: Control;
@group(0) @binding(7) var<storage, read_write> rev_fill: array<u32>;

@compute @workgroup_size(64)
fn detect_count(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    if (i >= params.n_grains) {
        return;
    }
    rev_fill[i] = 0u;
    if (!in_play(pos[i])) {
        pair_start[i] = 0u;
        return;
    }
    var it = search(i);
    var count = 0u;
    while (next_partner(&it) != NONE) {
        count += 1u;
    }
    let capacity = owner_capacity(it.p.w);
    if (count > capacity) {
        if (atomicMin(&control.overflow_grain, i) > i) {
            atomicStore(&control.overflow_count, count);
        }
        count = capacity;
    }
    pair_start[i] = count;
}

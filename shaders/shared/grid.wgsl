// The spatial hash shared by hash_cells and the neighbour search: each size class of grains
// (src/state/levels.rs) has a grid of its own, with integer cell coordinates wrapped along
// periodic axes; a cell of a class hashes into one of params.hash_size buckets (a power of
// two). Buckets may hold grains of several cells and classes; the search keeps a grain only
// where it was hashed (neighbours.wgsl).

// The size class of a grain of this radius (m): the first whose largest radius it does not
// exceed, the last when it exceeds them all (src/state/levels.rs class_index).
fn class_of(radius: f32) -> u32 {
    var k = 0u;
    while (k + 1u < params.classes && radius > params.class_cell[k].w) {
        k += 1u;
    }
    return k;
}

// Cell coordinates wrapped along the periodic axes of class k's grid.
fn wrap_cell(c: vec3<i32>, k: u32) -> vec3<i32> {
    var q = c;
    for (var a = 0u; a < 3u; a++) {
        let d = i32(params.class_dims[k][a]);
        if (d > 0) {
            q[a] = ((q[a] % d) + d) % d;
        }
    }
    return q;
}

// The cell of class k's grid holding position p (m).
fn cell_coords(p: vec3<f32>, k: u32) -> vec3<i32> {
    return wrap_cell(vec3<i32>(floor((p - params.periodic_lo.xyz) / params.class_cell[k].xyz)), k);
}

// The bucket of cell c of class k's grid.
fn cell_hash(c: vec3<i32>, k: u32) -> u32 {
    let h = (u32(c.x) * 73856093u) ^ (u32(c.y) * 19349663u) ^ (u32(c.z) * 83492791u) ^ (k * 2654435761u);
    return h & (params.hash_size - 1u);
}

// The shortest periodic image of a separation.
fn min_image(d_in: vec3<f32>) -> vec3<f32> {
    var d = d_in;
    for (var a = 0u; a < 3u; a++) {
        let len = params.periodic_len[a];
        if (len > 0.0) {
            // One period added or taken past half of it (the CPU twin's compares).
            if (d[a] > 0.5 * len) {
                d[a] -= len;
            } else if (d[a] < -0.5 * len) {
                d[a] += len;
            }
        }
    }
    return d;
}

// The separation r_i - r_j of two compensated positions (src/position.rs separation): the
// positions' difference folded to the minimum image, plus the residuals' difference.
fn separation(p_i: vec3<f32>, r_i: vec4<f32>, p_j: vec3<f32>, r_j: vec4<f32>) -> vec3<f32> {
    return complete(min_image(p_i - p_j), r_i.xyz - r_j.xyz, r_i.w);
}

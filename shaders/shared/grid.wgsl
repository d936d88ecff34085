// The spatial hash shared by hash_cells and detect_pairs: integer cell coordinates, wrapped
// along periodic axes, hashed into params.hash_size buckets (a power of two). Buckets may
// hold grains of several cells; the distance test sorts them out.

fn cell_coords(p: vec3<f32>) -> vec3<i32> {
    var c = vec3<i32>(floor((p - params.periodic_lo.xyz) / params.cell.xyz));
    for (var a = 0u; a < 3u; a++) {
        let d = i32(params.periodic_dims[a]);
        if (d > 0) {
            c[a] = ((c[a] % d) + d) % d;
        }
    }
    return c;
}

fn cell_hash(c: vec3<i32>) -> u32 {
    let h = (u32(c.x) * 73856093u) ^ (u32(c.y) * 19349663u) ^ (u32(c.z) * 83492791u);
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

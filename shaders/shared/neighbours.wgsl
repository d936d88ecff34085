// Neighbour search shared by detect_count and detect_fill (which declare pos, residual,
// cell_count and cell_grains): the distinct buckets of the 27 cells around a grain.

struct Buckets {
    h: array<u32, 27>,
    n: u32,
}

fn neighbour_buckets(p: vec3<f32>) -> Buckets {
    var b: Buckets;
    b.n = 0u;
    let c = cell_coords(p);
    for (var dz = -1; dz <= 1; dz++) {
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                var q = c + vec3<i32>(dx, dy, dz);
                for (var a = 0u; a < 3u; a++) {
                    let d = i32(params.periodic_dims[a]);
                    if (d > 0) {
                        q[a] = ((q[a] % d) + d) % d;
                    }
                }
                let h = cell_hash(q);
                var seen = false;
                for (var k = 0u; k < b.n; k++) {
                    if (b.h[k] == h) { seen = true; }
                }
                if (!seen) {
                    b.h[b.n] = h;
                    b.n += 1u;
                }
            }
        }
    }
    return b;
}

// Range of cell_grains holding bucket h.
fn bucket_range(h: u32) -> vec2<u32> {
    var end = params.n_grains;
    if (h + 1u < params.hash_size) {
        end = cell_count[h + 1u];
    }
    return vec2<u32>(cell_count[h], end);
}

// The most pairs a grain of this radius may own (m): params.max_neighbours for the smallest
// grains, 4x for each doubling radius + r_min needs past 2 r_min (src/state/pairs.rs
// owner_capacity: exact doublings and one correctly rounded sum, the same bits).
fn owner_capacity(radius: f32) -> u32 {
    let reach = radius + params.r_min;
    var edge = 2.0 * params.r_min;
    var capacity = params.max_neighbours;
    for (var k = 0u; k < OWNER_DOUBLINGS; k++) {
        if (edge >= reach) {
            break;
        }
        edge *= 2.0;
        capacity *= 4u;
    }
    return capacity;
}

// True when grain j is a partner grain i owns: a higher id within reach (minimum image).
fn owns(i: u32, j: u32, pi: vec4<f32>) -> bool {
    if (j <= i) {
        return false;
    }
    let pj = pos[j];
    let d = separation(pi.xyz, residual[i], pj.xyz, residual[j]);
    let reach = pi.w + pj.w + params.reach;
    return dot(d, d) < reach * reach;
}

// The neighbour search shared by detect_count and detect_fill (which declare pos, residual,
// cell_count and cell_grains): the grains one grain owns, from each size class's grid within
// the owner's reach into that class (src/state/levels.rs detect_pairs_in: the same cells),
// one cell at a time. A bucket may hold grains of other cells and classes (grid.wgsl); a
// grain counts only in the cell it was hashed to, so that each is found once.

struct Search {
    i: u32,           // the owner
    p: vec4<f32>,     // its position (m) in xyz, its radius (m) in w
    size: u32,        // the size class whose grid is being searched
    first: vec3<i32>, // the cells of that grid within reach: first + at, wrapped, for at < count
    count: vec3<u32>,
    at: vec3<u32>,
    cell: vec3<i32>,  // the cell being scanned (wrapped)
    s: u32,           // the range of cell_grains of its bucket still to scan
    end: u32,
}

// A search for the grains grain i owns, at the first class's grid.
fn search(i: u32) -> Search {
    var it: Search;
    it.i = i;
    it.p = pos[i];
    it.size = 0u;
    aim(&it);
    return it;
}

// Points the search at the cells of its class's grid that may hold a partner: those within
// h = ceil((R_i + the class's largest radius + reach) / cell edge), at least 1, of the
// owner's cell along each axis, every cell once where that spans a wrapping axis.
fn aim(it: ptr<function, Search>) {
    let k = (*it).size;
    let grid = params.class_cell[k];
    let far = (*it).p.w + grid.w + params.reach;
    let c = cell_coords((*it).p.xyz, k);
    for (var a = 0u; a < 3u; a++) {
        let h = max(1u, u32(ceil(far / grid[a])));
        let d = params.class_dims[k][a];
        if (d > 0u && 2u * h + 1u >= d) {
            (*it).first[a] = 0;
            (*it).count[a] = d;
        } else {
            (*it).first[a] = c[a] - i32(h);
            (*it).count[a] = 2u * h + 1u;
        }
    }
    (*it).at = vec3<u32>(0u);
    enter(it);
}

// Starts the scan of the search's current cell.
fn enter(it: ptr<function, Search>) {
    let q = wrap_cell((*it).first + vec3<i32>((*it).at), (*it).size);
    (*it).cell = q;
    let r = bucket_range(cell_hash(q, (*it).size));
    (*it).s = r.x;
    (*it).end = r.y;
}

// The next grain the search's owner owns, or NONE when the search is done: cells x fastest,
// then the next class.
fn next_partner(it: ptr<function, Search>) -> u32 {
    loop {
        if ((*it).s < (*it).end) {
            let j = cell_grains[(*it).s];
            (*it).s += 1u;
            if (owns((*it).i, j, (*it).p)) {
                let pj = pos[j];
                let k = (*it).size;
                if (class_of(pj.w) == k && all(cell_coords(pj.xyz, k) == (*it).cell)) {
                    return j;
                }
            }
            continue;
        }
        (*it).at.x += 1u;
        if ((*it).at.x == (*it).count.x) {
            (*it).at.x = 0u;
            (*it).at.y += 1u;
            if ((*it).at.y == (*it).count.y) {
                (*it).at.y = 0u;
                (*it).at.z += 1u;
                if ((*it).at.z == (*it).count.z) {
                    (*it).size += 1u;
                    if ((*it).size == params.classes) {
                        break;
                    }
                    aim(it);
                    continue;
                }
            }
        }
        enter(it);
    }
    return NONE;
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

// Mesh walls (needs `meshes`, `mesh_data`, `mesh_index`; MESH_CONTACTS and RAW_CONTACTS are
// written from src/mesh): the closest point of a triangle, a grain's contacts with a mesh and
// the slots its history keeps them in. The twins of src/mesh/{closest,grid,surface,slots}.rs,
// the same operations in the same order.

// The part of a triangle its closest point lies on: MESH_FACE, MESH_EDGE + k (corners k and
// k + 1), MESH_VERTEX + k.
const MESH_FACE: u32 = 0u;
const MESH_EDGE: u32 = 1u;
const MESH_VERTEX: u32 = 4u;

struct Closest {
    q: vec3<f32>,
    region: u32,
}

// The point of triangle (a, b, c) nearest to p, and its region (Ericson 5.1.5).
fn closest_on_triangle(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> Closest {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return Closest(a, MESH_VERTEX);
    }
    let bp = p - b;
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return Closest(b, MESH_VERTEX + 1u);
    }
    let vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        return Closest(a + ab * (d1 / (d1 - d3)), MESH_EDGE);
    }
    let cp = p - c;
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return Closest(c, MESH_VERTEX + 2u);
    }
    let vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        return Closest(a + ac * (d2 / (d2 - d6)), MESH_EDGE + 2u);
    }
    let va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return Closest(b + (c - b) * w, MESH_EDGE + 1u);
    }
    let denom = 1.0 / (va + vb + vc);
    return Closest(a + ab * (vb * denom) + ac * (vc * denom), MESH_FACE);
}

// Corner k (0..3) of triangle t of mesh m: its index, and its edge k's.
fn mesh_corner(m: MeshInfo, t: u32, k: u32) -> u32 {
    return mesh_index[m.bases.y + 6u * t + k];
}
fn mesh_edge(m: MeshInfo, t: u32, k: u32) -> u32 {
    return mesh_index[m.bases.y + 6u * t + 3u + k];
}
fn mesh_vertex(m: MeshInfo, v: u32) -> vec3<f32> {
    return mesh_data[m.bases.x + v].xyz;
}

// The range of mesh_index holding the triangles that may lie within the grid's reach of x (in
// the mesh's frame); empty outside the grid.
fn mesh_near(m: MeshInfo, x: vec3<f32>) -> vec2<u32> {
    let d = (x - m.origin.xyz) * m.origin.w;
    let f = floor(d);
    let n = vec3<f32>(m.dims.xyz);
    if (!(f.x >= 0.0 && f.x < n.x && f.y >= 0.0 && f.y < n.y && f.z >= 0.0 && f.z < n.z)) {
        return vec2<u32>(0u, 0u);
    }
    let c = u32(f.x) + m.dims.x * (u32(f.y) + m.dims.y * u32(f.z));
    let at = m.dims.w + c;
    return vec2<u32>(m.bases.z + mesh_index[at], m.bases.z + mesh_index[at + 1u]);
}

// A grain's contacts with one mesh: `len` of them, each a unit normal and a distance (m);
// `overflow` where it has too many.
struct MeshTouches {
    normal: array<vec3<f32>, MESH_CONTACTS>,
    dist: array<f32, MESH_CONTACTS>,
    len: u32,
    overflow: bool,
}

// The triangles within a grain's radius (touching's scratch).
var<private> raw_tri: array<u32, RAW_CONTACTS>;
var<private> raw_region: array<u32, RAW_CONTACTS>;
var<private> raw_offset: array<vec3<f32>, RAW_CONTACTS>;
var<private> raw_d2: array<f32, RAW_CONTACTS>;

// True when an edge or corner contact k belongs to a triangle whose face the grain touches,
// or (a corner) to an edge it touches (MeshSurface::hidden).
fn mesh_hidden(m: MeshInfo, n: u32, k: u32) -> bool {
    let region = raw_region[k];
    if (region < MESH_VERTEX) {
        let e = mesh_edge(m, raw_tri[k], region - MESH_EDGE);
        for (var o = 0u; o < n; o++) {
            if (raw_region[o] == MESH_FACE) {
                let t = raw_tri[o];
                if (mesh_edge(m, t, 0u) == e || mesh_edge(m, t, 1u) == e || mesh_edge(m, t, 2u) == e) {
                    return true;
                }
            }
        }
        return false;
    }
    let v = mesh_corner(m, raw_tri[k], region - MESH_VERTEX);
    for (var o = 0u; o < n; o++) {
        let t = raw_tri[o];
        if (raw_region[o] == MESH_FACE) {
            if (mesh_corner(m, t, 0u) == v || mesh_corner(m, t, 1u) == v || mesh_corner(m, t, 2u) == v) {
                return true;
            }
        } else if (raw_region[o] < MESH_VERTEX) {
            let j = raw_region[o] - MESH_EDGE;
            if (mesh_corner(m, t, j) == v || mesh_corner(m, t, (j + 1u) % 3u) == v) {
                return true;
            }
        }
    }
    return false;
}

// True when raw contacts a and b are the same edge or the same corner of the mesh.
fn mesh_same_feature(m: MeshInfo, a: u32, b: u32) -> bool {
    let ra = raw_region[a];
    let rb = raw_region[b];
    if (ra == MESH_FACE || rb == MESH_FACE) {
        return false;
    }
    if (ra < MESH_VERTEX && rb < MESH_VERTEX) {
        return mesh_edge(m, raw_tri[a], ra - MESH_EDGE) == mesh_edge(m, raw_tri[b], rb - MESH_EDGE);
    }
    if (ra >= MESH_VERTEX && rb >= MESH_VERTEX) {
        return mesh_corner(m, raw_tri[a], ra - MESH_VERTEX) == mesh_corner(m, raw_tri[b], rb - MESH_VERTEX);
    }
    return false;
}

// The contacts of a sphere of `radius` (m) centred at x (m, in the mesh's frame)
// (MeshSurface::touching).
fn mesh_touching(m: MeshInfo, x: vec3<f32>, radius: f32) -> MeshTouches {
    var out: MeshTouches;
    out.len = 0u;
    out.overflow = false;
    var first: array<vec3<f32>, MESH_CONTACTS>;
    var faces: array<vec3<f32>, MESH_CONTACTS>;
    var deepest_is_face: array<bool, MESH_CONTACTS>;
    var n = 0u;
    let range = mesh_near(m, x);
    for (var s = range.x; s < range.y; s++) {
        let t = mesh_index[s];
        let c = closest_on_triangle(x, mesh_vertex(m, mesh_corner(m, t, 0u)), mesh_vertex(m, mesh_corner(m, t, 1u)), mesh_vertex(m, mesh_corner(m, t, 2u)));
        let offset = x - c.q;
        let d2 = dot(offset, offset);
        if (d2 < radius * radius) {
            if (n == RAW_CONTACTS) {
                out.overflow = true;
                return out;
            }
            raw_tri[n] = t;
            raw_region[n] = c.region;
            raw_offset[n] = offset;
            raw_d2[n] = d2;
            n++;
        }
    }
    for (var i = 0u; i < n; i++) {
        if (raw_region[i] != MESH_FACE && mesh_hidden(m, n, i)) {
            continue;
        }
        var repeated = false;
        for (var o = 0u; o < i; o++) {
            repeated = repeated || mesh_same_feature(m, o, i);
        }
        if (repeated) {
            continue;
        }
        let dist = sqrt(raw_d2[i]);
        var normal: vec3<f32>;
        if (dist > 0.0) {
            normal = raw_offset[i] * (1.0 / dist);
        } else {
            let t = raw_tri[i];
            let a = mesh_vertex(m, mesh_corner(m, t, 0u));
            let across = cross(mesh_vertex(m, mesh_corner(m, t, 1u)) - a, mesh_vertex(m, mesh_corner(m, t, 2u)) - a);
            normal = across * (1.0 / sqrt(dot(across, across)));
        }
        let is_face = raw_region[i] == MESH_FACE;
        var face = vec3<f32>(0.0);
        if (is_face) {
            face = normal * (radius - dist);
        }
        var k = MESH_CONTACTS;
        for (var g = 0u; g < out.len; g++) {
            if (k == MESH_CONTACTS && dot(first[g], normal) > bitcast<f32>(m.bases.w)) {
                k = g;
            }
        }
        if (k < MESH_CONTACTS) {
            faces[k] += face;
            if (dist < out.dist[k]) {
                out.normal[k] = normal;
                out.dist[k] = dist;
                deepest_is_face[k] = is_face;
            }
        } else if (out.len == MESH_CONTACTS) {
            out.overflow = true;
            return out;
        } else {
            first[out.len] = normal;
            faces[out.len] = face;
            deepest_is_face[out.len] = is_face;
            out.normal[out.len] = normal;
            out.dist[out.len] = dist;
            out.len++;
        }
    }
    for (var g = 0u; g < out.len; g++) {
        if (deepest_is_face[g]) {
            out.normal[g] = faces[g] * (1.0 / sqrt(dot(faces[g], faces[g])));
        }
    }
    return out;
}

// What becomes of each slot (slots::assign): MESH_SLOT_FREE, or the contact it takes, plus
// MESH_SLOT_NEW where it starts from zero history. `last` holds each slot's last normal (zero:
// free); `cos` the merge cosine.
const MESH_SLOT_FREE: u32 = 0xffffffffu;
const MESH_SLOT_NEW: u32 = 0x10000u;
fn mesh_assign(t: MeshTouches, last: array<vec3<f32>, MESH_CONTACTS>, cos: f32) -> array<u32, MESH_CONTACTS> {
    var uses: array<u32, MESH_CONTACTS>;
    var placed: array<bool, MESH_CONTACTS>;
    for (var j = 0u; j < MESH_CONTACTS; j++) {
        uses[j] = MESH_SLOT_FREE;
        placed[j] = false;
    }
    for (var k = 0u; k < t.len; k++) {
        var best = MESH_CONTACTS;
        var best_dot = 0.0;
        for (var j = 0u; j < MESH_CONTACTS; j++) {
            if (uses[j] != MESH_SLOT_FREE || all(last[j] == vec3<f32>(0.0))) {
                continue;
            }
            let d = dot(last[j], t.normal[k]);
            if (d > cos && (best == MESH_CONTACTS || d > best_dot)) {
                best = j;
                best_dot = d;
            }
        }
        if (best < MESH_CONTACTS) {
            uses[best] = k;
            placed[k] = true;
        }
    }
    for (var k = 0u; k < t.len; k++) {
        if (!placed[k]) {
            var j = 0u;
            while (uses[j] != MESH_SLOT_FREE) {
                j++;
            }
            uses[j] = k + MESH_SLOT_NEW;
        }
    }
    return uses;
}

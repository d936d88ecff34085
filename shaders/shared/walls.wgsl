// Wall surfaces (needs `walls`): unit normal from the wall to a compensated position p + r
// and the signed distance from the surface to it, positive on the grains' side (not for a mesh,
// whose contacts are mesh_touching's).
fn wall_frame(w: Wall, p: vec3<f32>, r: vec4<f32>) -> vec4<f32> {
    if (w.kind == WALL_PLANE) {
        return vec4<f32>(w.normal.xyz, dot(complete(p - w.point.xyz, r.xyz, r.w), w.normal.xyz));
    }
    if (w.kind == WALL_CYLINDER) {
        let dxy = complete(vec3<f32>(p.xy - w.point.xy, 0.0), r.xyz, r.w).xy;
        let rho = length(dxy);
        var n = vec3<f32>(-1.0, 0.0, 0.0);
        if (rho > 0.0) { n = vec3<f32>(-dxy / rho, 0.0); }
        return vec4<f32>(n, w.normal.w - rho);
    }
    return vec4<f32>(0.0, 0.0, -1.0, keep(vec3<f32>(w.point.z - p.z), r.w).z - r.z);
}

// A driven wall's angular velocity (rad/s; zero for any other wall).
fn wall_spin(w: Wall) -> vec3<f32> {
    if ((w.flags & WALL_DRIVEN) != 0u) { return w.drive.xyz; }
    return vec3<f32>(0.0);
}

// The point a wall's spin turns it about (src/walls.rs WallGeom::pivot): a mesh's where its
// translation has taken it.
fn wall_pivot(w: Wall) -> vec3<f32> {
    if (w.kind == WALL_PLANE) { return w.point.xyz; }
    if (w.kind == WALL_MESH) { return w.normal.yzw + w.point.xyz; }
    if (w.kind == WALL_CYLINDER) { return vec3<f32>(w.point.xy, 0.0); }
    return vec3<f32>(0.0, 0.0, w.point.z);
}

// The velocity of a wall's surface at x: its velocity, plus spin x (x - pivot) where it spins.
fn wall_velocity_at(w: Wall, x: vec3<f32>) -> vec3<f32> {
    let spin = wall_spin(w);
    if (all(spin == vec3<f32>(0.0))) { return w.velocity.xyz; }
    return w.velocity.xyz + cross(spin, x - wall_pivot(w));
}

// A compensated position p + r in mesh wall w's rest frame, where its triangles are
// (src/walls.rs MeshPose::local).
fn mesh_local(w: Wall, p: vec3<f32>, r: vec4<f32>) -> vec3<f32> {
    if ((w.flags & WALL_TURNS) == 0u) {
        return complete(p - w.point.xyz, r.xyz, r.w);
    }
    let pivot = w.normal.yzw;
    return pivot + turn_unapply(w.turn, complete(p - (pivot + w.point.xyz), r.xyz, r.w));
}

// The statistics' count of a grain's wall contacts, packed into its force.w beside the pairs
// that push it (at most WALL_COUNTS_SLIDING - 1): sliding ones times WALL_COUNTS_SLIDING,
// rolling ones times WALL_COUNTS_ROLLING (each at most MAX_WALLS; the sum stays below 2^24, an
// integer an f32 holds exactly).
const WALL_COUNTS_SLIDING: u32 = 65536u;
const WALL_COUNTS_ROLLING: u32 = 1048576u;

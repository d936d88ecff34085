// Wall surfaces (needs `walls`): unit normal from the wall to a point and the signed
// distance from the surface to it, positive on the grains' side.
fn wall_frame(w: Wall, p: vec3<f32>) -> vec4<f32> {
    if (w.kind == WALL_PLANE) {
        return vec4<f32>(w.normal.xyz, dot(p - w.point.xyz, w.normal.xyz));
    }
    if (w.kind == WALL_CYLINDER) {
        let dxy = p.xy - w.point.xy;
        let rho = length(dxy);
        var n = vec3<f32>(-1.0, 0.0, 0.0);
        if (rho > 0.0) { n = vec3<f32>(-dxy / rho, 0.0); }
        return vec4<f32>(n, w.normal.w - rho);
    }
    return vec4<f32>(0.0, 0.0, -1.0, w.point.z - p.z);
}

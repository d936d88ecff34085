// Flat invocation index of a dispatch that may be split over two dimensions (more than
// 65535 workgroups of WG invocations).
fn flat_index(wid: vec3<u32>, lid: u32, nwg: vec3<u32>) -> u32 {
    return (wid.y * nwg.x + wid.x) * WG + lid;
}

// Workgroups for n items, split over y when x would exceed 65535.
fn groups_for(n: u32) -> DispatchArgs {
    let g = (n + WG - 1u) / WG;
    if (g <= 65535u) {
        return DispatchArgs(g, 1u, 1u);
    }
    return DispatchArgs(65535u, (g + 65534u) / 65535u, 1u);
}

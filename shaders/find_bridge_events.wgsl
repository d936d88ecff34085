// One invocation per pair: what update_bridges has to do there (the CPU's parallel pass in
// update_bridges), from the pair's own gap and bridge alone: BRIDGE_RUPTURE when its bridge
// is stretched past its rupture distance, BRIDGE_TOUCH when it touches without one, 0 else.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> residual: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> pair_i: array<u32>;
@group(0) @binding(4) var<storage, read> pair_j: array<u32>;
@group(0) @binding(5) var<storage, read> hist: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> bridge_event: array<u32>;
@group(0) @binding(7) var<storage, read> control: Control;

@compute @workgroup_size(64)
fn find_bridge_events(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = flat_index(wid, lid, nwg);
    if (k >= control.n_pairs) {
        return;
    }
    let i = pair_i[k];
    let j = pair_j[k];
    let d = separation(pos[i].xyz, residual[i], pos[j].xyz, residual[j]);
    // The CPU's |d| - r_i - r_j, summed in its order.
    let gap = sqrt(d.x * d.x + d.y * d.y + d.z * d.z) - pos[i].w - pos[j].w;
    // The bridge block is a contact's last.
    let v = hist[k * params.hist_blocks + params.hist_blocks - 1u].x;
    var event = 0u;
    if (v > 0.0) {
        if (!within_rupture(v, gap)) {
            event = BRIDGE_RUPTURE;
        }
    } else if (gap < 0.0) {
        event = BRIDGE_TOUCH;
    }
    bridge_event[k] = event;
}

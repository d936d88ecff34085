// One invocation walks the pairs in order (the CPU's update_bridges, serial so that a grain
// forming several bridges in one evaluation gives its liquid out in a fixed order), acting
// only where find_bridge_events marked the pair: a bridge stretched beyond its rupture
// distance gives its liquid back to its two grains in halves; a new contact takes half of
// each grain's liquid, capped at the largest bridge. Liquid is conserved to round-off.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_i: array<u32>;
@group(0) @binding(2) var<storage, read> pair_j: array<u32>;
@group(0) @binding(3) var<storage, read> bridge_event: array<u32>;
@group(0) @binding(4) var<storage, read_write> hist: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> liquid: array<f32>;
@group(0) @binding(6) var<storage, read> control: Control;

@compute @workgroup_size(1)
fn update_bridges() {
    // The bridge block is a contact's last.
    let last = params.hist_blocks - 1u;
    for (var k = 0u; k < control.n_pairs; k++) {
        let event = bridge_event[k];
        if (event == 0u) {
            continue;
        }
        let i = pair_i[k];
        let j = pair_j[k];
        let at = k * params.hist_blocks + last;
        if (event == BRIDGE_RUPTURE) {
            let v = hist[at].x;
            liquid[i] += v * 0.5;
            liquid[j] += v * 0.5;
            hist[at].x = 0.0;
        } else if (liquid[i] > 0.0 || liquid[j] > 0.0) {
            var a = liquid[i] * 0.5;
            var c = liquid[j] * 0.5;
            if (a + c > params.cohesion.w) {
                let s = params.cohesion.w / (a + c);
                a *= s;
                c *= s;
            }
            liquid[i] -= a;
            liquid[j] -= c;
            // (Its y may hold the normal velocity: src/gpu/layout.rs normal_slot.)
            hist[at].x = a + c;
        }
    }
}

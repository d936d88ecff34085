// One invocation sums one block of MEASURE_BLOCK contacts' shares of the convergence measure,
// in contact order.

@group(0) @binding(0) var<uniform> cd: CdParams;
@group(0) @binding(1) var<storage, read> measure: array<vec2<f32>>;
@group(0) @binding(2) var<storage, read_write> blocks: array<vec2<f32>>;
@group(0) @binding(3) var<storage, read> sweeps: CdControl;

@compute @workgroup_size(WG)
fn cd_measure(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let block = flat_index(wid, lid, nwg);
    if (sweeps.done != 0u || block >= cd.n_blocks) {
        return;
    }
    let end = min((block + 1u) * MEASURE_BLOCK, cd.n_contacts);
    var sum = vec2<f32>(0.0);
    for (var k = block * MEASURE_BLOCK; k < end; k++) {
        sum = sum + measure[k];
    }
    blocks[block] = sum;
}

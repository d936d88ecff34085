// One invocation (the first) sums the blocks in order into the square of the sweep's quadratic
// norm, sum |W dr|^2 / sum |W r|^2, counts the sweep, and stops the sweeps at the tolerance or
// at the cap.

@group(0) @binding(0) var<uniform> cd: CdParams;
@group(0) @binding(1) var<storage, read> blocks: array<vec2<f32>>;
@group(0) @binding(2) var<storage, read_write> sweeps: CdControl;

@compute @workgroup_size(WG)
fn cd_decide(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (sweeps.done != 0u || flat_index(wid, lid, nwg) != 0u) {
        return;
    }
    var sum = vec2<f32>(0.0);
    for (var b = 0u; b < cd.n_blocks; b++) {
        sum = sum + blocks[b];
    }
    sweeps.iterations += 1u;
    var norm2 = 0.0;
    if (sum.y > 0.0) {
        norm2 = sum.x / sum.y;
    }
    sweeps.sweep_norm2 = norm2;
    if (norm2 <= cd.tolerance2) {
        sweeps.converged = 1u;
        sweeps.done = 1u;
    } else if (sweeps.iterations >= cd.max_iterations) {
        sweeps.done = 1u;
    }
}

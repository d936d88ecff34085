// One workgroup adds its block's offset to the block's SCAN_BLOCK partial sums.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> scan_data: array<u32>;
@group(0) @binding(2) var<storage, read_write> block_sums: array<u32>;

const THREADS: u32 = 256u;
const PER_THREAD: u32 = SCAN_BLOCK / THREADS;

@compute @workgroup_size(256)
fn scan_add(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let n = arrayLength(&scan_data);
    let offset = block_sums[wid.x];
    for (var k = 0u; k < PER_THREAD; k++) {
        let idx = wid.x * SCAN_BLOCK + lid * PER_THREAD + k;
        if (idx < n) { scan_data[idx] += offset; }
    }
}

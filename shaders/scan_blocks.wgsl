// One workgroup turns one block of SCAN_BLOCK counts into exclusive prefix sums within the
// block and writes the block's total. A scan runs it over the data, then (with more than one
// block) once over the block totals (one block), then scan_add adds each block's offset.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> scan_data: array<u32>;
@group(0) @binding(2) var<storage, read_write> block_sums: array<u32>;

const THREADS: u32 = 256u;
const PER_THREAD: u32 = SCAN_BLOCK / THREADS;
var<workgroup> partial: array<u32, 256>;

@compute @workgroup_size(256)
fn scan_blocks(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let n = arrayLength(&scan_data);
    let base = wid.x * THREADS * PER_THREAD + lid * PER_THREAD;
    var local: array<u32, PER_THREAD>;
    var sum = 0u;
    for (var k = 0u; k < PER_THREAD; k++) {
        let idx = base + k;
        var v = 0u;
        if (idx < n) { v = scan_data[idx]; }
        local[k] = sum;
        sum += v;
    }
    partial[lid] = sum;
    workgroupBarrier();
    // Hillis-Steele inclusive scan of the thread totals.
    for (var off = 1u; off < THREADS; off *= 2u) {
        var add = 0u;
        if (lid >= off) { add = partial[lid - off]; }
        workgroupBarrier();
        partial[lid] += add;
        workgroupBarrier();
    }
    let before = partial[lid] - sum;
    for (var k = 0u; k < PER_THREAD; k++) {
        let idx = base + k;
        if (idx < n) { scan_data[idx] = before + local[k]; }
    }
    if (lid == THREADS - 1u) {
        block_sums[wid.x] = partial[lid];
    }
}

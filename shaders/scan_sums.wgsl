// One workgroup turns the block totals into exclusive prefix sums (at most 2048 blocks).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> block_sums: array<u32>;

const PER_THREAD: u32 = 8u;
const THREADS: u32 = 256u;
var<workgroup> partial: array<u32, 256>;

@compute @workgroup_size(256)
fn scan_sums(@builtin(local_invocation_index) lid: u32) {
    let n = arrayLength(&block_sums);
    let base = lid * PER_THREAD;
    var local: array<u32, 8>;
    var sum = 0u;
    for (var k = 0u; k < PER_THREAD; k++) {
        let idx = base + k;
        var v = 0u;
        if (idx < n) { v = block_sums[idx]; }
        local[k] = sum;
        sum += v;
    }
    partial[lid] = sum;
    workgroupBarrier();
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
        if (idx < n) { block_sums[idx] = before + local[k]; }
    }
}

// Fixed-order workgroup reduction of statistics rows (sums, then the largest value and its
// grain; ties go to the lower grain). Needs `row: array<f32, WG * STAT_ROW>` in workgroup
// memory. The fields whose bit is set in `counts` hold u32 counts (their bits in the f32
// slot) and are summed as integers.

// Field `f` of a row plus `v`, as an integer when `counts` says it is one.
fn add_field(a: f32, v: f32, f: u32, counts: u32) -> f32 {
    if (((counts >> f) & 1u) != 0u) {
        return bitcast<f32>(bitcast<u32>(a) + bitcast<u32>(v));
    }
    return a + v;
}

// A count as the bits of a row field.
fn count_field(n: u32) -> f32 {
    return bitcast<f32>(n);
}

fn reduce_rows(lid: u32, counts: u32) {
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride /= 2u) {
        if (lid < stride) {
            let a = lid * STAT_ROW;
            let b = (lid + stride) * STAT_ROW;
            for (var f = 0u; f < STAT_MAX; f++) {
                row[a + f] = add_field(row[a + f], row[b + f], f, counts);
            }
            let va = row[a + STAT_MAX];
            let vb = row[b + STAT_MAX];
            let ia = bitcast<u32>(row[a + STAT_ARG]);
            let ib = bitcast<u32>(row[b + STAT_ARG]);
            if (vb > va || (vb == va && ib < ia)) {
                row[a + STAT_MAX] = vb;
                row[a + STAT_ARG] = row[b + STAT_ARG];
            }
        }
        workgroupBarrier();
    }
}

fn clear_row(lid: u32) {
    for (var f = 0u; f < STAT_ROW; f++) {
        row[lid * STAT_ROW + f] = 0.0;
    }
    row[lid * STAT_ROW + STAT_ARG] = bitcast<f32>(NONE);
}

// One workgroup sums the statistics rows in a fixed order: stats[0..STAT_ROW] over grains,
// stats[STAT_ROW..2 STAT_ROW] over pairs (the pair rows beyond the current pair count are ignored).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> grain_rows: array<f32>;
@group(0) @binding(2) var<storage, read> pair_rows: array<f32>;
@group(0) @binding(3) var<storage, read> control: Control;
@group(0) @binding(4) var<storage, read_write> stats: array<f32>;

var<workgroup> row: array<f32, WG * STAT_ROW>;

fn fold(lid: u32, rows: u32, which: u32, counts: u32) {
    clear_row(lid);
    let r = lid * STAT_ROW;
    for (var s = lid; s < rows; s += WG) {
        let base = s * STAT_ROW;
        for (var f = 0u; f < STAT_MAX; f++) {
            var v = 0.0;
            if (which == 0u) { v = grain_rows[base + f]; } else { v = pair_rows[base + f]; }
            row[r + f] = add_field(row[r + f], v, f, counts);
        }
        var vmax = 0.0;
        var arg = 0.0;
        if (which == 0u) { vmax = grain_rows[base + STAT_MAX]; arg = grain_rows[base + STAT_ARG]; } else { vmax = pair_rows[base + STAT_MAX]; arg = pair_rows[base + STAT_ARG]; }
        if (vmax > row[r + STAT_MAX] || (vmax == row[r + STAT_MAX] && bitcast<u32>(arg) < bitcast<u32>(row[r + STAT_ARG]))) {
            row[r + STAT_MAX] = vmax;
            row[r + STAT_ARG] = arg;
        }
    }
    reduce_rows(lid, counts);
}

@compute @workgroup_size(64)
fn reduce_final(@builtin(local_invocation_index) lid: u32) {
    let grain_groups = (params.n_grains + WG - 1u) / WG;
    fold(lid, grain_groups, 0u, G_COUNTS);
    if (lid == 0u) {
        for (var f = 0u; f < STAT_ROW; f++) { stats[f] = row[f]; }
    }
    workgroupBarrier();
    let pair_groups = (control.n_pairs + WG - 1u) / WG;
    fold(lid, pair_groups, 1u, P_COUNTS);
    if (lid == 0u) {
        for (var f = 0u; f < STAT_ROW; f++) { stats[STAT_ROW + f] = row[f]; }
    }
}

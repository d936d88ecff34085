// One workgroup sums the per-workgroup wall rows in a fixed order into each wall's totals:
// entries 0..MAX_WALLS (xyz: force the grains exert, w: contacts, u32 bits), then MAX_WALLS.. (the
// contacts' summed stiffness and damping for servo walls and the spin's power for spinning
// walls; zero otherwise). With phase.kick > 0
// it then kicks the piston under those totals: the kick after an evaluation, whose grains the
// gather kicked; and with phase.drift > 0 kicks it by phase.then_kick and drifts it, the next
// step's first sweep, carried as the gather carried the grains', and drifts the driven walls.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<uniform> phase: Phase;
@group(0) @binding(2) var<storage, read> wall_partials: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> wall_reaction: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> walls: array<Wall>;

var<workgroup> acc: array<vec4<f32>, 512>;

@compute @workgroup_size(64)
fn wall_reduce(@builtin(local_invocation_index) lid: u32) {
    for (var half = 0u; half < 2u; half++) {
        reduce_half(lid, half * MAX_WALLS);
    }
    // Invocation 0 wrote the totals it reads.
    if (lid == 0u) {
        if (params.piston != NONE) {
            if (phase.kick > 0.0) {
                kick_piston(phase.kick);
            }
            move_piston(phase.then_kick, phase.drift);
        }
        move_walls(phase.drift);
    }
}

fn reduce_half(lid: u32, first: u32) {
    let row = 2u * MAX_WALLS;
    let rows = arrayLength(&wall_partials) / row;
    for (var w = 0u; w < MAX_WALLS; w++) {
        var s = vec4<f32>(0.0);
        for (var r = lid; r < rows; r += WG) {
            s = add_wall_row(s, wall_partials[r * row + first + w]);
        }
        acc[lid * MAX_WALLS + w] = s;
    }
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride /= 2u) {
        if (lid < stride) {
            for (var w = 0u; w < MAX_WALLS; w++) {
                acc[lid * MAX_WALLS + w] = add_wall_row(acc[lid * MAX_WALLS + w], acc[(lid + stride) * MAX_WALLS + w]);
            }
        }
        workgroupBarrier();
    }
    if (lid == 0u) {
        for (var w = 0u; w < MAX_WALLS; w++) {
            wall_reaction[first + w] = acc[w];
        }
    }
    workgroupBarrier();
}

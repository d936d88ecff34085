// One invocation reads the scanned pair count and writes the dispatch sizes of the per-pair
// kernels (dispatched directly, since it writes the indirect arguments; it does nothing on a
// step that does not rebuild). When the new list outgrows the pair buffers it stops the run
// instead: the flag raised, every dispatch size zeroed (the steps' own slots too) and nothing
// of the old list touched, so that the host can grow the buffers and go on from here, with the
// same bits as buffers that were large enough (src/gpu/engine/readback.rs, check).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_start: array<u32>;
@group(0) @binding(2) var<storage, read_write> control: Control;
@group(0) @binding(3) var<storage, read_write> args: array<DispatchArgs>;

@compute @workgroup_size(1)
fn pairs_ready() {
    if (control.rebuild == 0u || control.pair_overflow != 0u) {
        return;
    }
    let n = pair_start[params.n_grains];
    if (n > params.pair_capacity) {
        control.pair_overflow = 1u;
        for (var slot = 0u; slot < ARGS_SLOTS; slot++) {
            args[slot] = DispatchArgs(0u, 1u, 1u);
        }
        return;
    }
    control.n_pairs = n;
    args[ARGS_PAIRS] = groups_for(n);
    args[ARGS_NEW_PAIRS] = groups_for(n);
}

// One invocation reads the scanned pair count, flags a pair buffer overflow, and writes the
// dispatch sizes of the per-pair kernels (dispatched directly, since it writes the indirect
// arguments; it does nothing on a step that does not rebuild).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_start: array<u32>;
@group(0) @binding(2) var<storage, read_write> control: Control;
@group(0) @binding(3) var<storage, read_write> args: array<DispatchArgs>;

@compute @workgroup_size(1)
fn pairs_ready() {
    if (control.rebuild == 0u) {
        return;
    }
    var n = pair_start[params.n_grains];
    if (n > params.pair_capacity) {
        control.pair_overflow = 1u;
        n = params.pair_capacity;
    }
    control.n_pairs = n;
    args[ARGS_PAIRS] = groups_for(n);
    args[ARGS_NEW_PAIRS] = groups_for(n);
}

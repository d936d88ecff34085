// One invocation decides whether this step rebuilds the neighbour list (a grain moved half
// the skin since the last build, or the state went non-finite) and writes the dispatch sizes
// of the rebuild kernels accordingly (zero when not rebuilding). After a pair buffer overflow
// it does nothing, so that the steps stay stopped where the overflow left them.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> control: Control;
@group(0) @binding(2) var<storage, read_write> args: array<DispatchArgs>;

fn blocks(n: u32) -> DispatchArgs {
    return DispatchArgs((n + SCAN_BLOCK - 1u) / SCAN_BLOCK, 1u, 1u);
}

@compute @workgroup_size(1)
fn decide_rebuild() {
    if (control.pair_overflow != 0u) {
        return;
    }
    control.rebuild_checks += 1u;
    let d2 = bitcast<f32>(atomicExchange(&control.max_disp2, 0u));
    let half = 0.5 * params.skin;
    let rebuild = !(d2 < half * half);
    control.rebuild = select(0u, 1u, rebuild);
    let zero = DispatchArgs(0u, 1u, 1u);
    if (rebuild) {
        control.rebuilds += 1u;
        args[ARGS_GRAINS] = groups_for(params.n_grains);
        args[ARGS_HASH] = groups_for(params.hash_size);
        args[ARGS_HASH_BLOCKS] = blocks(params.hash_size);
        args[ARGS_GRAIN_BLOCKS] = blocks(params.n_grains + 1u);
        args[ARGS_ONE] = DispatchArgs(1u, 1u, 1u);
        args[ARGS_OLD_PAIRS] = args[ARGS_PAIRS];
        args[ARGS_GRAIN_STARTS] = groups_for(params.n_grains + 1u);
    } else {
        args[ARGS_GRAINS] = zero;
        args[ARGS_HASH] = zero;
        args[ARGS_HASH_BLOCKS] = zero;
        args[ARGS_GRAIN_BLOCKS] = zero;
        args[ARGS_ONE] = zero;
        args[ARGS_OLD_PAIRS] = zero;
        args[ARGS_NEW_PAIRS] = zero;
        args[ARGS_GRAIN_STARTS] = zero;
    }
}

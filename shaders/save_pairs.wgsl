// One invocation keeps one pair of the list being replaced: its partner and its history. They
// are kept where nothing reads between here and what rewrites them (`old_j` is `rev_pair`,
// which the rebuild's reverse lists rewrite; `old_hist0..2` are the pair force records
// `out_fi`, `out_tj`, `out_ti`, which the force evaluation after a rebuild rewrites: see
// `REBUILD_SCRATCH` in src/gpu/engine.rs), so the list being replaced costs no memory of its own.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pair_j: array<u32>;
@group(0) @binding(2) var<storage, read> hist: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> old_j: array<u32>;
// History block b of old pair k at old_hist<b>[k].
@group(0) @binding(4) var<storage, read_write> old_hist0: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> old_hist1: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> old_hist2: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> control: Control;

@compute @workgroup_size(64)
fn save_pairs(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = flat_index(wid, lid, nwg);
    if (k >= control.n_pairs) {
        return;
    }
    old_j[k] = pair_j[k];
    let blocks = params.hist_blocks;
    if (blocks > 0u) {
        old_hist0[k] = hist[k * blocks];
    }
    if (blocks > 1u) {
        old_hist1[k] = hist[k * blocks + 1u];
    }
    if (blocks > 2u) {
        old_hist2[k] = hist[k * blocks + 2u];
    }
}

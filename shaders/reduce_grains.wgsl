// One invocation adds one grain to its workgroup's statistics row: kinetic and gravitational
// energy, momentum, angular momentum, |net force| (all, and loaded grains), wall contacts, their
// elastic energy, its wall contacts sliding and rolling, whether it is a rattler and its
// kinetic energy if so, and the largest wall overlap.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> residual: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> vel: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> omega: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> force: array<vec4<f32>>; // w: pushing pairs and wall contacts' regimes (gather)
@group(0) @binding(6) var<storage, read> torque: array<vec4<f32>>; // w: |wall force|
@group(0) @binding(7) var<storage, read> image: array<vec4<i32>>;
@group(0) @binding(8) var<storage, read> material: array<u32>;
@group(0) @binding(9) var<storage, read> coeffs: array<PairCoeffs>;
@group(0) @binding(10) var<storage, read> walls: array<Wall>;
@group(0) @binding(11) var<storage, read_write> grain_rows: array<f32>;
@group(0) @binding(12) var<storage, read> meshes: array<MeshInfo>;
@group(0) @binding(13) var<storage, read> mesh_data: array<vec4<f32>>;
@group(0) @binding(14) var<storage, read> mesh_index: array<u32>;

var<workgroup> row: array<f32, WG * STAT_ROW>;

@compute @workgroup_size(64)
fn reduce_grains(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    clear_row(lid);
    var playing = false;
    if (i < params.n_grains) {
        playing = in_play(pos[i]);
    }
    if (playing) {
        let r = lid * STAT_ROW;
        let p = pos[i];
        let v = vel[i];
        let w = omega[i];
        var x = p.xyz;
        if (any(params.periodic_len.xyz > vec3<f32>(0.0))) {
            x += vec3<f32>(image[i].xyz) * params.periodic_len.xyz;
        }
        let mv = v.xyz * v.w;
        let l = cross(x, mv) + w.xyz * w.w;
        row[r + G_KE_T] = 0.5 * v.w * dot(v.xyz, v.xyz);
        row[r + G_KE_R] = 0.5 * w.w * dot(w.xyz, w.xyz);
        row[r + G_PE_G] = -v.w * dot(params.gravity.xyz, x);
        row[r + G_MOMENTUM] = mv.x;
        row[r + G_MOMENTUM + 1u] = mv.y;
        row[r + G_MOMENTUM + 2u] = mv.z;
        row[r + G_ANGULAR] = l.x;
        row[r + G_ANGULAR + 1u] = l.y;
        row[r + G_ANGULAR + 2u] = l.z;
        let counts = u32(force[i].w);
        row[r + G_WALL_FORCE] = torque[i].w;
        row[r + G_WALL_SLIDING] = count_field((counts / WALL_COUNTS_SLIDING) % (WALL_COUNTS_ROLLING / WALL_COUNTS_SLIDING));
        row[r + G_WALL_ROLLING] = count_field(counts / WALL_COUNTS_ROLLING);
        var contacts = f32(counts % WALL_COUNTS_SLIDING);
        var wall_contacts = 0u;
        for (var k = 0u; k < params.n_walls; k++) {
            // The overlaps with the wall: one, or one per contact with a mesh.
            var overlaps: array<f32, MESH_CONTACTS>;
            var touching = 0u;
            if ((walls[k].flags & WALL_ABSENT) != 0u) {
                continue;
            }
            if (walls[k].kind == WALL_MESH) {
                let t = mesh_touching(meshes[bitcast<u32>(walls[k].normal.x)], mesh_local(walls[k], p.xyz, residual[i]), p.w);
                for (var j = 0u; j < t.len; j++) {
                    overlaps[j] = p.w - t.dist[j];
                }
                touching = t.len;
            } else {
                overlaps[0] = p.w - wall_frame(walls[k], p.xyz, residual[i]).w;
                touching = select(0u, 1u, overlaps[0] > 0.0);
            }
            for (var j = 0u; j < touching; j++) {
                let h = overlaps[j];
                let c = coeffs[walls[k].material * params.n_materials + material[i]];
                contacts += 1.0;
                wall_contacts += 1u;
                row[r + G_WALL_ELASTIC] += normal_potential(c, p.w, h);
                if (h / p.w > row[r + STAT_MAX]) {
                    row[r + STAT_MAX] = h / p.w;
                    row[r + STAT_ARG] = bitcast<f32>(i);
                }
            }
        }
        // A rattler (fewer than RATTLER_CONTACTS contacts) is counted apart.
        row[r + G_WALL_CONTACTS] = count_field(wall_contacts);
        row[r + G_NET_FORCE] = length(force[i].xyz);
        if (contacts < f32(RATTLER_CONTACTS)) {
            row[r + G_RATTLERS] = count_field(1u);
            row[r + G_KE_RATTLERS] = row[r + G_KE_T];
        } else {
            row[r + G_NET_LOADED] = row[r + G_NET_FORCE];
        }
    }
    reduce_rows(lid, G_COUNTS);
    if (lid == 0u) {
        let out = (wid.y * nwg.x + wid.x) * STAT_ROW;
        for (var f = 0u; f < STAT_ROW; f++) {
            grain_rows[out + f] = row[f];
        }
    }
}

// One invocation sums the load on one grain in a fixed order: gravity, the pairs it owns, the
// pairs where it is partner, then its contacts with every wall (the grain-grain laws with an
// infinite partner; their springs advance here). No float atomics. Each workgroup sums the
// forces its grains put on each wall (row entries 0..MAX_WALLS: xyz force, w contacts as u32
// bits) and, for servo walls and spinning ones (WALL_RESPONSE), their contacts' normal tangent
// stiffness and damping coefficient and the power the walls' spin gives the grains (entries
// MAX_WALLS..: x N/m, y N s/m, z W), which wall_reduce totals. A wall moves at its surface
// velocity where the grain's centre projects onto it. A grain's contacts with a mesh wall add up
// in its row in their slots' order. For the
// statistics, force.w packs the grain's pairs that push (f_n > 0) with its wall contacts
// sliding and rolling (WALL_COUNTS_*), torque.w is the magnitude of its wall force. With
// phase.kick > 0 it then kicks the grain under that load: the kick after an evaluation, in the
// same dispatch (the piston's waits for wall_reduce). With phase.drift > 0 it runs the next
// step's first sweep too, carried into this one by a run of steps: a kick by phase.then_kick
// under the same load, then the drift (and the load is not stored: nothing reads it before the
// next evaluation). A partner's force is out_fj where the
// pair pass stores it (PARTNER_FORCE_STORED), else the owner's reversed: subtracting out_fi
// adds the same bits.
override PARTNER_FORCE_STORED: bool;
override WALL_RESPONSE: bool = false;
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<uniform> phase: Phase;
@group(0) @binding(2) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> omega: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> pair_start: array<u32>;
@group(0) @binding(5) var<storage, read> rev_start: array<u32>;
@group(0) @binding(6) var<storage, read> rev_pair: array<u32>;
@group(0) @binding(7) var<storage, read> out_fi: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> out_fj: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read> out_ti: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read> out_tj: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> residual: array<vec4<f32>>;
@group(0) @binding(13) var<storage, read> material: array<u32>;
@group(0) @binding(14) var<storage, read> coeffs: array<PairCoeffs>;
@group(0) @binding(15) var<storage, read> walls: array<Wall>;
@group(0) @binding(16) var<storage, read_write> wall_hist: array<vec4<f32>>;
@group(0) @binding(17) var<storage, read_write> wall_partials: array<vec4<f32>>;
@group(0) @binding(18) var<storage, read_write> force: array<vec4<f32>>;
@group(0) @binding(19) var<storage, read_write> torque: array<vec4<f32>>;
@group(0) @binding(20) var<storage, read> built_at: array<vec4<f32>>;
@group(0) @binding(21) var<storage, read_write> quat: array<vec4<f32>>;
@group(0) @binding(22) var<storage, read_write> control: Control;
@group(0) @binding(23) var<storage, read> meshes: array<MeshInfo>;
@group(0) @binding(24) var<storage, read> mesh_data: array<vec4<f32>>;
@group(0) @binding(25) var<storage, read> mesh_index: array<u32>;

var<workgroup> reaction: array<vec4<f32>, 512>; // WG x MAX_WALLS

// A grain's load from the walls and what the statistics count of it.
struct WallLoad {
    force: vec3<f32>,
    torque: vec3<f32>,
    sliding: u32,
    rolling: u32,
}

@compute @workgroup_size(64)
fn gather(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    let live = i < params.n_grains;
    // A grain out of play owns and partners no pair and feels no gravity and no wall.
    var playing = false;
    if (live) {
        playing = in_play(pos[i]);
    }
    var f = vec3<f32>(0.0);
    var t = vec3<f32>(0.0);
    var pushing = 0.0;
    if (playing) {
        f = params.gravity.xyz * vel[i].w;
        let end = min(pair_start[i + 1u], params.pair_capacity);
        for (var k = pair_start[i]; k < end; k++) {
            f += out_fi[k].xyz;
            t += out_ti[k].xyz;
            pushing += select(0.0, 1.0, out_fi[k].w > 0.0);
        }
        for (var s = rev_start[i]; s < rev_start[i + 1u]; s++) {
            let k = rev_pair[s];
            if (PARTNER_FORCE_STORED) {
                f += out_fj[k].xyz;
            } else {
                f -= out_fi[k].xyz;
            }
            t += out_tj[k].xyz;
            pushing += select(0.0, 1.0, out_fi[k].w > 0.0);
        }
    }
    var w = WallLoad(vec3<f32>(0.0), vec3<f32>(0.0), 0u, 0u);
    // (A uniform branch: every invocation of the workgroup reaches the reduction's barriers.)
    if (params.n_walls > 0u) {
        w = wall_loads(i, playing, lid, (wid.y * nwg.x + wid.x) * 2u * MAX_WALLS);
    }
    if (!live) {
        return;
    }
    let load = f + w.force;
    let moment = t + w.torque;
    // (A grain pushed by 65536 pairs or more counts 65535: the statistics only ask whether it
    // is a rattler.)
    let pushed = min(u32(pushing), WALL_COUNTS_SLIDING - 1u);
    let carries = phase.drift > 0.0;
    if (!carries) {
        force[i] = vec4<f32>(load, f32(pushed + w.sliding * WALL_COUNTS_SLIDING + w.rolling * WALL_COUNTS_ROLLING));
        torque[i] = vec4<f32>(moment, length(w.force));
    }
    if (phase.kick > 0.0) {
        kick_grain(i, load, moment, phase.kick);
    }
    if (carries) {
        kick_grain(i, load, moment, phase.then_kick);
        drift_grain(i, phase.drift);
    }
}

// Grain i's contacts with every wall (when live), their springs advanced; the workgroup's sums
// on each wall go to wall_partials[row..].
fn wall_loads(i: u32, live: bool, lid: u32, row: u32) -> WallLoad {
    var out = WallLoad(vec3<f32>(0.0), vec3<f32>(0.0), 0u, 0u);
    for (var w = 0u; w < MAX_WALLS; w++) {
        response[w] = vec3<f32>(0.0);
        reaction[lid * MAX_WALLS + w] = vec4<f32>(0.0);
    }
    if (live) {
        let p = pos[i];
        let v = vel[i];
        for (var w = 0u; w < params.n_walls; w++) {
            let wall = walls[w];
            let base = i * params.wall_blocks + wall.hist_at;
            if ((wall.flags & WALL_ABSENT) != 0u) {
                // Taken away: no contact, and its history forgotten.
                let blocks = select(params.hist_blocks, MESH_CONTACTS * (params.hist_blocks + 1u), wall.kind == WALL_MESH);
                for (var b = 0u; b < blocks; b++) { wall_hist[base + b] = vec4<f32>(0.0); }
                continue;
            }
            if (wall.kind == WALL_MESH) {
                mesh_loads(i, w, wall, base, lid, &out);
                continue;
            }
            let frame = wall_frame(wall, p.xyz, residual[i]);
            if (frame.w >= p.w) {
                for (var b = 0u; b < params.hist_blocks; b++) { wall_hist[base + b] = vec4<f32>(0.0); }
                // A contact that parted within the window may still pull: its force counts in
                // the wall's reaction, not in its contacts.
                let window = kick_window(phase.elapsed);
                if (ends_pull(window)) {
                    let g = geometry_grain_wall(frame.xyz, frame.w, p.w, v.w);
                    let f_n = parted_normal_force(coeffs[wall.material * params.n_materials + material[i]], g, dot(v.xyz - wall.velocity.xyz, g.n), window);
                    if (f_n != 0.0) {
                        let f_w = g.n * f_n;
                        out.force += f_w;
                        reaction[lid * MAX_WALLS + w] = vec4<f32>(-f_w, bitcast<f32>(0u));
                    }
                }
                continue;
            }
            wall_contact_at(i, w, wall, frame.xyz, frame.w, base, lid, true, &out);
        }
    }
    reduce_walls(lid, row);
    if (WALL_RESPONSE) {
        for (var w = 0u; w < MAX_WALLS; w++) {
            reaction[lid * MAX_WALLS + w] = vec4<f32>(response[w], 0.0);
        }
        reduce_walls(lid, row + MAX_WALLS);
    }
    return out;
}

// Each wall's response row of this invocation's grain (WALL_RESPONSE): its contacts' normal
// stiffness, damping and the spin's power.
var<private> response: array<vec3<f32>, MAX_WALLS>;

// Grain i's contact with wall w, along unit normal n from the wall at distance dist (m), its
// history at wall_hist[base..] advanced; its load added to `out`, its row to the wall's (set
// where `first`, the grain's first contact with the wall, added to otherwise).
fn wall_contact_at(i: u32, w: u32, wall: Wall, n: vec3<f32>, dist: f32, base: u32, lid: u32, first: bool, out: ptr<function, WallLoad>) {
    let p = pos[i];
    let v = vel[i];
    let om = omega[i];
    let g = geometry_grain_wall(n, dist, p.w, v.w);
    let surface = wall_velocity_at(wall, p.xyz - n * dist);
    let kin = Kinematics(v.xyz, surface, om.xyz, wall_spin(wall));
    let bodies = Bodies(v.w, om.w, 0.0, 0.0, true);
    let c = coeffs[wall.material * params.n_materials + material[i]];
    // Walls are not wetted: their contacts keep springs only.
    var blocks: array<vec4<f32>, MAX_HISTORY_BLOCKS>;
    for (var b = 0u; b < params.hist_blocks; b++) { blocks[b] = wall_hist[base + b]; }
    var h = history_of_blocks(blocks);
    let f = contact_force(c, g, kin, bodies, &h, phase.elapsed);
    blocks = blocks_of_history(h);
    for (var b = 0u; b < params.hist_blocks; b++) { wall_hist[base + b] = blocks[b]; }
    (*out).force += f.f_i;
    (*out).torque += f.t_i;
    let row = vec4<f32>(-f.f_i, bitcast<f32>(1u));
    if (first) {
        reaction[lid * MAX_WALLS + w] = row;
    } else {
        reaction[lid * MAX_WALLS + w] = add_wall_row(reaction[lid * MAX_WALLS + w], row);
    }
    (*out).sliding += select(0u, 1u, f.regime == REGIME_SLIDING);
    (*out).rolling += select(0u, 1u, f.regime == REGIME_ROLLING);
    if (WALL_RESPONSE) {
        var power = 0.0;
        if ((wall.flags & WALL_DRIVEN) != 0u && any(wall.drive.xyz != vec3<f32>(0.0))) {
            power = dot(f.f_i, surface - wall.velocity.xyz);
        }
        let r = vec3<f32>(normal_stiffness(c, g), normal_damping(c, g), power);
        if (first) {
            response[w] = r;
        } else {
            response[w] += r;
        }
    }
}

// Grain i's contacts with mesh wall w (mesh_touching), each in the slot of its history
// (mesh_assign) at wall_hist[base..]: slots of hist_blocks blocks and the normal's block.
// A grain touching the mesh at more places than it keeps stops the run (control.mesh_overflow).
fn mesh_loads(i: u32, w: u32, wall: Wall, base: u32, lid: u32, out: ptr<function, WallLoad>) {
    let p = pos[i];
    let m = meshes[bitcast<u32>(wall.normal.x)];
    var t = mesh_touching(m, mesh_local(wall, p.xyz, residual[i]), p.w);
    if (t.overflow) {
        atomicMin(&control.mesh_overflow, i);
        return;
    }
    if ((wall.flags & WALL_TURNS) != 0u) {
        for (var k = 0u; k < t.len; k++) {
            t.normal[k] = turn_apply(wall.turn, t.normal[k]);
        }
    }
    let size = params.hist_blocks + 1u;
    var last: array<vec3<f32>, MESH_CONTACTS>;
    for (var j = 0u; j < MESH_CONTACTS; j++) {
        last[j] = wall_hist[base + j * size + params.hist_blocks].xyz;
    }
    let uses = mesh_assign(t, last, bitcast<f32>(m.bases.w));
    var first = true;
    for (var j = 0u; j < MESH_CONTACTS; j++) {
        let at = base + j * size;
        if (uses[j] == MESH_SLOT_FREE || uses[j] >= MESH_SLOT_NEW) {
            for (var b = 0u; b < size; b++) { wall_hist[at + b] = vec4<f32>(0.0); }
        }
        if (uses[j] == MESH_SLOT_FREE) {
            continue;
        }
        let k = uses[j] % MESH_SLOT_NEW;
        wall_contact_at(i, w, wall, t.normal[k], t.dist[k], at, lid, first, out);
        wall_hist[at + params.hist_blocks] = vec4<f32>(t.normal[k], 0.0);
        first = false;
    }
}

// Sums `reaction` over the workgroup's lanes by a fixed-order tree into wall_partials[at..].
fn reduce_walls(lid: u32, at: u32) {
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride /= 2u) {
        if (lid < stride) {
            for (var w = 0u; w < MAX_WALLS; w++) {
                reaction[lid * MAX_WALLS + w] = add_wall_row(reaction[lid * MAX_WALLS + w], reaction[(lid + stride) * MAX_WALLS + w]);
            }
        }
        workgroupBarrier();
    }
    if (lid == 0u) {
        for (var w = 0u; w < MAX_WALLS; w++) {
            wall_partials[at + w] = reaction[w];
        }
    }
    workgroupBarrier();
}

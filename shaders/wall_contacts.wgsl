// One invocation computes one grain's contacts with every wall (the grain-grain laws with an
// infinite partner), and each workgroup sums the forces its grains put on each wall (row
// entries 0..MAX_WALLS: xyz force, w contacts as u32 bits) and, for servo walls (WALL_RESPONSE), their
// contacts' normal tangent stiffness and damping coefficient (entries MAX_WALLS..: x N/m,
// y N s/m). The w of wall_force and wall_torque count the grain's wall contacts sliding and
// rolling.
override WALL_RESPONSE: bool = false;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<uniform> phase: Phase;
@group(0) @binding(2) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> residual: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> vel: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> omega: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> material: array<u32>;
@group(0) @binding(7) var<storage, read> coeffs: array<PairCoeffs>;
@group(0) @binding(8) var<storage, read> walls: array<Wall>;
@group(0) @binding(9) var<storage, read_write> wall_hist: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> wall_force: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> wall_torque: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> wall_partials: array<vec4<f32>>;

var<workgroup> reaction: array<vec4<f32>, 512>; // WG x MAX_WALLS

@compute @workgroup_size(64)
fn wall_contacts(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(wid, lid, nwg);
    let live = i < params.n_grains;
    var force = vec3<f32>(0.0);
    var torque = vec3<f32>(0.0);
    var sliding = 0.0;
    var rolling = 0.0;
    var response: array<vec2<f32>, MAX_WALLS>;
    for (var w = 0u; w < MAX_WALLS; w++) {
        response[w] = vec2<f32>(0.0);
        reaction[lid * MAX_WALLS + w] = vec4<f32>(0.0);
    }
    if (live) {
        let p = pos[i];
        let v = vel[i];
        let om = omega[i];
        for (var w = 0u; w < params.n_walls; w++) {
            let wall = walls[w];
            let base = (i * params.n_walls + w) * params.hist_blocks;
            let frame = wall_frame(wall, p.xyz, residual[i]);
            if (frame.w >= p.w) {
                for (var b = 0u; b < params.hist_blocks; b++) { wall_hist[base + b] = vec4<f32>(0.0); }
                continue;
            }
            let g = geometry_grain_wall(frame.xyz, frame.w, p.w, v.w);
            let kin = Kinematics(v.xyz, wall.velocity.xyz, om.xyz, vec3<f32>(0.0));
            let bodies = Bodies(v.w, om.w, 0.0, 0.0, true);
            let c = coeffs[wall.material * params.n_materials + material[i]];
            // Walls are not wetted: their contacts keep springs only.
            var h = empty_history();
            var b = base;
            if (HAS_TANGENTIAL_HISTORY) { h.tangential = wall_hist[b].xyz; h.sliding = wall_hist[b].w != 0.0; b += 1u; }
            if (HAS_ROLLING_HISTORY) { h.rolling = wall_hist[b].xyz; }
            let f = contact_force(c, g, kin, bodies, &h, phase.elapsed);
            b = base;
            if (HAS_TANGENTIAL_HISTORY) { wall_hist[b] = vec4<f32>(h.tangential, select(0.0, 1.0, h.sliding)); b += 1u; }
            if (HAS_ROLLING_HISTORY) { wall_hist[b] = vec4<f32>(h.rolling, 0.0); }
            force += f.f_i;
            torque += f.t_i;
            reaction[lid * MAX_WALLS + w] = vec4<f32>(-f.f_i, bitcast<f32>(1u));
            sliding += select(0.0, 1.0, f.regime == REGIME_SLIDING);
            rolling += select(0.0, 1.0, f.regime == REGIME_ROLLING);
            if (WALL_RESPONSE) {
                response[w] = vec2<f32>(normal_stiffness(c, g), normal_damping(c, g));
            }
        }
        wall_force[i] = vec4<f32>(force, sliding);
        wall_torque[i] = vec4<f32>(torque, rolling);
    }
    let row = (wid.y * nwg.x + wid.x) * 2u * MAX_WALLS;
    reduce_walls(lid, row);
    if (WALL_RESPONSE) {
        for (var w = 0u; w < MAX_WALLS; w++) {
            reaction[lid * MAX_WALLS + w] = vec4<f32>(response[w], 0.0, 0.0);
        }
        reduce_walls(lid, row + MAX_WALLS);
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

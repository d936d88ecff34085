// The cohesion slot, the WGSL twin of src/model/cohesion/: capillary bridges (capillary.rs,
// Richefeu et al. (2009)); the constants in params.cohesion. A law's code is COHESION_<NAME>,
// written from the slot's registry.

// What update_bridges does at a pair (find_bridge_events marks it): its bridge ruptures, or
// it touches without one and one forms if its grains hold liquid.
const BRIDGE_RUPTURE: u32 = 1u;
const BRIDGE_TOUCH: u32 = 2u;

// Capillary bridges (src/model/cohesion/capillary.rs): whether the gap delta (m) lies within the
// rupture distance (1 + theta/2) V^(1/3) (m), tested on the cubes as the CPU does.
fn within_rupture(v_b: f32, delta: f32) -> bool {
    let k = 1.0 + params.cohesion.y * 0.5;
    return delta <= 0.0 || delta * delta * delta <= k * k * k * v_b;
}

// Decay length of the capillary force across the gap (m), Richefeu et al. (2009) eq. 8.
fn decay_length(r_i: f32, r_j: f32, v_b: f32) -> f32 {
    let ratio = max(r_i / r_j, r_j / r_i);
    return params.cohesion.z * 0.70710678118654752 * sqrt((1.0 / r_i + 1.0 / r_j) / ratio * v_b);
}

// Capillary normal force (N, tensile negative) of a bridge of volume v_b at gap delta (m).
fn capillary_force(r_i: f32, r_j: f32, v_b: f32, delta: f32) -> f32 {
    if (v_b <= 0.0) {
        return 0.0;
    }
    let f0 = -params.cohesion.x * sqrt(r_i * r_j);
    if (delta < 0.0) {
        return f0;
    }
    if (within_rupture(v_b, delta)) {
        return f0 * exp(-(delta / decay_length(r_i, r_j, v_b)));
    }
    return 0.0;
}

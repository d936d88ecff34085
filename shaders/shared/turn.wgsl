// Turning bodies: unit quaternions, scalar first (x = scalar), each the rotation from a
// body's rest frame to the world (a grain's orientation, a turning wall's); the CPU's
// src/turn.rs, operation for operation.

// q + (tau/2 (0, w) * q - 2 a q) / (1 + a), a = tau^2 |w|^2 / 16: Omelyan's norm-preserving
// rotation by the world-frame angular velocity w over tau.
fn rotate(q: vec4<f32>, w: vec3<f32>, tau: f32) -> vec4<f32> {
    let a = tau * tau * dot(w, w) / 16.0;
    let h = 0.5 * tau;
    let qv = q.yzw;
    let s = -dot(w, qv);
    let v = w * q.x + cross(w, qv);
    let inv = 1.0 / (1.0 + a);
    return q + (h * vec4<f32>(s, v) - 2.0 * a * q) * inv;
}

// The rest frame's vector v turned into the world by q: v + s t + u x t, t = 2 u x v.
fn turn_apply(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let t = cross(q.yzw, v) * 2.0;
    return v + t * q.x + cross(q.yzw, t);
}

// The world's vector v in the rest frame (turn_apply with the inverse rotation).
fn turn_unapply(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    return turn_apply(vec4<f32>(q.x, -q.yzw), v);
}

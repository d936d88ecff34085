//! Turning bodies: unit quaternions, scalar first, `[s, x, y, z]`, each the rotation from a
//! body's rest frame to the world (a grain's orientation, a turning wall's). The same
//! arithmetic as WGSL `shaders/shared/turn.wgsl`, operation for operation, so that the CPU's
//! f32 and the GPU agree to the bit.

use crate::real::{Real, Vec3};

/// The rotation that turns nothing.
pub fn identity<T: Real>() -> [T; 4] {
    [T::ONE, T::ZERO, T::ZERO, T::ZERO]
}

/// Omelyan's norm-preserving rotation of a unit quaternion (scalar first) by the world-frame
/// angular velocity `w` over `tau` (Oquendo et al. eqs. 16-18):
/// `q' = ((1 - a) q + tau/2 (0, w) * q) / (1 + a)`, `a = tau^2 |w|^2 / 16`, a rotation by
/// `4 atan(tau |w| / 4)` about `w`. The body-frame form of eq. 18, `Q(w_b) q`, equals
/// `1/2 (0, w) * q` because `w = q w_b q*`. It is evaluated as `q + (tau/2 (0, w) * q - 2 a q) / (1 + a)`
/// so that rounding touches only the small increment: the norm then drifts by about 1e-19
/// per step in f64 instead of 1e-16.
#[inline(always)]
pub fn rotate<T: Real>(q: [T; 4], w: Vec3<T>, tau: T) -> [T; 4] {
    let a = tau * tau * w.norm2() / T::of(16.0);
    let h = tau * T::of(0.5);
    let qv = Vec3::new(q[1], q[2], q[3]);
    // (0, w) * (q0, qv) = (-w.qv, q0 w + w x qv)
    let s = -w.dot(qv);
    let v = w * q[0] + w.cross(qv);
    let inv = T::ONE / (T::ONE + a);
    let two_a = T::of(2.0) * a;
    [
        q[0] + (h * s - two_a * q[0]) * inv,
        q[1] + (h * v.x - two_a * q[1]) * inv,
        q[2] + (h * v.y - two_a * q[2]) * inv,
        q[3] + (h * v.z - two_a * q[3]) * inv,
    ]
}

/// The vector `v` of the rest frame turned into the world by the unit quaternion `q`:
/// `v + s t + u x t`, `t = 2 u x v` (`q = (s, u)`).
#[inline(always)]
pub fn apply<T: Real>(q: [T; 4], v: Vec3<T>) -> Vec3<T> {
    let u = Vec3::new(q[1], q[2], q[3]);
    let t = u.cross(v) * T::of(2.0);
    v + t * q[0] + u.cross(t)
}

/// The world's vector `v` in the rest frame: [`apply`] with the inverse rotation.
#[inline(always)]
pub fn unapply<T: Real>(q: [T; 4], v: Vec3<T>) -> Vec3<T> {
    apply([q[0], -q[1], -q[2], -q[3]], v)
}

/// A bound on how far the rotation `q` carries a point at distance 1 from its centre, compared
/// with `before` (both unit): `|R(q) - R(before)| = 2 sin(theta / 2) <= 2 |q -+ before|`,
/// theta the angle between the two, the sign taken that makes the difference shortest.
pub fn chord<T: Real>(q: [T; 4], before: [T; 4]) -> T {
    let diff = |sign: T| (0..4).map(|k| (q[k] - sign * before[k]) * (q[k] - sign * before[k])).fold(T::ZERO, |a, b| a + b).sqrt();
    T::of(2.0) * diff(T::ONE).min(diff(-T::ONE))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quarter turn about z takes x to y, and back.
    #[test]
    fn quarter_turn() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let q = [h, 0.0, 0.0, h];
        let y = apply(q, Vec3::new(1.0, 0.0, 0.0));
        assert!((y - Vec3::new(0.0, 1.0, 0.0)).norm() < 1e-15, "{y:?}");
        let x = unapply(q, y);
        assert!((x - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-15, "{x:?}");
        // Turned by 90 degrees: a point at distance 1 moves by sqrt(2) <= the chord's bound.
        let c = chord(q, identity());
        assert!(c >= 2f64.sqrt() && c < 2.0 * 2f64.sqrt(), "{c}");
    }
}

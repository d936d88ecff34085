//! `integrate`: kicks (velocity updates) and drifts (position and orientation updates) of
//! one grain. Velocity Verlet and Oquendo et al.'s optimised velocity Verlet are sequences of these.

use super::built_at;
use crate::state::{Body, Load, Props};
use crate::position;
use crate::real::{Real, Vec3};

/// Kick: `v += F/m tau`, `w += T/I tau` (spheres: the inertia is isotropic, so the world-frame
/// torque needs no body-frame transform).
#[inline(always)]
pub fn kick<T: Real>(b: &mut Body<T>, l: &Load<T>, p: &Props<T>, tau: T) {
    b.vel += l.force * (tau / p.mass);
    b.omega += l.torque * (tau / p.inertia);
}

/// Drift: `x += v tau`, the sum's rounding kept in `residual` where positions are compensated
/// ([`position::advance`]). Returns the squared displacement of `pos` since the last neighbour
/// build, as kept ([`built_at::moved2`]).
#[inline(always)]
pub fn drift<T: Real>(b: &mut Body<T>, residual: &mut Vec3<T>, built_at: Vec3<f32>, tau: T) -> T {
    position::advance(&mut b.pos, residual, b.vel * tau);
    built_at::moved2(b.pos, built_at)
}

super::simd::dispatch! {
    /// A chunk of grains each [`kick`]ed by `kick` (s) when given, then [`drift`]ed by `tau`
    /// (s); `residual` is empty unless positions are compensated. Returns the largest squared
    /// displacement since the last neighbour build.
    pub fn kick_drift<T: Real>(body: &mut [Body<T>], residual: &mut [Vec3<T>], built_at: &[Vec3<f32>], load: &[Load<T>], prop: &[Props<T>], kick_by: Option<T>, tau: T) -> T => kick_drift_portable
}

/// [`kick_drift`] for whatever instruction set the caller is compiled for.
#[inline(always)]
fn kick_drift_portable<T: Real>(body: &mut [Body<T>], residual: &mut [Vec3<T>], built_at: &[Vec3<f32>], load: &[Load<T>], prop: &[Props<T>], kick_by: Option<T>, tau: T) -> T {
    let mut moved = T::ZERO;
    for (m, ((b, l), p)) in body.iter_mut().zip(load).zip(prop).enumerate() {
        if let Some(k) = kick_by {
            kick(b, l, p, k);
        }
        let mut none = Vec3::ZERO;
        let r = if T::COMPENSATED { &mut residual[m] } else { &mut none };
        moved = moved.max(drift(b, r, built_at[m], tau));
    }
    moved
}


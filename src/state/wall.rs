//! A grain's contact with a wall, the same laws as grain-grain contacts with the wall as a
//! partner of infinite radius and mass: the CPU's `wall_contacts` pass evaluates it per grain,
//! and the GPU engine's reports re-evaluate it on the host from the state it reads back.

use super::{Body, ForceContext, Props};
use crate::engine::WallContactRecord;
use crate::model::{contact_force, Bodies, ContactForce, Geometry, KickWindow, Kinematics, PairCoeffs};
use crate::real::{Real, Vec3};
use crate::walls::WallGeom;

/// A wall as the force pass sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallState<T> {
    /// Surface now.
    pub geom: WallGeom<T>,
    /// Velocity (m/s).
    pub velocity: Vec3<T>,
    /// Angular velocity (rad/s) about its axis of symmetry through [`WallGeom::centre`]; zero
    /// but for a driven wall that spins (`crate::scene::WallDrive`).
    pub spin: Vec3<T>,
    /// Material index.
    pub material: u32,
}

impl<T: Real> WallState<T> {
    /// The velocity (m/s) of the wall's surface at `x` (m): its velocity, plus `spin x (x -
    /// centre)` where it spins.
    #[inline(always)]
    pub fn velocity_at(&self, x: Vec3<T>) -> Vec3<T> {
        if self.spin == Vec3::ZERO { self.velocity } else { self.velocity + self.spin.cross(x - self.geom.centre()) }
    }
}

/// The contact of a grain of material `material` with a wall it touches, seen from the wall's
/// frame (`n`, `dist`: [`WallGeom::frame`]): its geometry, coefficients and force; the history
/// in `h_slot` advances by `ctx.elapsed`. The wall moves at its surface velocity where the
/// grain's centre projects onto it ([`WallState::velocity_at`]) and turns at its spin.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn wall_contact<'c, T: Real>(n: Vec3<T>, dist: T, b: &Body<T>, p: &Props<T>, material: usize, wall: &WallState<T>, ctx: &ForceContext<'c, T>, h_slot: &mut [T]) -> (Geometry<T>, &'c PairCoeffs<T>, ContactForce<T>) {
    let geo = Geometry::grain_wall(n, dist, p.radius, p.mass);
    // The wall's surface velocity where the grain's centre projects onto it.
    let kin = Kinematics { v_i: b.vel, v_j: wall.velocity_at(b.pos - n * dist), w_i: b.omega, w_j: wall.spin };
    let bodies = Bodies { m_i: p.mass, inertia_i: p.inertia, j_is_wall: true, ..Default::default() };
    let c = ctx.wall_coeffs(wall.material, material);
    let mut h = ctx.slots.load(h_slot);
    let f = contact_force(ctx.model, c, &geo, &kin, &bodies, &mut h, ctx.elapsed, KickWindow::centred(ctx.window));
    ctx.slots.store(&h, h_slot);
    (geo, c, f)
}

/// Every touching grain-wall contact, with its force evaluated from the current state
/// (springs read, not advanced: `ctx.elapsed` should be 0), grains in permanent-id order,
/// walls in order.
pub fn wall_contact_records<T: Real>(body: &[Body<T>], prop: &[Props<T>], id: &[u32], walls: &[WallState<T>], ctx: &ForceContext<T>, hist: &[T]) -> Vec<WallContactRecord> {
    let stride = ctx.slots.stride;
    let mut out = Vec::new();
    for (i, (b, p)) in body.iter().zip(prop).enumerate() {
        for (w, wall) in walls.iter().enumerate() {
            let (n, dist) = wall.geom.frame(b.pos, crate::position::residual_at(ctx.residual, i));
            if dist >= p.radius {
                continue;
            }
            let at = (i * walls.len() + w) * stride;
            let (geo, _, f) = wall_contact(n, dist, b, p, ctx.material(i), wall, ctx, &mut hist[at..at + stride].to_vec());
            out.push(WallContactRecord { grain: id[i], wall: w as u32, overlap: geo.h.f64(), normal: n.f64(), lever: geo.rp_i.f64(), force: f.f_i.f64() });
        }
    }
    out.sort_by_key(|r| r.grain);
    out
}

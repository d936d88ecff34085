//! A grain's contact with a wall, the same laws as grain-grain contacts with the wall as a
//! partner of infinite radius and mass: the CPU's `wall_contacts` pass evaluates it per grain,
//! and the GPU engine's reports re-evaluate it on the host from the state it reads back.

use super::{Body, ForceContext, Props};
use crate::engine::WallContactRecord;
use crate::mesh::slots::{assign, mesh_reals, slot_reals, SlotUse};
use crate::mesh::{MeshSurface, MESH_CONTACTS};
use crate::model::{contact_force, Bodies, ContactForce, Geometry, KickWindow, Kinematics, PairCoeffs};
use crate::real::{Real, Vec3};
use crate::walls::{MeshPose, WallGeom};

/// A wall as the force pass sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallState<T> {
    /// Surface now.
    pub geom: WallGeom<T>,
    /// Velocity (m/s).
    pub velocity: Vec3<T>,
    /// Angular velocity (rad/s) about the axis through [`WallGeom::pivot`]; zero but for a
    /// driven wall that spins (`crate::scene::WallDrive`).
    pub spin: Vec3<T>,
    /// Whether the spin turns the surface ([`WallGeom::turned`]): on from the first drive
    /// that turns it ([`crate::walls::turns_with`]).
    pub turns: bool,
    /// Material index.
    pub material: u32,
    /// False while a stage has taken the wall away: it touches no grain (and keeps moving).
    pub present: bool,
}

impl<T: Real> WallState<T> {
    /// The velocity (m/s) of the wall's surface at `x` (m): its velocity, plus `spin x (x -
    /// pivot)` where it spins.
    #[inline(always)]
    pub fn velocity_at(&self, x: Vec3<T>) -> Vec3<T> {
        if self.spin == Vec3::ZERO { self.velocity } else { self.velocity + self.spin.cross(x - self.geom.pivot()) }
    }

    /// Takes a drive (m/s, rad/s): a spin that turns the wall turns it from now on.
    pub fn drive(&mut self, velocity: Vec3<T>, spin: Vec3<T>, turns: bool) {
        (self.velocity, self.spin) = (velocity, spin);
        if turns && !self.turns {
            self.turns = true;
            if let WallGeom::Mesh { pose, .. } = &mut self.geom {
                pose.turn = Some(crate::turn::identity());
            }
        }
    }
}

/// The overlaps (m) of a grain of `radius` at `x` (residual `r`) with `wall`: at most one with
/// a wall of one contact, one per contact with a mesh (`meshes`); the count is the second.
pub fn wall_overlaps<T: Real>(wall: &WallState<T>, meshes: &[MeshSurface<T>], x: Vec3<T>, r: Vec3<T>, radius: T) -> ([T; MESH_CONTACTS], usize) {
    let mut out = [T::ZERO; MESH_CONTACTS];
    if !wall.present {
        return (out, 0);
    }
    if let WallGeom::Mesh { mesh, pose } = wall.geom {
        let t = meshes[mesh as usize].touching(pose.local(x, r), radius);
        for (o, c) in out.iter_mut().zip(&t.contacts[..t.len]) {
            *o = radius - c.dist;
        }
        return (out, t.len);
    }
    out[0] = radius - wall.geom.frame(x, r).1;
    (out, (out[0] > T::ZERO) as usize)
}

/// The contact of a grain of material `material` with a wall it touches, seen from the wall's
/// frame (`n`, `dist`: [`WallGeom::frame`]): its geometry, coefficients, force, and the power
/// (W) of the wall's spin through it (`f . (surface - velocity)`, zero where it does not
/// spin); the history in `h_slot` advances by `ctx.elapsed`. The wall moves at its surface
/// velocity where the grain's centre projects onto it ([`WallState::velocity_at`]) and turns
/// at its spin.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn wall_contact<'c, T: Real>(n: Vec3<T>, dist: T, b: &Body<T>, p: &Props<T>, material: usize, wall: &WallState<T>, ctx: &ForceContext<'c, T>, h_slot: &mut [T]) -> (Geometry<T>, &'c PairCoeffs<T>, ContactForce<T>, T) {
    let geo = Geometry::grain_wall(n, dist, p.radius, p.mass);
    // The wall's surface velocity where the grain's centre projects onto it.
    let kin = Kinematics { v_i: b.vel, v_j: wall.velocity_at(b.pos - n * dist), w_i: b.omega, w_j: wall.spin };
    let bodies = Bodies { m_i: p.mass, inertia_i: p.inertia, j_is_wall: true, ..Default::default() };
    let c = ctx.wall_coeffs(wall.material, material);
    let mut h = ctx.slots.load(h_slot);
    let f = contact_force(ctx.model, c, &geo, &kin, &bodies, &mut h, ctx.elapsed, KickWindow::centred(ctx.window));
    ctx.slots.store(&h, h_slot);
    let power = if wall.spin == Vec3::ZERO { T::ZERO } else { f.f_i.dot(kin.v_j - wall.velocity) };
    (geo, c, f, power)
}

/// Reals of wall history a grain keeps for `wall`: `stride` for a wall of one contact,
/// [`MESH_CONTACTS`] slots of history and normal for a mesh ([`crate::mesh::slots`]).
#[inline(always)]
pub fn wall_reals<T>(wall: &WallState<T>, stride: usize) -> usize {
    if matches!(wall.geom, WallGeom::Mesh { .. }) { mesh_reals(stride) } else { stride }
}

/// Reals of wall history a grain keeps for all of `walls`, one block after another.
pub fn walls_reals<T>(walls: &[WallState<T>], stride: usize) -> usize {
    walls.iter().map(|w| wall_reals(w, stride)).sum()
}

/// The contacts of a grain (its body `b` with position residual `residual`) with mesh wall
/// `wall` (`surface`, where `pose` puts it): each one's slot in `block` ([`wall_reals`]) is
/// chosen ([`assign`]), its history advanced and its normal kept, and `each` is given its
/// normal, geometry, coefficients, force and spin's power ([`wall_contact`]); slots left
/// without a contact are cleared. False
/// when the grain touches the mesh at more places than it has slots
/// ([`MeshSurface::touching`]); its contacts are then not evaluated.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn mesh_contacts<'c, T: Real>(
    b: &Body<T>,
    residual: Vec3<T>,
    p: &Props<T>,
    material: usize,
    wall: &WallState<T>,
    surface: &MeshSurface<T>,
    pose: &MeshPose<T>,
    ctx: &ForceContext<'c, T>,
    block: &mut [T],
    mut each: impl FnMut(Vec3<T>, &Geometry<T>, &'c PairCoeffs<T>, &ContactForce<T>, T),
) -> bool {
    let mut touches = surface.touching(pose.local(b.pos, residual), p.radius);
    if touches.overflow {
        return false;
    }
    for c in &mut touches.contacts[..touches.len] {
        c.normal = pose.world_direction(c.normal);
    }
    let (stride, size) = (ctx.slots.stride, slot_reals(ctx.slots.stride));
    let last: [Vec3<T>; MESH_CONTACTS] = std::array::from_fn(|j| {
        let n = &block[j * size + stride..(j + 1) * size];
        Vec3::new(n[0], n[1], n[2])
    });
    let uses = assign(&touches.contacts[..touches.len], &last, surface.merge_cos);
    for (j, u) in uses.into_iter().enumerate() {
        let slot = &mut block[j * size..(j + 1) * size];
        let k = match u {
            SlotUse::Free => {
                slot.fill(T::ZERO);
                continue;
            }
            SlotUse::New(k) => {
                slot.fill(T::ZERO);
                k
            }
            SlotUse::Carried(k) => k,
        };
        let c = touches.contacts[k];
        let (geo, coeffs, f, power) = wall_contact(c.normal, c.dist, b, p, material, wall, ctx, &mut slot[..stride]);
        slot[stride..].copy_from_slice(&[c.normal.x, c.normal.y, c.normal.z]);
        each(c.normal, &geo, coeffs, &f, power);
    }
    true
}

/// Every touching grain-wall contact, with its force evaluated from the current state
/// (springs read, not advanced: `ctx.elapsed` should be 0), grains in permanent-id order,
/// walls in order.
pub fn wall_contact_records<T: Real>(body: &[Body<T>], prop: &[Props<T>], id: &[u32], walls: &[WallState<T>], ctx: &ForceContext<T>, hist: &[T]) -> Vec<WallContactRecord> {
    let stride = ctx.slots.stride;
    let per_grain = walls_reals(walls, stride);
    let mut out = Vec::new();
    for (i, (b, p)) in body.iter().zip(prop).enumerate() {
        let residual = crate::position::residual_at(ctx.residual, i);
        let mut at = i * per_grain;
        for (w, wall) in walls.iter().enumerate() {
            let block = &hist[at..at + wall_reals(wall, stride)];
            at += block.len();
            if !wall.present {
                continue;
            }
            let record = |n: Vec3<T>, geo: &Geometry<T>, f: &ContactForce<T>| WallContactRecord { grain: id[i], wall: w as u32, overlap: geo.h.f64(), normal: n.f64(), lever: geo.rp_i.f64(), force: f.f_i.f64() };
            if let WallGeom::Mesh { mesh, pose } = wall.geom {
                mesh_contacts(b, residual, p, ctx.material(i), wall, &ctx.meshes[mesh as usize], &pose, ctx, &mut block.to_vec(), |n, geo, _, f, _| out.push(record(n, geo, f)));
                continue;
            }
            let (n, dist) = wall.geom.frame(b.pos, residual);
            if dist >= p.radius {
                continue;
            }
            let (geo, _, f, _) = wall_contact(n, dist, b, p, ctx.material(i), wall, ctx, &mut block.to_vec());
            out.push(record(n, &geo, &f));
        }
    }
    out.sort_by_key(|r| r.grain);
    out
}

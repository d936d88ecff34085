//! `wall_contacts`: one invocation computes the contacts of one grain with every wall, with
//! the same laws as grain-grain contacts (the wall is a partner of infinite radius and mass).

use super::wall_springs::is_candidate;
use crate::state::{mesh_contacts, wall_contact, wall_reals, Body, ForceContext, Load, Props, WallState};
use crate::walls::WallGeom;
use crate::model::{normal_damping, parted_normal_force, ContactForce, Geometry, NormalModel, PairCoeffs, Regime};
use crate::real::{Real, Vec3};

/// What one grain-wall contact adds to its wall's sums.
#[derive(Clone, Copy, Debug)]
pub struct WallTouch<T> {
    /// The grain's permanent id.
    pub grain: u32,
    /// The wall's index.
    pub wall: u32,
    /// Force on the grain (N); the wall receives its opposite.
    pub force: Vec3<T>,
    /// Normal tangent stiffness (N/m).
    pub stiffness: T,
    /// Normal damping coefficient (N s/m).
    pub damping: T,
    /// Power (W) the wall's spin gives the grain: the force on the grain dotted with the spin's
    /// part of the surface velocity at the contact (zero unless the wall spins).
    pub power: T,
    /// Tangential regime.
    pub regime: Regime,
    /// False for a contact that parted within the window and still pulls
    /// ([`parted_normal_force`]): its force counts in the wall's reaction, not in its
    /// touching grains, stiffness, damping or regimes.
    pub touching: bool,
}

impl<T: Real> WallTouch<T> {
    /// The touching contact of grain `id` with wall `w` whose force is `f`, with its geometry
    /// `geo`, coefficients `c` and the spin's `power` (W).
    #[inline(always)]
    fn touching(id: u32, w: usize, f: &ContactForce<T>, ctx: &ForceContext<T>, c: &PairCoeffs<T>, geo: &Geometry<T>, power: T) -> Self {
        WallTouch {
            grain: id,
            wall: w as u32,
            force: f.f_i,
            stiffness: ctx.model.normal.stiffness(c, geo),
            damping: normal_damping(&ctx.model.damping, &ctx.model.normal, c, geo),
            power,
            regime: f.regime,
            touching: true,
        }
    }
}

impl<T> WallTouch<T> {
    /// The regime's code, plus [`Self::PARTED`] where the contact no longer touches: how
    /// checkpoints and the distributed engine's rows carry both.
    pub fn code(&self) -> u8 {
        self.regime as u8 | if self.touching { 0 } else { Self::PARTED }
    }

    /// The regime and whether the contact touches, from [`Self::code`].
    pub fn of_code(code: u8) -> (Regime, bool) {
        (Regime::from_code(code & !Self::PARTED), code & Self::PARTED == 0)
    }

    /// The code's mark of a contact that no longer touches.
    const PARTED: u8 = 8;
}

/// `wall_contacts` for the grain of permanent id `id` and material `material`. `hist` holds
/// the grain's history blocks, one after another ([`wall_reals`] each); each touching wall's
/// contacts are appended to `touches`. Returns the load on the grain. A grain that touches a
/// mesh at more places than it has slots sets `overflow` to its id.
#[inline(always)]
pub fn wall_contacts<T: Real>(
    id: u32,
    b: &Body<T>,
    residual: Vec3<T>,
    p: &Props<T>,
    material: usize,
    walls: &[WallState<T>],
    ctx: &ForceContext<T>,
    hist: &mut [T],
    touches: &mut Vec<WallTouch<T>>,
    overflow: &mut Option<u32>,
) -> Load<T> {
    let mut load = Load::default();
    let stride = ctx.slots.stride;
    let mut at = 0;
    for (w, wall) in walls.iter().enumerate() {
        let h_slot = &mut hist[at..at + wall_reals(wall, stride)];
        at += h_slot.len();
        if !wall.present {
            h_slot.fill(T::ZERO);
            continue;
        }
        if let WallGeom::Mesh { mesh, pose } = wall.geom {
            let touched = mesh_contacts(b, residual, p, material, wall, &ctx.meshes[mesh as usize], &pose, ctx, h_slot, |_, geo, c, f, power| {
                load.force += f.f_i;
                load.torque += f.t_i;
                touches.push(WallTouch::touching(id, w, f, ctx, c, geo, power));
            });
            if !touched {
                *overflow = Some(id);
            }
            continue;
        }
        let (n, dist) = wall.geom.frame(b.pos, residual);
        if dist >= p.radius {
            ctx.slots.clear_springs(h_slot);
            if ctx.ends_pull() {
                let geo = Geometry::grain_wall(n, dist, p.radius, p.mass);
                let f_n = parted_normal_force(ctx.model, ctx.wall_coeffs(wall.material, material), &geo, (b.vel - wall.velocity).dot(n), ctx.window);
                if f_n != T::ZERO {
                    load.force += n * f_n;
                    touches.push(WallTouch { grain: id, wall: w as u32, force: n * f_n, stiffness: T::ZERO, damping: T::ZERO, power: T::ZERO, regime: Regime::Static, touching: false });
                }
            }
            continue;
        }
        let (geo, c, f, power) = wall_contact(n, dist, b, p, material, wall, ctx, h_slot);
        load.force += f.f_i;
        load.torque += f.t_i;
        touches.push(WallTouch::touching(id, w, &f, ctx, c, &geo, power));
    }
    load
}

super::simd::dispatch! {
    /// `wall_contacts` for the candidates among slots `first..first + loads.len()` (at most
    /// one part of [`split::split`](super::split::split); `id`, `body`, `residual` (empty
    /// unless positions are compensated) and `prop` are theirs alone, `candidate` the
    /// candidate bits from `first`, a multiple of [`ALIGN`](super::split::ALIGN), on): each
    /// one's wall load (zero without a contact) is added to its load; `springs` holds their
    /// entries' history blocks in slot order (empty when the model keeps none); the contacts
    /// are appended to `touches`; `overflow` as [`wall_contacts`]'. A grain that is not a
    /// candidate can touch no wall ([`super::wall_springs`]).
    pub fn wall_block<T: Real>(first: usize, loads: &mut [Load<T>], candidate: &[u64], springs: &mut [T], id: &[u32], body: &[Body<T>], residual: &[Vec3<T>], prop: &[Props<T>], walls: &[WallState<T>], ctx: &ForceContext<T>, touches: &mut Vec<WallTouch<T>>, overflow: &mut Option<u32>) => wall_block_portable
}

/// [`wall_block`] for whatever instruction set the caller is compiled for.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn wall_block_portable<T: Real>(first: usize, loads: &mut [Load<T>], candidate: &[u64], springs: &mut [T], id: &[u32], body: &[Body<T>], residual: &[Vec3<T>], prop: &[Props<T>], walls: &[WallState<T>], ctx: &ForceContext<T>, touches: &mut Vec<WallTouch<T>>, overflow: &mut Option<u32>) {
    let per_grain = crate::state::walls_reals(walls, ctx.slots.stride);
    let mut e = 0;
    for (m, l) in loads.iter_mut().enumerate() {
        if !is_candidate(candidate, m) {
            continue;
        }
        let w = wall_contacts(id[m], &body[m], crate::position::residual_at(residual, m), &prop[m], ctx.material(first + m), walls, ctx, &mut springs[e * per_grain..(e + 1) * per_grain], touches, overflow);
        l.force += w.force;
        l.torque += w.torque;
        e += 1;
    }
}

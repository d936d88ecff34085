//! Wall geometry shared by the scene checks and the engines.

use crate::mesh::MeshSurface;
use crate::position::complete;
use crate::real::{Real, Vec3};
use crate::scene::types::WallShape;
use crate::turn;

/// Fraction of the largest stable servo gain a servo wall keeps where its contacts are stiff
/// (`A / (k tau + c)`, see the CPU engine's `servo_drift` and WGSL `servo_move`).
pub const SERVO_RELAXATION: f64 = 0.5;

/// Largest sine of the angle between a spin and an axis for the spin to count as along it: a
/// plane spinning along its normal, or a cylinder along its axis, stays in place.
pub const SPIN_OFF_AXIS: f64 = 1e-9;

/// Whether the spin `spin` (rad/s) turns the surface of a wall of `shape`: a plane's about
/// any axis but its normal (as the scene gives it), a mesh's about any axis. A wall turns
/// from the first drive that turns it on ([`WallGeom::turned`]).
pub fn turns_with(shape: &WallShape, spin: glam::DVec3) -> bool {
    match shape {
        WallShape::Plane { normal, .. } => spin.cross(*normal).length() > SPIN_OFF_AXIS * spin.length(),
        WallShape::Mesh { .. } => spin != glam::DVec3::ZERO,
        _ => false,
    }
}

/// Where a mesh wall stands: moved by `shift` from where the scene put it, and, once a drive
/// has turned it, turned by `turn` about `pivot + shift`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshPose<T> {
    /// Translation since the start (m).
    pub shift: Vec3<T>,
    /// The point it turns about, where the scene put it (m).
    pub pivot: Vec3<T>,
    /// The rotation from where the scene put it ([`crate::turn`]); `None` until a drive turns
    /// it, so that a mesh that only translates keeps the arithmetic of one that cannot turn.
    pub turn: Option<[T; 4]>,
}

impl<T: Real> MeshPose<T> {
    /// The point `x + r` (m; `r` a compensated position's residual) in the mesh's rest frame,
    /// where its triangles are.
    #[inline(always)]
    pub fn local(&self, x: Vec3<T>, r: Vec3<T>) -> Vec3<T> {
        match self.turn {
            None => complete(x - self.shift, r),
            Some(q) => self.pivot + turn::unapply(q, complete(x - (self.pivot + self.shift), r)),
        }
    }

    /// A direction of the rest frame (a contact's normal) in the world.
    #[inline(always)]
    pub fn world_direction(&self, n: Vec3<T>) -> Vec3<T> {
        match self.turn {
            None => n,
            Some(q) => turn::apply(q, n),
        }
    }

    /// A point of the rest frame (a corner of a triangle, m) in the world.
    pub fn world_point(&self, y: Vec3<T>) -> Vec3<T> {
        match self.turn {
            None => y + self.shift,
            Some(q) => self.pivot + self.shift + turn::apply(q, y - self.pivot),
        }
    }

    /// The same pose in `f64`.
    pub fn f64(&self) -> MeshPose<f64> {
        MeshPose { shift: Vec3::of(self.shift.f64()), pivot: Vec3::of(self.pivot.f64()), turn: self.turn.map(|q| q.map(|x| x.f64())) }
    }
}

/// The surface of a wall at one instant, in the engine's precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WallGeom<T> {
    /// Plane through `point` with unit `normal` into the domain.
    Plane {
        /// A point on the plane (m).
        point: Vec3<T>,
        /// Unit normal into the domain.
        normal: Vec3<T>,
    },
    /// Vertical cylinder around (`cx`, `cy`), grains inside.
    Cylinder {
        /// Axis x (m).
        cx: T,
        /// Axis y (m).
        cy: T,
        /// Radius (m).
        radius: T,
    },
    /// Horizontal plate at height `z` facing down.
    Piston {
        /// Height (m).
        z: T,
    },
    /// Triangle mesh number `mesh` among the scene's meshes ([`crate::mesh::MeshSurface`]),
    /// where `pose` puts it. It has no single frame: its contacts are
    /// [`crate::mesh::MeshSurface::touching`]'s.
    Mesh {
        /// Index into the engine's meshes.
        mesh: u32,
        /// Where it stands.
        pose: MeshPose<T>,
    },
}

impl<T: Real> WallGeom<T> {
    /// The same surface in `f64`, for frames.
    pub fn f64(&self) -> WallGeom<f64> {
        match *self {
            WallGeom::Plane { point, normal } => WallGeom::Plane { point: Vec3::of(point.f64()), normal: Vec3::of(normal.f64()) },
            WallGeom::Cylinder { cx, cy, radius } => WallGeom::Cylinder { cx: cx.f64(), cy: cy.f64(), radius: radius.f64() },
            WallGeom::Piston { z } => WallGeom::Piston { z: z.f64() },
            WallGeom::Mesh { mesh, pose } => WallGeom::Mesh { mesh, pose: pose.f64() },
        }
    }

    /// The surface of a scene wall at its initial position.
    pub fn of(shape: &WallShape) -> Self {
        match shape {
            WallShape::Plane { point, normal } => WallGeom::Plane { point: Vec3::of(*point), normal: Vec3::of(*normal) },
            WallShape::Cylinder { center, radius } => WallGeom::Cylinder { cx: T::of(center[0]), cy: T::of(center[1]), radius: T::of(*radius) },
            WallShape::Piston { z, .. } => WallGeom::Piston { z: T::of(*z) },
            WallShape::Mesh { index, pivot, .. } => WallGeom::Mesh { mesh: *index, pose: MeshPose { shift: Vec3::ZERO, pivot: Vec3::of(*pivot), turn: None } },
        }
    }

    /// The same surface moved by `d` (m): a cylinder, infinite along z, by `d`'s x and y.
    pub fn translated(&self, d: Vec3<T>) -> Self {
        match *self {
            WallGeom::Plane { point, normal } => WallGeom::Plane { point: point + d, normal },
            WallGeom::Cylinder { cx, cy, radius } => WallGeom::Cylinder { cx: cx + d.x, cy: cy + d.y, radius },
            WallGeom::Piston { z } => WallGeom::Piston { z: z + d.z },
            WallGeom::Mesh { mesh, pose } => WallGeom::Mesh { mesh, pose: MeshPose { shift: pose.shift + d, ..pose } },
        }
    }

    /// The same surface turned by `spin` (rad/s) for `tau` (s) about its pivot
    /// ([`Self::pivot`]; [`crate::turn::rotate`]): a plane's normal turned and kept of unit
    /// length, a mesh's rotation advanced. Other walls do not turn.
    pub fn turned(&self, spin: Vec3<T>, tau: T) -> Self {
        match *self {
            WallGeom::Plane { point, normal } => {
                let n = turn::apply(turn::rotate(turn::identity(), spin, tau), normal);
                WallGeom::Plane { point, normal: n * (T::ONE / n.norm()) }
            }
            WallGeom::Mesh { mesh, pose } => WallGeom::Mesh { mesh, pose: MeshPose { turn: Some(turn::rotate(pose.turn.unwrap_or_else(turn::identity), spin, tau)), ..pose } },
            other => other,
        }
    }

    /// Where the wall's translation has taken it (m), as checkpoints keep it: a plane's
    /// point, a cylinder's axis at z = 0, the middle of the piston, a mesh's shift.
    pub fn centre(&self) -> Vec3<T> {
        match *self {
            WallGeom::Mesh { pose, .. } => pose.shift,
            _ => self.pivot(),
        }
    }

    /// The same surface with its [`Self::centre`] at `c` (m).
    pub fn centred_at(&self, c: Vec3<T>) -> Self {
        match *self {
            WallGeom::Plane { normal, .. } => WallGeom::Plane { point: c, normal },
            WallGeom::Cylinder { radius, .. } => WallGeom::Cylinder { cx: c.x, cy: c.y, radius },
            WallGeom::Piston { .. } => WallGeom::Piston { z: c.z },
            WallGeom::Mesh { mesh, pose } => WallGeom::Mesh { mesh, pose: MeshPose { shift: c, ..pose } },
        }
    }

    /// The point a spin turns the wall about (m): a plane's point, a cylinder's axis at
    /// z = 0, the middle of the piston, a mesh's pivot where its translation has taken it.
    pub fn pivot(&self) -> Vec3<T> {
        match *self {
            WallGeom::Plane { point, .. } => point,
            WallGeom::Cylinder { cx, cy, .. } => Vec3::new(cx, cy, T::ZERO),
            WallGeom::Piston { z } => Vec3::new(T::ZERO, T::ZERO, z),
            WallGeom::Mesh { pose, .. } => pose.pivot + pose.shift,
        }
    }

    /// True when the point `x` lies nearer than `reach` (m) to one of `walls` (signed distance,
    /// [`Self::frame`]; a mesh's among `meshes`, [`MeshSurface::within`]): a grain of radius
    /// `r` there can touch one of them within `reach - r`.
    pub fn any_within<'a>(walls: impl IntoIterator<Item = &'a WallGeom<T>>, meshes: &[MeshSurface<T>], x: Vec3<T>, reach: T) -> bool
    where
        T: 'a,
    {
        walls.into_iter().any(|w| match *w {
            WallGeom::Mesh { mesh, pose } => meshes[mesh as usize].within(pose.local(x, Vec3::ZERO), reach),
            _ => w.frame(x, Vec3::ZERO).1 < reach,
        })
    }

    /// How far the surface has moved since it was `before` (m): no point within `reach` (m)
    /// of its pivot then ([`Self::pivot`]; for a mesh, no point of the mesh) has had its
    /// distance to it change by more. A turn moves a point by at most its distance from the
    /// pivot times the turn's chord ([`crate::turn::chord`]). Infinite where the two cannot be
    /// compared (another kind).
    pub fn moved_since(&self, before: &WallGeom<T>, reach: T) -> T {
        match (*self, *before) {
            (WallGeom::Plane { point, normal }, WallGeom::Plane { point: p0, normal: n0 }) if normal == n0 => (point - p0).dot(normal).abs(),
            (WallGeom::Plane { point, normal }, WallGeom::Plane { point: p0, normal: n0 }) => {
                // (x - p) n - (x - p0) n0 = (x - p0)(n - n0) - (p - p0) n
                (point - p0).norm() + reach * (normal - n0).norm()
            }
            (WallGeom::Cylinder { cx, cy, radius }, WallGeom::Cylinder { cx: x0, cy: y0, radius: r0 }) => ((cx - x0) * (cx - x0) + (cy - y0) * (cy - y0)).sqrt() + (radius - r0).abs(),
            (WallGeom::Piston { z }, WallGeom::Piston { z: z0 }) => (z - z0).abs(),
            (WallGeom::Mesh { mesh, pose }, WallGeom::Mesh { mesh: m0, pose: p0 }) if mesh == m0 => {
                let shift = (pose.shift - p0.shift).norm();
                match (pose.turn, p0.turn) {
                    (None, None) => shift,
                    (q, q0) => shift + reach * turn::chord(q.unwrap_or_else(turn::identity), q0.unwrap_or_else(turn::identity)),
                }
            }
            _ => T::of(f64::INFINITY),
        }
    }

    /// Unit normal from the wall to a point `p + r` (m; `r` the residual of a compensated
    /// position, [`crate::position`]), and the signed distance (m) from the surface to it,
    /// positive on the grains' side. A mesh, which has no single frame, is never nearer than
    /// infinity: its contacts are [`MeshSurface::touching`]'s.
    #[inline(always)]
    pub fn frame(&self, p: Vec3<T>, r: Vec3<T>) -> (Vec3<T>, T) {
        match *self {
            WallGeom::Plane { point, normal } => (normal, complete(p - point, r).dot(normal)),
            WallGeom::Cylinder { cx, cy, radius } => {
                let d = complete(Vec3::new(p.x - cx, p.y - cy, T::ZERO), r);
                let (dx, dy) = (d.x, d.y);
                let rho = (dx * dx + dy * dy).sqrt();
                let n = if rho > T::ZERO { Vec3::new(-dx / rho, -dy / rho, T::ZERO) } else { Vec3::new(-T::ONE, T::ZERO, T::ZERO) };
                (n, radius - rho)
            }
            WallGeom::Piston { z } => (Vec3::new(T::ZERO, T::ZERO, -T::ONE), if T::COMPENSATED { (z - p.z) - r.z } else { z - p.z }),
            WallGeom::Mesh { .. } => (Vec3::ZERO, T::of(f64::INFINITY)),
        }
    }
}

//! Wall geometry shared by the scene checks and the engines.

use crate::mesh::MeshSurface;
use crate::position::complete;
use crate::real::{Real, Vec3};
use crate::scene::types::WallShape;

/// Fraction of the largest stable servo gain a servo wall keeps where its contacts are stiff
/// (`A / (k tau + c)`, see the CPU engine's `servo_drift` and WGSL `servo_move`).
pub const SERVO_RELAXATION: f64 = 0.5;

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
    /// moved by `shift` from where the scene put it. It has no single frame: its contacts are
    /// [`crate::mesh::MeshSurface::touching`]'s.
    Mesh {
        /// Index into the engine's meshes.
        mesh: u32,
        /// Translation since the start (m).
        shift: Vec3<T>,
    },
}

impl<T: Real> WallGeom<T> {
    /// The same surface in `f64`, for frames.
    pub fn f64(&self) -> WallGeom<f64> {
        match *self {
            WallGeom::Plane { point, normal } => WallGeom::Plane { point: Vec3::of(point.f64()), normal: Vec3::of(normal.f64()) },
            WallGeom::Cylinder { cx, cy, radius } => WallGeom::Cylinder { cx: cx.f64(), cy: cy.f64(), radius: radius.f64() },
            WallGeom::Piston { z } => WallGeom::Piston { z: z.f64() },
            WallGeom::Mesh { mesh, shift } => WallGeom::Mesh { mesh, shift: Vec3::of(shift.f64()) },
        }
    }

    /// The surface of a scene wall at its initial position.
    pub fn of(shape: &WallShape) -> Self {
        match shape {
            WallShape::Plane { point, normal } => WallGeom::Plane { point: Vec3::of(*point), normal: Vec3::of(*normal) },
            WallShape::Cylinder { center, radius } => WallGeom::Cylinder { cx: T::of(center[0]), cy: T::of(center[1]), radius: T::of(*radius) },
            WallShape::Piston { z, .. } => WallGeom::Piston { z: T::of(*z) },
            WallShape::Mesh { index, .. } => WallGeom::Mesh { mesh: *index, shift: Vec3::ZERO },
        }
    }

    /// The same surface moved by `d` (m): a cylinder, infinite along z, by `d`'s x and y.
    pub fn translated(&self, d: Vec3<T>) -> Self {
        match *self {
            WallGeom::Plane { point, normal } => WallGeom::Plane { point: point + d, normal },
            WallGeom::Cylinder { cx, cy, radius } => WallGeom::Cylinder { cx: cx + d.x, cy: cy + d.y, radius },
            WallGeom::Piston { z } => WallGeom::Piston { z: z + d.z },
            WallGeom::Mesh { mesh, shift } => WallGeom::Mesh { mesh, shift: shift + d },
        }
    }

    /// The point on the wall's axis of symmetry that a spin turns about (m): a plane's point,
    /// a cylinder's axis at z = 0, the middle of the piston, a mesh's shift.
    pub fn centre(&self) -> Vec3<T> {
        match *self {
            WallGeom::Plane { point, .. } => point,
            WallGeom::Cylinder { cx, cy, .. } => Vec3::new(cx, cy, T::ZERO),
            WallGeom::Piston { z } => Vec3::new(T::ZERO, T::ZERO, z),
            WallGeom::Mesh { shift, .. } => shift,
        }
    }

    /// The same surface with its [`Self::centre`] at `c` (m).
    pub fn centred_at(&self, c: Vec3<T>) -> Self {
        match *self {
            WallGeom::Plane { normal, .. } => WallGeom::Plane { point: c, normal },
            WallGeom::Cylinder { radius, .. } => WallGeom::Cylinder { cx: c.x, cy: c.y, radius },
            WallGeom::Piston { .. } => WallGeom::Piston { z: c.z },
            WallGeom::Mesh { mesh, .. } => WallGeom::Mesh { mesh, shift: c },
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
            WallGeom::Mesh { mesh, shift } => meshes[mesh as usize].within(x - shift, reach),
            _ => w.frame(x, Vec3::ZERO).1 < reach,
        })
    }

    /// How far the surface has moved since it was `before` (m): no point's distance to it has
    /// changed by more. Infinite where the two cannot be compared (another kind, a turned
    /// plane).
    pub fn moved_since(&self, before: &WallGeom<T>) -> T {
        match (*self, *before) {
            (WallGeom::Plane { point, normal }, WallGeom::Plane { point: p0, normal: n0 }) if normal == n0 => (point - p0).dot(normal).abs(),
            (WallGeom::Cylinder { cx, cy, radius }, WallGeom::Cylinder { cx: x0, cy: y0, radius: r0 }) => ((cx - x0) * (cx - x0) + (cy - y0) * (cy - y0)).sqrt() + (radius - r0).abs(),
            (WallGeom::Piston { z }, WallGeom::Piston { z: z0 }) => (z - z0).abs(),
            (WallGeom::Mesh { mesh, shift }, WallGeom::Mesh { mesh: m0, shift: s0 }) if mesh == m0 => (shift - s0).norm(),
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

//! The broad phase of a mesh wall: its triangles binned once into a grid of cubic cells over
//! the mesh's box widened by the reach, each cell listing (ascending) the triangles that a
//! point in it can lie within the reach of. A grain looks up its own cell only. The grid is in
//! the mesh's own frame, so a mesh that moves keeps it.

use super::closest::closest_point;
use super::TriMesh;
use crate::real::{Real, Vec3};
use glam::DVec3;

/// Most cells along the mesh's longest side: coarser cells beyond that keep the grid's size
/// bounded for a mesh much larger than its grains.
pub const MAX_CELLS_PER_SIDE: f64 = 128.0;

/// A mesh's triangles binned by cell.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleGrid<T> {
    /// Lower corner of cell (0, 0, 0) (m).
    pub origin: Vec3<T>,
    /// Inverse of the cell side (1/m).
    pub inv_cell: T,
    /// Cells along x, y and z.
    pub dims: [u32; 3],
    /// Cell `c`'s triangles are `ids[start[c]..start[c + 1]]`; cells are numbered x fastest.
    pub start: Vec<u32>,
    /// Triangle indices, cell by cell, ascending within a cell.
    pub ids: Vec<u32>,
    /// The reach (m) it was built for: every triangle within it of a point is in its cell.
    pub reach: f64,
}

impl<T: Real> TriangleGrid<T> {
    /// Bins `mesh`'s triangles for points up to `reach` (m) away.
    pub fn build(mesh: &TriMesh, reach: f64) -> Self {
        let (lo, hi) = mesh.bounds();
        let (lo, hi) = (lo - DVec3::splat(reach), hi + DVec3::splat(reach));
        let side = (hi - lo).max_element();
        let cell = reach.max(side / MAX_CELLS_PER_SIDE);
        let dims = ((hi - lo) / cell).ceil().max(DVec3::ONE).as_uvec3().to_array();
        let (nx, ny) = (dims[0] as usize, dims[1] as usize);
        let n_cells = nx * ny * dims[2] as usize;
        // Any point of a cell lies within half its diagonal of the cell's centre (plus a
        // margin for a point that rounding puts in the next cell).
        let widen = reach + cell * (0.5 * 3f64.sqrt() + 1e-3);
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            let (tlo, thi) = (a.min(b).min(c) - DVec3::splat(widen), a.max(b).max(c) + DVec3::splat(widen));
            let first = ((tlo - lo) / cell).floor().max(DVec3::ZERO).as_uvec3();
            let last = ((thi - lo) / cell).floor().as_uvec3().min(glam::UVec3::from_array(dims) - 1);
            for z in first.z..=last.z {
                for y in first.y..=last.y {
                    for x in first.x..=last.x {
                        let centre = lo + (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * cell;
                        let (q, _) = closest_point(Vec3::<f64>::of(centre), Vec3::of(a), Vec3::of(b), Vec3::of(c));
                        if (q.f64() - centre).length() < widen {
                            pairs.push(((x as usize + nx * (y as usize + ny * z as usize)) as u32, t as u32));
                        }
                    }
                }
            }
        }
        pairs.sort_unstable();
        let mut start = vec![0u32; n_cells + 1];
        for &(c, _) in &pairs {
            start[c as usize + 1] += 1;
        }
        for c in 0..n_cells {
            start[c + 1] += start[c];
        }
        TriangleGrid { origin: Vec3::of(lo), inv_cell: T::of(1.0 / cell), dims, start, ids: pairs.into_iter().map(|(_, t)| t).collect(), reach }
    }

    /// The triangles that may lie within the reach of `x` (m, in the mesh's frame): none
    /// outside the grid.
    #[inline(always)]
    pub fn near(&self, x: Vec3<T>) -> &[u32] {
        let d = (x - self.origin) * self.inv_cell;
        let (fx, fy, fz) = (d.x.floor(), d.y.floor(), d.z.floor());
        let inside = |f: T, n: u32| f >= T::ZERO && f < T::of(n as f64);
        if !(inside(fx, self.dims[0]) && inside(fy, self.dims[1]) && inside(fz, self.dims[2])) {
            return &[];
        }
        let c = fx.f64() as usize + self.dims[0] as usize * (fy.f64() as usize + self.dims[1] as usize * fz.f64() as usize);
        &self.ids[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

//! Triangle-mesh walls: a surface read from an STL file (`[[wall]] type = "mesh"`), its
//! triangles binned once into a grid of cells, and the contacts of a sphere with it.
//!
//! A grain touches a mesh at its closest point on each triangle within its radius, sorted into
//! the triangle's face, one of its edges or one of its vertices ([`closest`]). Triangles share
//! their edges and vertices ([`TriMesh`] welds the file's corners), so a grain over an edge or a
//! vertex that several triangles share finds it once, and a grain over a face drops the edges
//! and vertices of that face; contacts whose normals lie within [`MERGE_ANGLE_DEG`] of each
//! other are one contact, the deepest, pushed along the faces' overlap-weighted mean normal
//! where the grain lies on several faces ([`surface::MeshSurface::touching`]). A grain rolling
//! from one triangle to the next therefore keeps one contact whose force is continuous, while
//! a grain in a crease of the mesh (a hopper's cone meeting its floor) touches both sides.
//! Each grain keeps [`MESH_CONTACTS`] contact slots per mesh, each with its history and the
//! normal it last had: a contact takes over the slot whose normal is nearest to its own, so
//! the springs follow it across triangles ([`slots`]).

pub mod closest;
pub mod grid;
pub mod read;
pub mod slots;
pub mod surface;

pub use read::{MeshError, MeshPlacement};
pub use surface::MeshSurface;

use glam::DVec3;

/// Contacts a grain can have with one mesh at once (the slots its history keeps).
pub const MESH_CONTACTS: usize = 4;

/// Contacts with normals closer than this (degrees) are one contact: the mesh's facets may
/// turn by less than this where they approximate a curved surface.
pub const MERGE_ANGLE_DEG: f64 = 30.0;

/// Raw contacts (before merging) a grain may have with one mesh's triangles: a mesh whose
/// triangles are so much smaller than its grains that more lie within one grain is refused
/// at run time.
pub const RAW_CONTACTS: usize = 32;

/// A triangle mesh in the scene's frame (m), its corners shared between triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct TriMesh {
    /// The file it was read from, for messages.
    pub file: std::path::PathBuf,
    /// Distinct corners (m).
    pub vertices: Vec<DVec3>,
    /// Each triangle's corners, indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's edges, indices into the mesh's distinct edges: edge `k` joins corners
    /// `k` and `(k + 1) % 3`.
    pub edges: Vec<[u32; 3]>,
    /// Number of distinct edges.
    pub n_edges: usize,
}

impl TriMesh {
    /// A mesh of `triangles` over `vertices`, its edges numbered (an edge shared by triangles
    /// has one number whatever their winding).
    pub fn new(file: std::path::PathBuf, vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Self {
        let mut ids = std::collections::BTreeMap::new();
        let edges = triangles
            .iter()
            .map(|t| {
                std::array::from_fn(|k| {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let n = ids.len() as u32;
                    *ids.entry((a.min(b), a.max(b))).or_insert(n)
                })
            })
            .collect();
        TriMesh { file, vertices, triangles, edges, n_edges: ids.len() }
    }

    /// The corners of triangle `t` (m).
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|v| self.vertices[v as usize])
    }

    /// Lower and upper corners of the box around every triangle (m).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.vertices.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), &v| (lo.min(v), hi.max(v)))
    }

    /// Distance (m) from `x` to the nearest point of the mesh.
    pub fn distance(&self, x: DVec3) -> f64 {
        use crate::real::Vec3;
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t).map(Vec3::<f64>::of);
                (closest::closest_point(Vec3::of(x), a, b, c).0.f64() - x).length()
            })
            .fold(f64::INFINITY, f64::min)
    }
}

//! A mesh wall in the engine's precision: its corners, triangles, edges and grid, and the
//! contacts of a sphere with it.

use super::closest::{closest_point, Region, EDGE, FACE, VERTEX};
use super::grid::TriangleGrid;
use super::{TriMesh, MERGE_ANGLE_DEG, MESH_CONTACTS, RAW_CONTACTS};
use crate::real::{Real, Vec3};

/// A mesh as the force pass sees it (positions in the frame the mesh started in: a grain at
/// `x` is at `x - shift` for a mesh moved by `shift`).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshSurface<T> {
    /// Corners (m).
    pub vertices: Vec<Vec3<T>>,
    /// Each triangle's corners.
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's edges ([`TriMesh::edges`]).
    pub edges: Vec<[u32; 3]>,
    /// The triangles binned by cell.
    pub grid: TriangleGrid<T>,
    /// Cosine of [`MERGE_ANGLE_DEG`].
    pub merge_cos: T,
}

/// One contact of a grain with a mesh: the unit normal from the mesh to the grain's centre and
/// the centre's distance (m) from the mesh along it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeshContact<T> {
    /// Unit normal from the mesh to the grain.
    pub normal: Vec3<T>,
    /// Distance from the contact point to the grain's centre (m).
    pub dist: T,
}

/// A grain's contacts with one mesh, at most [`MESH_CONTACTS`].
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshTouches<T> {
    /// The contacts, `len` of them.
    pub contacts: [MeshContact<T>; MESH_CONTACTS],
    /// How many.
    pub len: usize,
    /// True when the grain had more than [`RAW_CONTACTS`] triangles within its radius or more
    /// than [`MESH_CONTACTS`] distinct contacts: the run must stop.
    pub overflow: bool,
}

/// The contacts [`MeshSurface::touching`] merges into one: the first one's normal, which the
/// others are compared with, the sum of the face contacts' normals weighted by their overlaps,
/// and whether the deepest so far is a face contact.
#[derive(Clone, Copy, Debug, Default)]
struct Group<T> {
    first: Vec3<T>,
    faces: Vec3<T>,
    deepest_is_face: bool,
}

/// A triangle within a grain's radius: which triangle, the region and the closest point's
/// offset to the centre.
#[derive(Clone, Copy, Debug, Default)]
struct Raw<T> {
    tri: u32,
    region: Region,
    offset: Vec3<T>,
    d2: T,
}

impl<T: Real> MeshSurface<T> {
    /// `mesh` in precision `T`, binned for grains of radius up to `reach` (m, the largest
    /// radius plus the skin).
    pub fn new(mesh: &TriMesh, reach: f64) -> Self {
        MeshSurface {
            vertices: mesh.vertices.iter().map(|&v| Vec3::of(v)).collect(),
            triangles: mesh.triangles.clone(),
            edges: mesh.edges.clone(),
            grid: TriangleGrid::build(mesh, reach),
            merge_cos: T::of(MERGE_ANGLE_DEG.to_radians().cos()),
        }
    }

    #[inline(always)]
    fn corners(&self, t: u32) -> [Vec3<T>; 3] {
        self.triangles[t as usize].map(|v| self.vertices[v as usize])
    }

    /// True when a point of the mesh lies nearer than `reach` (m, at most the grid's) to `x`
    /// (m, in the mesh's frame).
    pub fn within(&self, x: Vec3<T>, reach: T) -> bool {
        self.grid.near(x).iter().any(|&t| {
            let [a, b, c] = self.corners(t);
            (x - closest_point(x, a, b, c).0).norm2() < reach * reach
        })
    }

    /// The contacts of a sphere of `radius` (m) centred at `x` (m, in the mesh's frame): the
    /// closest point of each triangle nearer than `radius`, less the edges and corners of a
    /// triangle whose face it touches (and the corners of an edge it touches), each shared
    /// edge and corner once; contacts whose normals lie within [`MERGE_ANGLE_DEG`] of the
    /// first one's are one contact, at the least distance, along the deepest one's normal or,
    /// where that is a face's, along the face contacts' normals' mean weighted by their
    /// overlaps: a grain in a shallow crease of the mesh, on two faces, is pushed along its
    /// bisector, and a face joining in at zero overlap turns nothing at once (an edge or a
    /// corner left beside a face is never the deepest and never turns it). In the order of
    /// their triangles.
    #[inline(always)]
    pub fn touching(&self, x: Vec3<T>, radius: T) -> MeshTouches<T> {
        let mut out = MeshTouches::default();
        let mut groups = [Group::default(); MESH_CONTACTS];
        let mut raw = [Raw::default(); RAW_CONTACTS];
        let mut n = 0;
        for &t in self.grid.near(x) {
            let [a, b, c] = self.corners(t);
            let (q, region) = closest_point(x, a, b, c);
            let offset = x - q;
            let d2 = offset.norm2();
            if d2 < radius * radius {
                if n == RAW_CONTACTS {
                    out.overflow = true;
                    return out;
                }
                raw[n] = Raw { tri: t, region, offset, d2 };
                n += 1;
            }
        }
        for i in 0..n {
            let r = raw[i];
            if r.region != FACE && self.hidden(&raw[..n], r) {
                continue;
            }
            if raw[..i].iter().any(|o| self.same_feature(o, &r)) {
                continue;
            }
            let dist = r.d2.sqrt();
            let normal = if dist > T::ZERO { r.offset * (T::ONE / dist) } else { self.face_normal(r.tri) };
            let face = if r.region == FACE { normal * (radius - dist) } else { Vec3::ZERO };
            match groups[..out.len].iter().position(|g| g.first.dot(normal) > self.merge_cos) {
                Some(k) => {
                    let (g, c) = (&mut groups[k], &mut out.contacts[k]);
                    g.faces += face;
                    if dist < c.dist {
                        *c = MeshContact { normal, dist };
                        g.deepest_is_face = r.region == FACE;
                    }
                }
                None if out.len == MESH_CONTACTS => {
                    out.overflow = true;
                    return out;
                }
                None => {
                    groups[out.len] = Group { first: normal, faces: face, deepest_is_face: r.region == FACE };
                    out.contacts[out.len] = MeshContact { normal, dist };
                    out.len += 1;
                }
            }
        }
        for (c, g) in out.contacts[..out.len].iter_mut().zip(&groups) {
            if g.deepest_is_face {
                c.normal = g.faces * (T::ONE / g.faces.norm());
            }
        }
        out
    }

    /// True when an edge or corner contact `r` belongs to a triangle whose face the grain
    /// touches, or (a corner) to an edge it touches.
    #[inline(always)]
    fn hidden(&self, raw: &[Raw<T>], r: Raw<T>) -> bool {
        if r.region < VERTEX {
            let e = self.edges[r.tri as usize][(r.region - EDGE) as usize];
            return raw.iter().any(|o| o.region == FACE && self.edges[o.tri as usize].contains(&e));
        }
        let v = self.triangles[r.tri as usize][(r.region - VERTEX) as usize];
        raw.iter().any(|o| match o.region {
            FACE => self.triangles[o.tri as usize].contains(&v),
            reg if reg < VERTEX => {
                let (k, tri) = ((reg - EDGE) as usize, self.triangles[o.tri as usize]);
                tri[k] == v || tri[(k + 1) % 3] == v
            }
            _ => false,
        })
    }

    /// True when `a` and `b` are the same edge or the same corner of the mesh.
    #[inline(always)]
    fn same_feature(&self, a: &Raw<T>, b: &Raw<T>) -> bool {
        match (a.region, b.region) {
            (FACE, _) | (_, FACE) => false,
            (ra, rb) if ra < VERTEX && rb < VERTEX => self.edges[a.tri as usize][(ra - EDGE) as usize] == self.edges[b.tri as usize][(rb - EDGE) as usize],
            (ra, rb) if ra >= VERTEX && rb >= VERTEX => self.triangles[a.tri as usize][(ra - VERTEX) as usize] == self.triangles[b.tri as usize][(rb - VERTEX) as usize],
            _ => false,
        }
    }

    /// Unit normal of triangle `t` (by its corners' winding).
    fn face_normal(&self, t: u32) -> Vec3<T> {
        let [a, b, c] = self.corners(t);
        let n = (b - a).cross(c - a);
        n * (T::ONE / n.norm())
    }
}

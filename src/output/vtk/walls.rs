//! The walls of a frame as polygons: planes and the piston as quads over the domain (the
//! piston as a disc inside a cylinder), the cylinder as a ring of quads over the domain's
//! height, a mesh as its triangles.

use super::xml::{Array, PolyData};
use crate::engine::Frame;
use crate::real::Vec3;
use crate::scene::Scene;
use crate::walls::WallGeom;

/// Sides of the polygon that stands for a circle.
const CIRCLE_SIDES: usize = 64;

/// The domain's box (lower, upper corner, m): the grains' extent, the periodic intervals, the
/// axis-aligned planes and the cylinder's footprint.
pub fn domain(scene: &Scene, f: &Frame) -> ([f64; 3], [f64; 3]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut include = |a: usize, x: f64| {
        lo[a] = lo[a].min(x);
        hi[a] = hi[a].max(x);
    };
    for (p, r) in f.position.iter().zip(&f.radius) {
        for (a, x) in p.to_array().iter().enumerate() {
            include(a, x - r);
            include(a, x + r);
        }
    }
    for (a, axis) in scene.periodic.iter().enumerate() {
        if let Some([l, h]) = axis {
            include(a, *l);
            include(a, *h);
        }
    }
    for w in &f.walls {
        match *w {
            WallGeom::Plane { point, normal } => {
                if let Some(a) = axis_of(normal.f64().to_array()) {
                    include(a, point.f64()[a]);
                }
            }
            WallGeom::Cylinder { cx, cy, radius } => {
                include(0, cx - radius);
                include(0, cx + radius);
                include(1, cy - radius);
                include(1, cy + radius);
            }
            WallGeom::Piston { z } => include(2, z),
            WallGeom::Mesh { mesh, pose } => {
                for v in &mesh_of(scene, mesh).vertices {
                    for (a, x) in pose.world_point(crate::real::Vec3::of(*v)).f64().to_array().into_iter().enumerate() {
                        include(a, x);
                    }
                }
            }
        }
    }
    (lo, hi)
}

/// The scene's mesh of index `index` ([`WallGeom::Mesh`]).
fn mesh_of(scene: &Scene, index: u32) -> &crate::mesh::TriMesh {
    scene
        .walls
        .iter()
        .find_map(|w| match &w.shape {
            crate::scene::WallShape::Mesh { mesh, index: i, .. } if *i == index => Some(&**mesh),
            _ => None,
        })
        .expect("a frame's mesh walls are its scene's")
}

/// The axis a unit normal lies along, if it does.
fn axis_of(n: [f64; 3]) -> Option<usize> {
    (0..3).find(|&a| n[a].abs() > 1.0 - 1e-9)
}

/// The walls of frame `f` (whose `walls` are where they stand) as one polygon set, with the
/// wall index and the force the grains exert on each wall per polygon.
pub fn piece(scene: &Scene, f: &Frame) -> PolyData {
    let (lo, hi) = domain(scene, f);
    let mut piece = PolyData::default();
    let mut wall = Vec::new();
    let cylinder = f.walls.iter().find_map(|w| match *w {
        WallGeom::Cylinder { cx, cy, radius } => Some((cx, cy, radius)),
        _ => None,
    });
    let mut polygon = |piece: &mut PolyData, corners: Vec<[f64; 3]>, w: usize| {
        let k = piece.points.len();
        piece.polys.push(k..k + corners.len());
        piece.points.extend(corners);
        wall.push(w);
    };
    // A wall a stage has taken away is not drawn.
    for (w, geom) in f.walls.iter().enumerate().filter(|&(w, _)| f.walls_present.get(w).copied().unwrap_or(true)) {
        match *geom {
            WallGeom::Plane { point, normal } => polygon(&mut piece, plane_quad(point.f64().to_array(), normal.f64().to_array(), lo, hi), w),
            WallGeom::Piston { z } => match cylinder {
                Some((cx, cy, radius)) => polygon(&mut piece, circle(cx, cy, radius).map(|(x, y)| [x, y, z]).collect(), w),
                None => polygon(&mut piece, vec![[lo[0], lo[1], z], [hi[0], lo[1], z], [hi[0], hi[1], z], [lo[0], hi[1], z]], w),
            },
            WallGeom::Mesh { mesh, pose } => {
                let m = mesh_of(scene, mesh);
                for t in 0..m.triangles.len() {
                    polygon(&mut piece, m.corners(t).map(|v| pose.world_point(crate::real::Vec3::of(v)).f64().to_array()).to_vec(), w);
                }
            }
            WallGeom::Cylinder { cx, cy, radius } => {
                let ring: Vec<(f64, f64)> = circle(cx, cy, radius).collect();
                for s in 0..CIRCLE_SIDES {
                    let ((x0, y0), (x1, y1)) = (ring[s], ring[(s + 1) % CIRCLE_SIDES]);
                    polygon(&mut piece, vec![[x0, y0, lo[2]], [x1, y1, lo[2]], [x1, y1, hi[2]], [x0, y0, hi[2]]], w);
                }
            }
        }
    }
    // The force on each wall: the opposite of its contacts' forces on the grains.
    let mut on_wall = vec![[0.0f64; 3]; f.walls.len()];
    for c in f.wall_contacts.as_deref().unwrap_or(&[]) {
        for (total, part) in on_wall[c.wall as usize].iter_mut().zip(c.force.to_array()) {
            *total -= part;
        }
    }
    piece.cell_data = vec![Array::integers("wall", wall.iter().map(|&w| w as i64)), Array::vectors("force", wall.iter().map(|&w| on_wall[w]))];
    piece
}

/// Corners of a circle's polygon around (`cx`, `cy`).
fn circle(cx: f64, cy: f64, radius: f64) -> impl Iterator<Item = (f64, f64)> {
    (0..CIRCLE_SIDES).map(move |s| {
        let phi = 2.0 * std::f64::consts::PI * s as f64 / CIRCLE_SIDES as f64;
        (cx + radius * phi.cos(), cy + radius * phi.sin())
    })
}

/// The part of a plane inside the box `lo`-`hi`: for an axis-aligned plane the box's face at
/// the plane's coordinate; otherwise a square around the box centre's projection, as wide as
/// the box's diagonal.
fn plane_quad(point: [f64; 3], normal: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    if let Some(a) = axis_of(normal) {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let corner = |u: f64, v: f64| {
            let mut p = [0.0; 3];
            (p[a], p[b], p[c]) = (point[a], u, v);
            p
        };
        return vec![corner(lo[b], lo[c]), corner(hi[b], lo[c]), corner(hi[b], hi[c]), corner(lo[b], hi[c])];
    }
    let n = Vec3::of(normal);
    let centre = Vec3::of([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])]);
    let on_plane = centre - n * (centre - Vec3::of(point)).dot(n);
    let half = 0.5 * (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt();
    // A direction across the normal: the axis the normal is least along.
    let least = (0..3).min_by(|&x, &y| normal[x].abs().total_cmp(&normal[y].abs())).unwrap_or(0);
    let mut e = [0.0; 3];
    e[least] = 1.0;
    let u = n.cross(Vec3::of(e));
    let u = u * (half / u.norm());
    let v = n.cross(u);
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].iter().map(|&(s, t)| (on_plane + u * s + v * t).f64().to_array()).collect()
}

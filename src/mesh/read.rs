//! Reading a mesh wall's STL file (binary or ASCII, through `stl_io`) and placing it in the
//! scene: scaled, turned and moved, its corners welded where the file repeats them.

use super::TriMesh;
use glam::{DMat3, DVec3};
use std::path::{Path, PathBuf};

/// Why a mesh file was refused: one line naming the file, what is wrong and the fix.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {problem}; fix: {fix}")]
pub struct MeshError {
    /// The STL file.
    pub file: PathBuf,
    /// What is wrong with it.
    pub problem: String,
    /// How to fix it.
    pub fix: String,
}

/// Where a mesh goes: each corner `x` of the file becomes `rotation (scale x) + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshPlacement {
    /// Factor from the file's units to metres (e.g. 0.001 for a file in millimetres).
    pub scale: f64,
    /// Turns (degrees) about x, then y, then z (fixed axes, right-handed).
    pub rotation_deg: DVec3,
    /// Translation (m) after scaling and turning.
    pub offset: DVec3,
}

impl Default for MeshPlacement {
    fn default() -> Self {
        MeshPlacement { scale: 1.0, rotation_deg: DVec3::ZERO, offset: DVec3::ZERO }
    }
}

impl MeshPlacement {
    /// The turn as a matrix.
    pub fn matrix(&self) -> DMat3 {
        let r = self.rotation_deg * (std::f64::consts::PI / 180.0);
        DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x)
    }

    /// Where the file's point `x` goes (m).
    pub fn place(&self, x: DVec3) -> DVec3 {
        self.matrix() * (x * self.scale) + self.offset
    }
}

/// Reads the STL file `path` and places it. Refuses an unreadable or malformed file, one
/// without triangles, a corner that is not finite and a triangle without area.
pub fn read_stl(path: &Path, placement: &MeshPlacement) -> Result<TriMesh, MeshError> {
    let err = |problem: String, fix: &str| MeshError { file: path.to_path_buf(), problem, fix: fix.to_string() };
    let mut file = std::fs::File::open(path).map_err(|e| err(format!("cannot open the mesh: {e}"), "check the path (relative paths start at the scene file's folder)"))?;
    let mut reader = std::io::BufReader::new(&mut file);
    let indexed = stl_io::read_stl(&mut reader).map_err(|e| err(format!("not a readable STL file ({e})"), "export the surface as binary or ASCII STL"))?;
    if indexed.faces.is_empty() {
        return Err(err("has no triangles".into(), "export a surface with at least one facet"));
    }
    for (i, v) in indexed.vertices.iter().enumerate() {
        if !v.0.iter().all(|c| c.is_finite()) {
            return Err(err(format!("corner {i} is {:?}, not finite", v.0), "repair the file in the CAD tool"));
        }
    }
    let vertices: Vec<DVec3> = indexed.vertices.iter().map(|v| placement.place(DVec3::new(v.0[0] as f64, v.0[1] as f64, v.0[2] as f64))).collect();
    let triangles: Vec<[u32; 3]> = indexed.faces.iter().map(|f| f.vertices.map(|k| k as u32)).collect();
    for (t, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|k| vertices[k as usize]);
        let area = 0.5 * (b - a).cross(c - a).length();
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        if !(area > 1e-12 * longest * longest) {
            return Err(err(format!("facet {t} has no area (corners {:?}, {:?}, {:?} m after placing)", a.to_array(), b.to_array(), c.to_array()), "remove degenerate facets in the CAD tool"));
        }
    }
    Ok(TriMesh::new(path.to_path_buf(), vertices, triangles))
}

/// Writes `triangles` (corners in m) as an ASCII STL file: the examples' and the tests' way to
/// make meshes.
pub fn write_ascii_stl(path: &Path, name: &str, triangles: &[[DVec3; 3]]) -> std::io::Result<()> {
    use std::fmt::Write;
    let mut s = format!("solid {name}\n");
    for t in triangles {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        let _ = writeln!(s, "  facet normal {:e} {:e} {:e}\n    outer loop", n.x, n.y, n.z);
        for v in t {
            let _ = writeln!(s, "      vertex {:e} {:e} {:e}", v.x, v.y, v.z);
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    let _ = writeln!(s, "endsolid {name}");
    std::fs::write(path, s)
}

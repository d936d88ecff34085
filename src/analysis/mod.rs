//! Measures of a packing computed from a frame, and the fits of the experiments.

pub mod ensemble;
pub mod fit;
pub mod network;
pub mod oquendo;
pub mod richefeu;
pub mod tail;

use crate::engine::{ContactRecord, Frame};
use glam::{DMat3, DVec3};
use crate::periodic::Periodic;
use crate::real::Vec3;
use crate::scene::{cross_section, Scene, WallShape};

/// Beds at least this many mean diameters tall are measured in their bulk only.
pub const BULK_MIN_HEIGHT_DIAMETERS: f64 = 6.0;
/// Layers (mean diameters) left out at the floor and the top when measuring the bulk.
pub const BULK_MARGIN_DIAMETERS: f64 = 2.0;

/// Solid fraction of the bed in a container with a floor (a plane facing +z) and a
/// horizontal cross-section (a cylinder or a box's side planes), or `None` without one.
///
/// The bed spans from the floor to the piston, or to the top of the highest grain. A bed taller
/// than [`BULK_MIN_HEIGHT_DIAMETERS`] is measured in its bulk, as the peers' benchmark does:
/// the volume of grains whose centres lie more than [`BULK_MARGIN_DIAMETERS`] from the floor
/// and the top, over the band's volume. Shallower beds count every grain over the whole span.
///
/// A servo box's planes move: its bed is measured in the box where the frame has them, up to
/// its top plane.
pub fn packing_fraction(scene: &Scene, frame: &Frame, piston_z: Option<f64>) -> Option<f64> {
    let shapes: Vec<WallShape> = if scene.servo.is_some() && frame.walls.len() == scene.walls.len() {
        frame
            .walls
            .iter()
            .zip(&scene.walls)
            .map(|(now, w)| match now {
                crate::walls::WallGeom::Plane { point, normal } => WallShape::Plane { point: DVec3::new(point.x, point.y, point.z), normal: DVec3::new(normal.x, normal.y, normal.z) },
                _ => w.shape.clone(),
            })
            .collect()
    } else {
        scene.walls.iter().map(|w| w.shape.clone()).collect()
    };
    let plane_at = |facing: DVec3| {
        shapes.iter().find_map(|s| match *s {
            WallShape::Plane { point, normal } if normal == facing => Some(point[2]),
            _ => None,
        })
    };
    let area = cross_section(shapes.iter(), &scene.periodic)?;
    let floor = plane_at(DVec3::Z)?;
    let piston_z = piston_z.or_else(|| scene.servo.and_then(|_| plane_at(DVec3::NEG_Z)));
    let n = frame.radius.len();
    if n == 0 {
        return None;
    }
    let d_mean = 2.0 * frame.radius.iter().sum::<f64>() / n as f64;
    let top = piston_z.unwrap_or_else(|| (0..n).map(|i| frame.position[i][2] + frame.radius[i]).fold(f64::NEG_INFINITY, f64::max));
    let (lo, hi) = if top - floor >= BULK_MIN_HEIGHT_DIAMETERS * d_mean {
        (floor + BULK_MARGIN_DIAMETERS * d_mean, top - BULK_MARGIN_DIAMETERS * d_mean)
    } else {
        (f64::NEG_INFINITY, f64::INFINITY)
    };
    let solid: f64 = (0..n)
        .filter(|&i| frame.position[i][2] >= lo && frame.position[i][2] < hi)
        .map(|i| 4.0 / 3.0 * std::f64::consts::PI * frame.radius[i].powi(3))
        .sum();
    let height = hi.min(top) - lo.max(floor);
    (height > 0.0).then(|| solid / (area * height))
}

/// A 3x3 tensor: glam's column-major `DMat3`, element (a, b) in `t.col(b)[a]`; written to
/// files as its three rows ([`tensor_rows`]).
pub type Tensor = DMat3;

/// The outer product `f (x) c` (element (a, b) = `f[a] c[b]`).
pub fn outer(f: DVec3, c: DVec3) -> Tensor {
    DMat3::from_cols(f * c.x, f * c.y, f * c.z)
}

/// The trace `t_xx + t_yy + t_zz`, summed in that order.
pub fn trace(t: &Tensor) -> f64 {
    t.x_axis.x + t.y_axis.y + t.z_axis.z
}

/// A tensor in `summary.json` and `analysis.json`: its rows, `[[xx, xy, xz], [yx, ..], ..]`
/// (`#[serde(with = "crate::analysis::tensor_rows")]`).
pub mod tensor_rows {
    use glam::DMat3;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes the rows.
    pub fn serialize<S: Serializer>(t: &DMat3, s: S) -> Result<S::Ok, S::Error> {
        t.transpose().to_cols_array_2d().serialize(s)
    }

    /// Reads the rows.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<DMat3, D::Error> {
        Ok(DMat3::from_cols_array_2d(&<[[f64; 3]; 3]>::deserialize(d)?).transpose())
    }
}

/// Volume of the grains (m^3).
pub fn solid_volume(frame: &Frame) -> f64 {
    frame.radius.iter().map(|r| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3)).sum()
}

/// Void ratio `e = (V_total - V_solid) / V_solid` of grains filling `total_volume` (m^3).
pub fn void_ratio(solid_volume: f64, total_volume: f64) -> f64 {
    (total_volume - solid_volume) / solid_volume
}

/// Volume (m^3) between the container's floor and a piston at `piston_z` (m), for a container
/// with a cross-section (see [`cross_section`]); `None` otherwise.
pub fn container_volume(scene: &Scene, piston_z: f64) -> Option<f64> {
    let area = cross_section(scene.walls.iter().map(|w| &w.shape), &scene.periodic)?;
    let floor = scene.walls.iter().find_map(|w| match w.shape {
        WallShape::Plane { point, normal } if normal == DVec3::Z => Some(point[2]),
        _ => None,
    })?;
    Some(area * (piston_z - floor))
}

/// The unit vector from grain j's centre to grain i's (nearest periodic images) of a touching
/// pair of `frame`: the direction a compressive normal force pushes grain i.
pub fn contact_normal(frame: &Frame, periodic: &Periodic<f64>, c: &ContactRecord) -> Vec3<f64> {
    let d = periodic.min_image(Vec3::of(frame.position[c.i as usize]) - Vec3::of(frame.position[c.j as usize]));
    d * (1.0 / d.norm())
}

/// Per grain, the net force of its contacts (N): grain-grain pairs (each end's own force)
/// and walls, summed in the frame's order. Indexed like the frame's grains (slot = permanent
/// id); zero for every grain of a frame taken without contacts.
pub fn contact_forces(frame: &Frame) -> Vec<DVec3> {
    let mut f = vec![DVec3::ZERO; frame.radius.len()];
    for r in frame.contacts.as_deref().unwrap_or(&[]) {
        f[r.i as usize] += r.force;
        f[r.j as usize] += r.force_j;
    }
    for w in frame.wall_contacts.as_deref().unwrap_or(&[]) {
        f[w.grain as usize] += w.force;
    }
    f
}

/// Per grain, the sum over its contacts of `f (x) c` (N m): `f` the force on the grain, `c`
/// the vector from its centre to the contact point (Richefeu et al. (2009) eq. 11 before the division by
/// the grain's volume). Grain-grain and grain-wall contacts of the frame count; the frame
/// must have been taken with contacts. Indexed like the frame's grains (slot = permanent id).
pub fn contact_moments(frame: &Frame, periodic: &Periodic<f64>) -> Vec<Tensor> {
    let mut m = vec![DMat3::ZERO; frame.radius.len()];
    let add = |t: &mut Tensor, f: DVec3, c: DVec3| *t += outer(f, c);
    for r in frame.contacts.as_deref().unwrap_or(&[]) {
        let (i, j) = (r.i as usize, r.j as usize);
        let n = contact_normal(frame, periodic, r);
        let (ri, rj) = (frame.radius[i], frame.radius[j]);
        let rp_i = ri - r.overlap * rj / (ri + rj);
        let rp_j = rj - r.overlap * ri / (ri + rj);
        add(&mut m[i], r.force, (n * -rp_i).f64());
        add(&mut m[j], r.force_j, (n * rp_j).f64());
    }
    for w in frame.wall_contacts.as_deref().unwrap_or(&[]) {
        let c = DVec3::new(-w.lever * w.normal[0], -w.lever * w.normal[1], -w.lever * w.normal[2]);
        add(&mut m[w.grain as usize], w.force, c);
    }
    m
}

/// Volume-weighted mean of the particle stresses over a volume (Pa): `(1/V) sum_i sum_c f (x) c`
/// (the particle volumes cancel). Negative in compression, as Richefeu et al. (2009) eq. 11 defines it.
pub fn macroscopic_stress(moments: &[Tensor], volume: f64) -> Tensor {
    let mut s = DMat3::ZERO;
    for t in moments {
        s += *t / volume;
    }
    s
}

/// The sample's box (lower, upper corner, m): the servo box's walls when there is one (from
/// their positions in `stats`), the period along periodic axes, else the grains' extent.
pub fn sample_bounds(scene: &Scene, stats: &crate::engine::Stats, frame: &Frame) -> network::Bounds {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for i in 0..frame.radius.len() {
        for a in 0..3 {
            lo[a] = lo[a].min(frame.position[i][a] - frame.radius[i]);
            hi[a] = hi[a].max(frame.position[i][a] + frame.radius[i]);
        }
    }
    for a in 0..3 {
        if let Some([l, h]) = scene.periodic[a] {
            (lo[a], hi[a]) = (l, h);
        }
    }
    if let Some(servo) = scene.servo {
        for a in 0..3 {
            if let (Some(l), Some(h)) = (stats.walls[servo.walls[2 * a]].position, stats.walls[servo.walls[2 * a + 1]].position) {
                (lo[a], hi[a]) = (l, h);
            }
        }
    }
    (lo, hi)
}

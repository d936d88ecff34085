//! Measures of a packing computed from a frame, and the fits of the experiments.

pub mod fit;

use crate::engine::Frame;
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
pub fn packing_fraction(scene: &Scene, frame: &Frame, piston_z: Option<f64>) -> Option<f64> {
    let area = cross_section(scene.walls.iter().map(|w| &w.shape), &scene.periodic)?;
    let floor = scene.walls.iter().find_map(|w| match w.shape {
        WallShape::Plane { point, normal: [0.0, 0.0, 1.0] } => Some(point[2]),
        _ => None,
    })?;
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

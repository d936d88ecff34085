//! The `[[wall]]` tables of the scene schema, as written by users: each wall kind's keys with
//! their units. [`super::wall_specs`] validates them.

use glam::DVec3;
use serde::Deserialize;

/// `[[wall]]`: a rigid boundary made of `material`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum WallSpec {
    /// Infinite plane; grains live on the side its normal points to.
    Plane {
        /// Name that stages use (default `wall[i]`).
        name: Option<String>,
        /// Material name.
        material: String,
        /// A point on the plane (m).
        point: DVec3,
        /// Normal pointing into the domain (any length).
        normal: DVec3,
        /// Prescribed velocity (m/s). Default 0.
        velocity: Option<DVec3>,
        /// Prescribed angular velocity (rad/s) about the axis through `point`: along the normal
        /// the plane spins in place (a turntable); any other way it turns (a tilting floor, a
        /// gate swinging about a hinge through `point`). Default 0.
        angular_velocity: Option<DVec3>,
    },
    /// Five or six planes bounding an axis-aligned box; grains live inside.
    Box {
        /// Name that stages use for the whole box (default `wall[i]`; its faces are
        /// `NAME.bottom`, `NAME.x_min`, ...).
        name: Option<String>,
        /// Material name.
        material: String,
        /// Lower corner (m).
        min: DVec3,
        /// Upper corner (m).
        max: DVec3,
        /// Leave out the top (z = max) plane. Default false.
        #[serde(default)]
        open_top: bool,
        /// Prescribed velocity of the whole box (m/s). Default 0.
        velocity: Option<DVec3>,
    },
    /// Vertical cylindrical side wall (axis along z, infinite height); grains live inside.
    Cylinder {
        /// Name that stages use (default `wall[i]`).
        name: Option<String>,
        /// Material name.
        material: String,
        /// Axis position (x, y) (m).
        center: [f64; 2],
        /// Radius (m).
        radius: f64,
        /// Prescribed velocity (m/s). Default 0.
        velocity: Option<DVec3>,
        /// Prescribed angular velocity (rad/s), along z: the cylinder spins about its axis (a
        /// drum). Default 0.
        angular_velocity: Option<DVec3>,
    },
    /// A triangle mesh read from an STL file (binary or ASCII), placed by `scale`, then
    /// `rotation`, then `offset`; grains touch either side of its triangles.
    Mesh {
        /// Name that stages use (default `wall[i]`).
        name: Option<String>,
        /// Material name.
        material: String,
        /// The STL file, relative to the scene file's folder.
        file: String,
        /// Factor from the file's units to metres (0.001 for millimetres). Default 1.
        scale: Option<f64>,
        /// Turns (degrees) about x, then y, then z (fixed axes). Default none.
        rotation: Option<DVec3>,
        /// Translation (m) after scaling and turning. Default none.
        offset: Option<DVec3>,
        /// Prescribed velocity (m/s). Default 0.
        velocity: Option<DVec3>,
        /// Prescribed angular velocity (rad/s): the mesh turns about the axis through `center`
        /// (a mixer's blade, a tumbling drum). Default 0.
        angular_velocity: Option<DVec3>,
        /// The point (m) the mesh turns about, carried along by its velocity. Default `offset`
        /// (where the file's origin is placed).
        center: Option<DVec3>,
    },
    /// Six planes bounding a box, each moved along its normal by a servo that holds a target
    /// pressure: wall speed = gain x (target - measured pressure), capped at `max_speed`
    /// (isotropic compaction); a stage's `axial_strain_rate` drives the two z planes at a
    /// fixed strain rate instead (triaxial compression).
    ServoBox {
        /// Material name.
        material: String,
        /// Lower corner (m).
        min: DVec3,
        /// Upper corner (m).
        max: DVec3,
        /// Target pressure (Pa). Default 0 (the walls back off until nothing pushes them).
        #[serde(default)]
        pressure: f64,
        /// Wall speed per pressure error (m/(s Pa)). Default: max_speed / max(pressure, 10 Pa),
        /// full speed for an error as large as the target.
        gain: Option<f64>,
        /// Largest wall speed (m/s). Default 0.005.
        max_speed: Option<f64>,
    },
    /// Horizontal plate facing down whose height follows Newton's law under the grains' push
    /// and a target pressure (stages may change the pressure).
    Piston {
        /// Material name.
        material: String,
        /// Initial height (m).
        z: f64,
        /// Target pressure (Pa), pushing down on the grains. Default 0.
        #[serde(default)]
        pressure: f64,
        /// Mass (kg). Default: the total grain mass.
        mass: Option<f64>,
        /// Area (m^2) the pressure acts on. Default: the cross-section of the scene's cylinder
        /// wall or box.
        area: Option<f64>,
    },
}


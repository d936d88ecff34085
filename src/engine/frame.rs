//! What a run records of an instant: the grains, their contacts and the walls.

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// Quaternions in MCAP frames as the engines keep them, scalar first: `[w, x, y, z]`
/// (`#[serde(with = "scalar_first")]`; glam's own order is `[x, y, z, w]`).
pub mod scalar_first {
    use glam::DQuat;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes each quaternion as `[w, x, y, z]`.
    pub fn serialize<S: Serializer>(q: &Option<Vec<DQuat>>, s: S) -> Result<S::Ok, S::Error> {
        q.as_ref().map(|v| v.iter().map(|q| [q.w, q.x, q.y, q.z]).collect::<Vec<_>>()).serialize(s)
    }

    /// Reads `[w, x, y, z]` quaternions.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<DQuat>>, D::Error> {
        Ok(Option::<Vec<[f64; 4]>>::deserialize(d)?.map(|v| v.into_iter().map(|[w, x, y, z]| DQuat::from_xyzw(x, y, z, w)).collect()))
    }
}

/// One recorded instant: what an MCAP frame holds.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// Simulated time (s).
    pub time: f64,
    /// Permanent grain ids.
    pub id: Vec<u32>,
    /// Centre positions (m).
    pub position: Vec<DVec3>,
    /// Radii (m).
    pub radius: Vec<f64>,
    /// Velocities (m/s).
    pub velocity: Vec<DVec3>,
    /// Angular velocities (rad/s).
    pub angular_velocity: Vec<DVec3>,
    /// Orientation quaternions, when the scene tracks orientation; written scalar first,
    /// `[w, x, y, z]` ([`scalar_first`]).
    #[serde(with = "scalar_first")]
    pub orientation: Option<Vec<DQuat>>,
    /// Touching grain pairs with their forces, when asked for.
    pub contacts: Option<Vec<ContactRecord>>,
    /// Grain-wall contacts with their forces, when contacts are asked for.
    #[serde(default)]
    pub wall_contacts: Option<Vec<WallContactRecord>>,
    /// Every wall's surface where it stands at this instant, in the scene's wall order (servo
    /// walls and the piston move). Not recorded in MCAP frames.
    #[serde(skip)]
    pub walls: Vec<crate::walls::WallGeom<f64>>,
    /// Whether each wall is there (false while a stage has taken it away), in the scene's
    /// wall order. Not recorded in MCAP frames.
    #[serde(skip)]
    pub walls_present: Vec<bool>,
}

impl Frame {
    /// Keeps the grains for which `keep(k)` holds of the `k`th grain listed (and the contacts
    /// between those kept).
    pub fn retain_grains(&mut self, keep: impl Fn(usize) -> bool) {
        let kept: Vec<bool> = (0..self.id.len()).map(keep).collect();
        if kept.iter().all(|&k| k) {
            return;
        }
        fn pick<X: Clone>(v: &mut Vec<X>, kept: &[bool]) {
            let mut k = kept.iter();
            v.retain(|_| *k.next().unwrap_or(&true));
        }
        let gone: std::collections::HashSet<u32> = self.id.iter().zip(&kept).filter(|(_, k)| !**k).map(|(&i, _)| i).collect();
        pick(&mut self.id, &kept);
        pick(&mut self.position, &kept);
        pick(&mut self.radius, &kept);
        pick(&mut self.velocity, &kept);
        pick(&mut self.angular_velocity, &kept);
        if let Some(q) = &mut self.orientation {
            pick(q, &kept);
        }
        if let Some(c) = &mut self.contacts {
            c.retain(|c| !gone.contains(&c.i) && !gone.contains(&c.j));
        }
        if let Some(c) = &mut self.wall_contacts {
            c.retain(|c| !gone.contains(&c.grain));
        }
    }
}

/// One touching pair.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactRecord {
    /// Permanent id of grain i (the lower id).
    pub i: u32,
    /// Permanent id of grain j.
    pub j: u32,
    /// Overlap (m).
    pub overlap: f64,
    /// Total normal force (N, compressive positive, tensile negative): elastic + damping +
    /// capillary, less an adhesive law's pull-off.
    pub normal_force: f64,
    /// Total force on i (N).
    pub force: DVec3,
    /// Total force on j (N): `-force` except in Oquendo et al.'s rolling regime.
    pub force_j: DVec3,
    /// Tangential spring `xi` (m), zero when the model keeps none.
    pub tangential_spring: DVec3,
    /// Rolling spring `psi` (m), zero when the model keeps none.
    #[serde(default)]
    pub rolling_spring: DVec3,
    /// Liquid in the pair's bridge (m^3), zero without one.
    #[serde(default)]
    pub bridge_volume: f64,
}

/// One grain touching one wall. Its force is evaluated from the state of the frame (springs
/// as they stand, not advanced).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WallContactRecord {
    /// Permanent id of the grain.
    pub grain: u32,
    /// Wall index.
    pub wall: u32,
    /// Overlap (m).
    pub overlap: f64,
    /// Unit normal from the wall to the grain.
    pub normal: DVec3,
    /// Distance from the grain's centre to the contact point (m).
    pub lever: f64,
    /// Force on the grain (N).
    pub force: DVec3,
}

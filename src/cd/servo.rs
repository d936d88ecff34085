//! The servo box under contact dynamics. Rigid grains leave no stiffness for a velocity servo
//! to act through (the DEM engine's servo reads a pressure that a rigid packing would jump
//! from 0 to anything); so, as in LMGC90's stress-controlled boxes, the three planes at the
//! low ends of the axes stand still and each of the other three is a body of mass `M` that
//! translates along its normal, pushed inwards by the target pressure times its face, and the
//! contacts' impulses hold it: the solve finds those walls' velocities with the grains', and
//! a wall at rest carries exactly the target pressure. Three fixed planes hold the packing in
//! place: with all six free, grains and walls together could drift at any constant velocity
//! (nothing anchors their momentum), a motion no dissipation stops, and the packing would
//! never come to rest. In triaxial mode the z_max plane instead closes at the strain rate, as
//! prescribed motion (infinite mass).

use super::{ContactDynamics, Partner, WallMotion};
use crate::real::{Real, Vec3};
use crate::walls::WallGeom;

/// The servo box's state.
#[derive(Clone, Copy, Debug)]
pub(super) struct ServoWalls<T> {
    /// Wall indices: x_min, x_max, y_min, y_max, z_min, z_max.
    pub(super) walls: [usize; 6],
    /// Target pressure (Pa).
    pub(super) pressure: T,
    /// Largest speed a wall reaches under its push alone (m/s).
    pub(super) max_speed: T,
    /// Each wall's mass (kg).
    pub(super) mass: T,
    /// Strain rate of the box along z (1/s, positive closing), when the z_max wall is
    /// strain-controlled.
    pub(super) strain_rate: Option<T>,
}

impl<T: Real> ContactDynamics<T> {
    /// Point and inward unit normal of wall `w`, a plane.
    fn plane(&self, w: usize) -> (Vec3<T>, Vec3<T>) {
        match self.walls[w].0 {
            WallGeom::Plane { point, normal } => (point, normal),
            _ => unreachable!("servo walls are planes"),
        }
    }

    /// The box's extent along each axis (m).
    fn extents(&self, s: &ServoWalls<T>) -> [T; 3] {
        let at = |k: usize, a: usize| {
            let p = self.plane(s.walls[k]).0;
            [p.x, p.y, p.z][a]
        };
        [0, 1, 2].map(|a| at(2 * a + 1, a) - at(2 * a, a))
    }

    /// Sets the walls' laws for the step (before the contacts are listed: a wall's mass enters
    /// their Delassus diagonals): the low planes stand still, each pressure-held wall yields
    /// with `1/M`, a strain-controlled one moves as prescribed.
    pub(super) fn servo_prepare(&mut self) {
        let Some(s) = self.servo else { return };
        let extents = self.extents(&s);
        for (k, &w) in s.walls.iter().enumerate() {
            let normal = self.plane(w).1;
            self.wall_motion[w] = match s.strain_rate {
                _ if k % 2 == 0 => WallMotion { vel: Vec3::ZERO, inv_mass: T::ZERO },
                Some(rate) if k == 5 => WallMotion { vel: normal * (rate * extents[2]), inv_mass: T::ZERO },
                _ => WallMotion { vel: self.wall_motion[w].vel, inv_mass: T::ONE / s.mass },
            };
        }
    }

    /// The servo walls' places along their axes (m) and the pressures the grains exert on them
    /// (Pa): each wall's force (N, on the wall, from `stats`) against its inward normal, over
    /// its face.
    pub(super) fn servo_stats(&self, walls: &mut [crate::engine::WallStats]) {
        let Some(s) = self.servo else { return };
        let extents = self.extents(&s);
        for (k, &w) in s.walls.iter().enumerate() {
            let (point, normal) = self.plane(w);
            let a = k / 2;
            let area = (extents[(a + 1) % 3] * extents[(a + 2) % 3]).f64();
            let n = normal.f64();
            let f = walls[w].force;
            walls[w].position = Some([point.x, point.y, point.z][a].f64());
            walls[w].pressure = Some(-(f[0] * n[0] + f[1] * n[1] + f[2] * n[2]) / area);
        }
    }

    /// The free motion of the pressure-held walls over the step: each pushed inwards by the
    /// target pressure over its face, its normal speed capped at the largest speed.
    pub(super) fn servo_kick(&mut self) {
        let Some(s) = self.servo else { return };
        let extents = self.extents(&s);
        for (k, &w) in s.walls.iter().enumerate() {
            let m = &mut self.wall_motion[w];
            if m.inv_mass == T::ZERO {
                continue;
            }
            let normal = match self.walls[w].0 {
                WallGeom::Plane { normal, .. } => normal,
                _ => unreachable!("servo walls are planes"),
            };
            let a = k / 2;
            let area = extents[(a + 1) % 3] * extents[(a + 2) % 3];
            let speed = (m.vel.dot(normal) + self.h * s.pressure * area * m.inv_mass).max(-s.max_speed).min(s.max_speed);
            m.vel = normal * speed;
        }
    }

    /// Moves the servo walls by the theta-method between their velocities before the step
    /// (`before`) and after it, and books their work on the grains: `-R . dx / h` (J) for a
    /// wall that took impulse `R` (N s, its contacts' sum) while moving by `dx` (m).
    pub(super) fn servo_move(&mut self, before: &[WallMotion<T>]) {
        let Some(s) = self.servo else { return };
        let theta = T::of(self.params.theta);
        let mut impulse = [Vec3::<T>::ZERO; 6];
        let tail = self.schedule.tail();
        for c in &self.contacts[tail..] {
            if let Partner::Wall(w) = c.b
                && let Some(k) = s.walls.iter().position(|&sw| sw == w as usize)
            {
                impulse[k] += c.r;
            }
        }
        for (k, &w) in s.walls.iter().enumerate() {
            let (point, normal) = self.plane(w);
            let dx = (self.wall_motion[w].vel * theta + before[w].vel * (T::ONE - theta)) * self.h;
            self.walls[w].0 = WallGeom::Plane { point: point + dx, normal };
            self.external_work -= (impulse[k].dot(dx) / self.h).f64();
        }
    }
}

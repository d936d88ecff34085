//! The walls' controllers: the piston's state, the servo box's six planes and the driven walls.

use super::*;

/// The piston's dynamic state.
#[derive(Clone, Copy, Debug)]
pub(super) struct Piston<T> {
    /// Index into the walls.
    pub(super) wall: usize,
    pub(super) mass: T,
    pub(super) area: T,
    /// Target pressure (Pa).
    pub(super) pressure: T,
}

/// The servo box's control state.
#[derive(Clone, Copy, Debug)]
pub(super) struct Servo<T> {
    /// Wall indices: x_min, x_max, y_min, y_max, z_min, z_max.
    pub(super) walls: [usize; 6],
    /// Target pressure (Pa).
    pub(super) pressure: T,
    /// Wall speed per pressure error (m/(s Pa)).
    pub(super) gain: T,
    /// Largest wall speed (m/s).
    pub(super) max_speed: T,
    /// Strain rate of the z walls (1/s), when they are strain-controlled.
    pub(super) strain_rate: Option<T>,
}

impl<T: Real> CpuEngine<T> {
    /// Plane point and unit normal of wall `w` (a plane).
    pub(super) fn plane(&self, w: usize) -> (Vec3<T>, Vec3<T>) {
        match self.walls[w].geom {
            WallGeom::Plane { point, normal } => (point, normal),
            _ => unreachable!("servo walls are planes"),
        }
    }

    /// Extent of the servo box along each axis (m).
    pub(super) fn servo_extents(&self, s: &Servo<T>) -> [T; 3] {
        let coord = |k: usize, a: usize| {
            let p = self.plane(s.walls[k]).0;
            [p.x, p.y, p.z][a]
        };
        [0, 1, 2].map(|a| coord(2 * a + 1, a) - coord(2 * a, a))
    }

    /// The pressure (Pa) the grains exert on servo wall `k` (0..6) of the box.
    pub(super) fn servo_pressure(&self, s: &Servo<T>, k: usize) -> T {
        let e = self.servo_extents(s);
        let a = k / 2;
        let area = e[(a + 1) % 3] * e[(a + 2) % 3];
        let (_, normal) = self.plane(s.walls[k]);
        -self.wall_reaction[s.walls[k]].dot(normal) / area
    }

    /// Moves the servo walls by `tau` (s): each plane along its normal at
    /// `gain x (target - measured pressure)`, capped at the largest speed; in triaxial mode the
    /// z planes close at the strain rate instead. Books their work on the grains.
    ///
    /// The gain is lowered where the wall's contacts respond strongly: a wall moving at `v` for
    /// `tau` changes the pressure it reads by `(k tau + c) v / A` (`k` the summed contact
    /// stiffness, `c` the summed damping coefficients: a moving wall feels its own dashpots),
    /// so a gain above `A / (k tau + c)` overshoots every step and the wall rattles; the servo
    /// keeps to [`SERVO_RELAXATION`] of that, as YADE's and Thornton's servos do for stiffness.
    pub(super) fn servo_drift(&mut self, tau: T) {
        let Some(s) = self.servo else { return };
        let extents = self.servo_extents(&s);
        for k in 0..6 {
            let w = s.walls[k];
            let (point, normal) = self.plane(w);
            let a = k / 2;
            let area = extents[(a + 1) % 3] * extents[(a + 2) % 3];
            let (k_wall, c_wall) = self.wall_response[w];
            let response = k_wall * tau + c_wall;
            let gain = if response > T::ZERO { s.gain.min(T::of(SERVO_RELAXATION) * area / response) } else { s.gain };
            let speed = match s.strain_rate {
                Some(rate) if k >= 4 => rate * extents[2] * T::of(0.5),
                _ => (gain * (s.pressure - self.servo_pressure(&s, k))).max(-s.max_speed).min(s.max_speed),
            };
            let velocity = normal * speed;
            self.walls[w].geom = WallGeom::Plane { point: point + velocity * tau, normal };
            self.walls[w].velocity = velocity;
            self.external_work -= (self.wall_reaction[w].dot(velocity) * tau).f64();
        }
    }

    /// Moves each driven wall by its velocity for `tau` (s), turns one that turns by its spin,
    /// and books the work it did on the grains: its velocity against the grains' push, and
    /// its spin's power.
    pub(super) fn drive_walls(&mut self, tau: T) {
        for &w in &self.drivable {
            let wall = &mut self.walls[w];
            if wall.velocity == Vec3::ZERO && wall.spin == Vec3::ZERO {
                continue;
            }
            wall.geom = wall.geom.translated(wall.velocity * tau);
            if wall.turns && wall.spin != Vec3::ZERO {
                wall.geom = wall.geom.turned(wall.spin, tau);
            }
            self.external_work += ((self.wall_power[w] - self.wall_reaction[w].dot(wall.velocity)) * tau).f64();
        }
    }
}

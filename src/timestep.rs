//! Time step from the Rayleigh and Hertz times (docs/physics.md "Time step").
//!
//! * Rayleigh time `t_R = pi R_min sqrt(rho / G) / (0.1631 nu + 0.8766)`, `G = E / (2 (1 + nu))`,
//!   for the smallest grain of each material (Hertz law only: the linear law has no elastic
//!   wave speed of its own).
//! * Collision time at the largest expected speed `v`: Hertz
//!   `t_c = 2.868 (m_eff^2 / (R_eff V_eff^2 v))^(1/5)`, linear `pi sqrt(m_eff / k_n)`, for the
//!   smallest grain of each material against the smallest of each other and against each wall
//!   material.
//!
//! `auto` takes the smaller of [`AUTO_RAYLEIGH_FRACTION`] `t_R` and `t_c /`
//! [`AUTO_COLLISION_STEPS`]. A given step above [`WARN_RAYLEIGH_FRACTION`] `t_R` or
//! `t_c /` [`WARN_COLLISION_STEPS`] gets a warning; above [`MAX_RAYLEIGH_FRACTION`] `t_R` or
//! `t_c /` [`MAX_COLLISION_STEPS`] the scene is refused.

use crate::model::{ContactModel, MaterialConstants, NormalSetup};
pub use crate::scene::types::{CharacteristicTimes, TimeStep};
use crate::scene::types::{Grains, Material, Wall};

/// `auto` uses this fraction of the Rayleigh time at most.
pub const AUTO_RAYLEIGH_FRACTION: f64 = 0.1;
/// `auto` resolves a collision in at least this many steps (Hertz error ~1e-4, see tests).
pub const AUTO_COLLISION_STEPS: f64 = 50.0;
/// Above this fraction of `t_R` a given step gets a warning.
pub const WARN_RAYLEIGH_FRACTION: f64 = 0.2;
/// Fewer steps per collision than this gets a warning.
pub const WARN_COLLISION_STEPS: f64 = 20.0;
/// Above this fraction of `t_R` a given step is refused.
pub const MAX_RAYLEIGH_FRACTION: f64 = 1.0;
/// Fewer steps per collision than this is refused.
pub const MAX_COLLISION_STEPS: f64 = 5.0;

impl TimeStep {
    /// The step suggested after an instability (s): half this one, and no more than `auto`
    /// would pick.
    pub fn suggested_after_instability(&self) -> f64 {
        (0.5 * self.dt).min(self.auto_dt())
    }
    /// The `auto` step.
    pub fn auto(times: CharacteristicTimes) -> Self {
        TimeStep { dt: auto_dt(&times), auto: true, times }
    }
    /// A step given by the scene.
    pub fn given(dt: f64, times: CharacteristicTimes) -> Self {
        TimeStep { dt, auto: false, times }
    }
    /// What `auto` would pick (s).
    pub fn auto_dt(&self) -> f64 {
        auto_dt(&self.times)
    }
    /// The largest step accepted (s).
    pub fn safe_limit(&self) -> f64 {
        (MAX_RAYLEIGH_FRACTION * self.times.rayleigh).min(self.times.collision / MAX_COLLISION_STEPS)
    }
    /// Which limit the step breaks, if any.
    pub fn exceeds_limit(&self) -> Option<String> {
        if self.dt > MAX_RAYLEIGH_FRACTION * self.times.rayleigh {
            Some(format!("{MAX_RAYLEIGH_FRACTION} x t_R = {:.3e} s", MAX_RAYLEIGH_FRACTION * self.times.rayleigh))
        } else if self.dt > self.times.collision / MAX_COLLISION_STEPS {
            Some(format!("t_c / {MAX_COLLISION_STEPS} = {:.3e} s at {} m/s", self.times.collision / MAX_COLLISION_STEPS, self.times.expected_speed))
        } else {
            None
        }
    }
    /// A warning when the step is above the recommended fraction.
    pub fn warning(&self) -> Option<String> {
        let warn = (WARN_RAYLEIGH_FRACTION * self.times.rayleigh).min(self.times.collision / WARN_COLLISION_STEPS);
        (self.dt > warn).then(|| {
            format!(
                "above the recommended {warn:.3e} s ({WARN_RAYLEIGH_FRACTION} t_R, t_c/{WARN_COLLISION_STEPS}); expect errors above 0.1% in collisions (\"auto\" gives {:.3e} s)",
                self.auto_dt()
            )
        })
    }
}

fn auto_dt(t: &CharacteristicTimes) -> f64 {
    (AUTO_RAYLEIGH_FRACTION * t.rayleigh).min(t.collision / AUTO_COLLISION_STEPS)
}

/// Rayleigh time (s) of a grain of radius `r` (m).
pub fn rayleigh_time(r: f64, density: f64, youngs_modulus: f64, poisson_ratio: f64) -> f64 {
    let g = youngs_modulus / (2.0 * (1.0 + poisson_ratio));
    std::f64::consts::PI * r * (density / g).sqrt() / (0.1631 * poisson_ratio + 0.8766)
}

pub use crate::model::hertz_collision_time;

/// Largest overlap (m) of an undamped Hertz collision at relative speed `v` (m/s).
pub fn hertz_max_overlap(m_eff: f64, r_eff: f64, v_eff: f64, v: f64) -> f64 {
    (15.0 * m_eff * v * v / (16.0 * v_eff * r_eff.sqrt())).powf(0.4)
}

/// Twice the largest initial speed (two grains meeting head-on), or the free-fall speed over
/// the grains' height span plus one diameter, whichever is larger; at least 1e-3 m/s.
pub fn default_expected_speed(grains: &Grains, gravity: glam::DVec3) -> f64 {
    let g = (gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]).sqrt();
    let v0 = grains.velocity.iter().map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()).fold(0.0, f64::max);
    let fall = if g > 0.0 {
        let up = [-gravity[0] / g, -gravity[1] / g, -gravity[2] / g];
        let heights = grains.position.iter().map(|p| p[0] * up[0] + p[1] * up[1] + p[2] * up[2]);
        let (lo, hi) = heights.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), h| (lo.min(h), hi.max(h)));
        let d_max = 2.0 * grains.radius.iter().copied().fold(0.0, f64::max);
        (2.0 * g * (hi - lo + d_max)).sqrt()
    } else {
        0.0
    };
    (2.0 * v0).max(fall).max(1e-3)
}

/// Rayleigh and collision times of a scene.
pub fn characteristic_times(materials: &[Material], grains: &Grains, walls: &[Wall], model: &ContactModel<f64>, v: f64) -> CharacteristicTimes {
    // Smallest grain per material: (radius, mass).
    let mut smallest: Vec<Option<(f64, f64)>> = vec![None; materials.len()];
    for i in 0..grains.len() {
        let s = &mut smallest[grains.material[i] as usize];
        if s.is_none_or(|(r, _)| grains.radius[i] < r) {
            *s = Some((grains.radius[i], grains.mass[i]));
        }
    }
    let collision = |a: usize, b: Option<usize>, (ra, ma): (f64, f64), other: Option<(f64, f64)>| -> f64 {
        let v_eff = MaterialConstants::effective_stiffness(&materials[a].constants, &materials[b.unwrap_or(a)].constants);
        let (r_eff, m_eff) = match other {
            Some((rb, mb)) => (ra * rb / (ra + rb), ma * mb / (ma + mb)),
            None => (ra, ma),
        };
        model.normal.collision_time(m_eff, r_eff, v_eff, v)
    };
    let mut t_c = f64::INFINITY;
    let mut t_r = f64::INFINITY;
    for (a, sa) in smallest.iter().enumerate() {
        let Some(sa) = *sa else { continue };
        if model.normal.uses_moduli() {
            let m = &materials[a];
            t_r = t_r.min(rayleigh_time(sa.0, m.density.unwrap_or(0.0), m.constants.youngs_modulus, m.constants.poisson_ratio));
        }
        for (b, sb) in smallest.iter().enumerate() {
            if let Some(sb) = *sb {
                t_c = t_c.min(collision(a, Some(b), sa, Some(sb)));
            }
        }
        for w in walls {
            t_c = t_c.min(collision(a, Some(w.material as usize), sa, None));
        }
    }
    CharacteristicTimes { rayleigh: t_r, collision: t_c, expected_speed: v }
}

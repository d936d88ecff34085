//! Contact geometry: normal, overlap, reduced radius and mass, lever arms to the contact point.

use crate::real::{Real, Vec3};

/// Geometry of one contact (Oquendo et al. eq. 3 for the contact point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry<T> {
    /// Unit normal from j to i.
    pub n: Vec3<T>,
    /// Overlap `R_i + R_j - |r_i - r_j|` (m), positive in contact.
    pub h: T,
    /// `R_eff = R_i R_j / (R_i + R_j)` (m); `R_i` for a wall.
    pub r_eff: T,
    /// `m_eff = m_i m_j / (m_i + m_j)` (kg); `m_i` for a wall.
    pub m_eff: T,
    /// `R'_i`: distance from the centre of i to the contact point (m).
    pub rp_i: T,
    /// `R'_j`: distance from the centre of j to the contact point (m); 0 for a wall, whose
    /// angular velocity is zero so that the lever arm never enters.
    pub rp_j: T,
    /// `R'_eff = R'_i R'_j / (R'_i + R'_j)` (m); `R'_i` for a wall.
    pub rp_eff: T,
    /// Radius of i (m).
    pub r_i: T,
    /// Radius of j (m); infinite for a wall.
    pub r_j: T,
}

/// Velocities of the two partners (world frame).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kinematics<T> {
    /// Velocity of i (m/s).
    pub v_i: Vec3<T>,
    /// Velocity of j (m/s); the wall's velocity for a wall.
    pub v_j: Vec3<T>,
    /// Angular velocity of i (rad/s).
    pub w_i: Vec3<T>,
    /// Angular velocity of j (rad/s); zero for a wall.
    pub w_j: Vec3<T>,
}

/// Mass and moment of inertia of the two partners, for Oquendo et al.'s rolling regime.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bodies<T> {
    /// Mass of i (kg).
    pub m_i: T,
    /// Moment of inertia of i (kg m^2).
    pub inertia_i: T,
    /// Mass of j (kg); ignored for a wall.
    pub m_j: T,
    /// Moment of inertia of j (kg m^2); ignored for a wall.
    pub inertia_j: T,
    /// True when j is a wall (infinite radius and mass, no spin).
    pub j_is_wall: bool,
}

impl<T: Real> Geometry<T> {
    /// Geometry of grains i and j from the separation `d = r_i - r_j` (minimum image when the
    /// domain is periodic). `dist` must be positive.
    #[inline(always)]
    pub fn grain_grain(d: Vec3<T>, dist: T, r_i: T, r_j: T, m_i: T, m_j: T) -> Self {
        let h = r_i + r_j - dist;
        let n = d * (T::ONE / dist);
        let inv_sum = T::ONE / (r_i + r_j);
        let rp_i = r_i - h * r_j * inv_sum;
        let rp_j = r_j - h * r_i * inv_sum;
        Geometry {
            n,
            h,
            r_eff: r_i * r_j * inv_sum,
            m_eff: m_i * m_j / (m_i + m_j),
            rp_i,
            rp_j,
            rp_eff: rp_i * rp_j / (rp_i + rp_j),
            r_i,
            r_j,
        }
    }

    /// Radius of i (m).
    #[inline(always)]
    pub fn r_i(&self) -> T {
        self.r_i
    }

    /// Radius of j (m).
    #[inline(always)]
    pub fn r_j(&self) -> T {
        self.r_j
    }

    /// Geometry of grain i against a wall whose surface is at signed distance `dist` from the
    /// centre along the wall's inward unit normal `n` (pointing from the wall to the grain).
    #[inline(always)]
    pub fn grain_wall(n: Vec3<T>, dist: T, r_i: T, m_i: T) -> Self {
        let h = r_i - dist;
        let rp_i = r_i - h;
        Geometry { n, h, r_eff: r_i, m_eff: m_i, rp_i, rp_j: T::ZERO, rp_eff: rp_i, r_i, r_j: T::of(f64::INFINITY) }
    }
}

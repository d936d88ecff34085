//! Per-grain arrays of the CPU engine. The CPU keeps the data one kernel invocation reads
//! together (array of structures: one or two cache lines per grain); the GPU keeps
//! structures of arrays.

use crate::model::{History, HistoryLayout, Regime};
use crate::real::{Real, Vec3};

/// Kinematic state of a grain.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Body<T> {
    /// Centre position (m).
    pub pos: Vec3<T>,
    /// Velocity (m/s).
    pub vel: Vec3<T>,
    /// Angular velocity, world frame (rad/s).
    pub omega: Vec3<T>,
}

/// Constant properties of a grain.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Props<T> {
    /// Radius (m).
    pub radius: T,
    /// Mass (kg).
    pub mass: T,
    /// Moment of inertia `2/5 m R^2` (kg m^2).
    pub inertia: T,
    /// Material index.
    pub material: u32,
}

/// Force and torque on a grain (N, N m).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Load<T> {
    /// Force (N).
    pub force: Vec3<T>,
    /// Torque (N m).
    pub torque: Vec3<T>,
}

/// What the statistics and frames read of a pair's last force evaluation (the forces
/// themselves went to the grains: the owner's share into its load, the partner's into the
/// pair's [`Load`] record).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairReport<T> {
    /// Elastic + damping normal force after the no-pull clamp (N, compressive positive).
    pub f_n: T,
    /// Capillary normal force (N, tensile negative; 0 without a bridge).
    pub f_c: T,
    /// True when the no-pull clamp removed an attractive damping force.
    pub clamped: bool,
    /// The tangential regime.
    pub regime: Regime,
}

/// Where each history block sits in a contact's fixed-stride slot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HistorySlots {
    /// Which blocks exist.
    pub layout: HistoryLayout,
    /// Offset of the tangential spring.
    pub tangential: usize,
    /// Offset of the sliding flag.
    pub sliding: usize,
    /// Offset of the rolling spring.
    pub rolling: usize,
    /// Offset of the bridge volume.
    pub bridge: usize,
    /// Reals per contact.
    pub stride: usize,
}

impl HistorySlots {
    /// Packs the blocks a layout uses, in slot order (tangential, sliding, rolling, bridge).
    pub fn new(layout: HistoryLayout) -> Self {
        let tangential = 0;
        let sliding = if layout.tangential { 3 } else { 0 };
        let rolling = sliding + if layout.sliding { 1 } else { 0 };
        let bridge = rolling + if layout.rolling { 3 } else { 0 };
        let stride = layout.reals();
        HistorySlots { layout, tangential, sliding, rolling, bridge, stride }
    }

    /// Forgets the springs of a contact that has opened, keeping its liquid bridge.
    #[inline(always)]
    pub fn clear_springs<T: Real>(&self, s: &mut [T]) {
        // Fixed-size stores per block: a `fill` of run-time length becomes a call to memset.
        if self.layout.tangential {
            s[self.tangential..self.tangential + 3].copy_from_slice(&[T::ZERO; 3]);
        }
        if self.layout.sliding {
            s[self.sliding] = T::ZERO;
        }
        if self.layout.rolling {
            s[self.rolling..self.rolling + 3].copy_from_slice(&[T::ZERO; 3]);
        }
    }

    /// Reads one contact's history (absent blocks read as zero).
    #[inline(always)]
    pub fn load<T: Real>(&self, s: &[T]) -> History<T> {
        let v = |o: usize| Vec3::new(s[o], s[o + 1], s[o + 2]);
        History {
            tangential: if self.layout.tangential { v(self.tangential) } else { Vec3::ZERO },
            sliding: self.layout.sliding && s[self.sliding] != T::ZERO,
            rolling: if self.layout.rolling { v(self.rolling) } else { Vec3::ZERO },
            bridge: if self.layout.bridge { s[self.bridge] } else { T::ZERO },
        }
    }

    /// Writes one contact's history.
    #[inline(always)]
    pub fn store<T: Real>(&self, h: &History<T>, s: &mut [T]) {
        if self.layout.sliding {
            s[self.sliding] = if h.sliding { T::ONE } else { T::ZERO };
        }
        let mut put = |o: usize, v: Vec3<T>| {
            s[o] = v.x;
            s[o + 1] = v.y;
            s[o + 2] = v.z;
        };
        if self.layout.tangential {
            put(self.tangential, h.tangential);
        }
        if self.layout.rolling {
            put(self.rolling, h.rolling);
        }
        if self.layout.bridge {
            s[self.bridge] = h.bridge;
        }
    }
}

//! Per-grain arrays: the CPU engine's state, and the form the GPU's state is read back in.
//! The CPU keeps the data one kernel invocation reads
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
    /// Moment of inertia `2/5 m R^2` (kg m^2). Kept rather than computed where it is read:
    /// computing it in the kick cost 4-5% of the step on two threads (10^4, f64) for 8 bytes
    /// a grain.
    pub inertia: T,
}

impl<T: Real> Props<T> {
    /// A sphere's properties: its inertia `2/5 m R^2` from the f64 mass and radius, rounded
    /// once to `T` (the GPU's upload takes it from here too).
    pub fn sphere(radius: f64, mass: f64) -> Self {
        Props { radius: T::of(radius), mass: T::of(mass), inertia: T::of(0.4 * mass * radius * radius) }
    }

    /// Whether the grain is in play. A grain out of play (waiting in an inlet's reservoir, or
    /// gone through an outlet: [`crate::flow`]) keeps its slot with its radius stored negated
    /// (WGSL `in_play`, the radius in `pos.w`): it is in no cell and no pair, touches no wall,
    /// feels no gravity, does not move and counts in no statistic.
    #[inline(always)]
    pub fn in_play(&self) -> bool {
        self.radius > T::ZERO
    }

    /// The same grain in play or out of it ([`Self::in_play`]).
    pub fn with_play(self, in_play: bool) -> Self {
        let r = self.radius.abs();
        Props { radius: if in_play { r } else { -r }, ..self }
    }
}

/// Material index of slot `i` in `material`, the engine's indices by slot (empty in a scene
/// of one material, whose grains are all 0).
#[inline(always)]
pub fn material_at(material: &[u32], i: usize) -> usize {
    material.get(i).map_or(0, |&m| m as usize)
}

/// Each grain's periodic image counts (the periods it has crossed along each axis, positive
/// upward), kept for the wrapping axes alone: a scene periodic in x and y keeps two counts a
/// grain, one without periods none. Counts take two bytes each until one reaches
/// [`Images::WIDEN_AT`] periods, four from then on (LAMMPS packs its three into one 32-bit
/// integer, ten bits each, and lets them wrap around).
#[derive(Clone, Debug, PartialEq)]
pub struct Images {
    /// The wrapping axes.
    axes: Vec<usize>,
    /// `axes.len()` counts per grain.
    counts: Counts,
}

/// Image counts, two or four bytes each.
#[derive(Clone, Debug, PartialEq)]
pub enum Counts {
    /// Two bytes each, while every count is below [`Images::WIDEN_AT`].
    Narrow(Vec<i16>),
    /// Four bytes each, once one has reached it.
    Wide(Vec<i32>),
}

impl Default for Images {
    fn default() -> Self {
        Images { axes: Vec::new(), counts: Counts::Narrow(Vec::new()) }
    }
}

/// One image count, of either width.
pub trait ImageCount: Copy + Send + Sync {
    /// Adds `d` periods; returns the sum, or `None` where it does not fit this width (the
    /// count is then left as it was).
    fn add(&mut self, d: i32) -> Option<i32>;
}

impl ImageCount for i16 {
    #[inline]
    fn add(&mut self, d: i32) -> Option<i32> {
        let v = i16::try_from(*self as i32 + d).ok()?;
        *self = v;
        Some(v as i32)
    }
}

impl ImageCount for i32 {
    #[inline]
    fn add(&mut self, d: i32) -> Option<i32> {
        *self = self.checked_add(d)?;
        Some(*self)
    }
}

impl Images {
    /// The magnitude from which counts take four bytes: half of what two hold, so that a
    /// build that finds a count past it widens them while every step since could only have
    /// added a few periods.
    pub const WIDEN_AT: i32 = 1 << 14;

    /// Zero counts for `n` grains along the axes `on`.
    pub fn new(on: [bool; 3], n: usize) -> Self {
        let axes: Vec<usize> = (0..3).filter(|&a| on[a]).collect();
        Images { counts: Counts::Narrow(vec![0; n * axes.len()]), axes }
    }
    /// Counts per grain.
    pub fn width(&self) -> usize {
        self.axes.len()
    }
    /// The wrapping axes.
    pub fn axes(&self) -> &[usize] {
        &self.axes
    }
    /// Grain `i`'s counts along the three axes (0 along the others).
    #[inline]
    pub fn get(&self, i: usize) -> [i32; 3] {
        let w = self.axes.len();
        let mut out = [0; 3];
        for (k, &a) in self.axes.iter().enumerate() {
            out[a] = match &self.counts {
                Counts::Narrow(v) => v[i * w + k] as i32,
                Counts::Wide(v) => v[i * w + k],
            };
        }
        out
    }
    /// Sets grain `i`'s counts (those along the axes that do not wrap are dropped), widening
    /// every count first where one of these reaches [`Self::WIDEN_AT`].
    pub fn set(&mut self, i: usize, c: [i32; 3]) {
        self.widen_for(self.axes.iter().map(|&a| c[a].unsigned_abs()).max().unwrap_or(0));
        let w = self.axes.len();
        for (k, &a) in self.axes.iter().enumerate() {
            match &mut self.counts {
                Counts::Narrow(v) => v[i * w + k] = c[a] as i16,
                Counts::Wide(v) => v[i * w + k] = c[a],
            }
        }
    }
    /// Widens the counts to four bytes when `largest` (the largest count's magnitude) has
    /// reached [`Self::WIDEN_AT`].
    pub fn widen_for(&mut self, largest: u32) {
        if let (Counts::Narrow(v), true) = (&self.counts, largest >= Self::WIDEN_AT as u32) {
            self.counts = Counts::Wide(v.iter().map(|&c| c as i32).collect());
        }
    }
    /// The counts, [`Self::width`] per grain.
    pub fn counts_mut(&mut self) -> &mut Counts {
        &mut self.counts
    }
    /// Bytes allocated.
    pub fn bytes(&self) -> u64 {
        match &self.counts {
            Counts::Narrow(v) => super::allocated(v),
            Counts::Wide(v) => super::allocated(v),
        }
    }
}

/// Force and torque on a grain (N, N m).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Load<T> {
    /// Force (N).
    pub force: Vec3<T>,
    /// Torque (N m).
    pub torque: Vec3<T>,
}

/// What the statistics and frames read of each pair's last force evaluation, one entry per
/// pair in arrays of their own (9 bytes a pair in f64 without cohesion; the forces themselves
/// went to the grains: the owner's share into its load, the partner's into the pair's [`Load`]
/// record).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairReports<T> {
    /// Elastic + damping normal force after the no-pull clamp (N, compressive positive).
    pub f_n: Vec<T>,
    /// Capillary normal force (N, tensile negative; 0 without a bridge); empty in scenes
    /// without cohesion, where it is always 0.
    pub f_c: Vec<T>,
    /// [`PairFlags`]: the tangential regime and the no-pull clamp.
    pub flags: Vec<u8>,
}

impl<T: Real> PairReports<T> {
    /// `n` pairs' worth of zeros, with the capillary force when `capillary`.
    pub fn renew(&mut self, n: usize, capillary: bool) {
        super::renew(&mut self.f_n, n);
        super::renew(&mut self.f_c, if capillary { n } else { 0 });
        super::renew(&mut self.flags, n);
    }
    /// Capillary normal force of pair `k` (N).
    #[inline]
    pub fn f_c(&self, k: usize) -> T {
        self.f_c.get(k).copied().unwrap_or(T::ZERO)
    }
    /// True when the no-pull clamp removed an attractive damping force from pair `k`.
    #[inline]
    pub fn clamped(&self, k: usize) -> bool {
        PairFlags(self.flags[k]).clamped()
    }
    /// Pair `k`'s tangential regime.
    #[inline]
    pub fn regime(&self, k: usize) -> Regime {
        PairFlags(self.flags[k]).regime()
    }
}

/// A pair's tangential regime (bits 0-1, [`Regime`]'s code), whether the no-pull clamp
/// removed an attractive damping force (bit 2) and whether the pair was open with every
/// record zero (bit 3, [`Self::OPEN`]), in one byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PairFlags(pub u8);

impl PairFlags {
    /// A dry pair found open: its force, reports and springs were all set to zero, so that
    /// while it stays open the pair pass need not write them again (a third of a dense
    /// packing's listed pairs, whose zeros were most of the pass's stores). Regime static,
    /// no clamp.
    pub const OPEN: PairFlags = PairFlags(8);

    /// The flags of a regime and a clamp.
    #[inline(always)]
    pub fn new(regime: Regime, clamped: bool) -> Self {
        PairFlags(regime as u8 | (clamped as u8) << 2)
    }
    /// The regime.
    pub fn regime(self) -> Regime {
        Regime::from_code(self.0 & 3)
    }
    /// The clamp.
    pub fn clamped(self) -> bool {
        self.0 & 4 != 0
    }
}

/// Where each history block sits in a contact's fixed-stride slot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HistorySlots {
    /// Which blocks exist.
    pub layout: HistoryLayout,
    /// Offset of the tangential spring.
    pub tangential: usize,
    /// Offset of the normal velocity.
    pub normal: usize,
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
    /// Packs the blocks a layout uses, in slot order (tangential, normal, sliding, rolling,
    /// bridge).
    pub fn new(layout: HistoryLayout) -> Self {
        let tangential = 0;
        let normal = if layout.tangential { 3 } else { 0 };
        let sliding = normal + layout.normal as usize;
        let rolling = sliding + if layout.sliding { 1 } else { 0 };
        let bridge = rolling + if layout.rolling { 3 } else { 0 };
        let stride = layout.reals();
        HistorySlots { layout, tangential, normal, sliding, rolling, bridge, stride }
    }

    /// Forgets the springs and the normal velocity of a contact that has opened, keeping its
    /// liquid bridge.
    #[inline(always)]
    pub fn clear_springs<T: Real>(&self, s: &mut [T]) {
        // Fixed-size stores per block: a `fill` of run-time length becomes a call to memset.
        if self.layout.tangential {
            s[self.tangential..self.tangential + 3].copy_from_slice(&[T::ZERO; 3]);
        }
        if self.layout.normal {
            s[self.normal] = T::ZERO;
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
            v_n: if self.layout.normal { s[self.normal] } else { T::ZERO },
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
        if self.layout.normal {
            s[self.normal] = h.v_n;
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

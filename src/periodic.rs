//! Periodic boundaries: axes along which the domain wraps, with the minimum-image convention.

use crate::real::{Real, Vec3};

/// Which axes wrap, and the interval `[lo, lo + len)` each wraps over.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Periodic<T> {
    /// True for a wrapping axis.
    pub on: [bool; 3],
    /// Lower bound of each wrapping axis (m).
    pub lo: [T; 3],
    /// Period of each wrapping axis (m).
    pub len: [T; 3],
}

impl<T: Real> Periodic<T> {
    /// From the scene's `[periodic]` intervals (f64, m).
    pub fn of(axes: &[Option<[f64; 2]>; 3]) -> Self {
        let mut p = Periodic { on: [false; 3], lo: [T::ZERO; 3], len: [T::ZERO; 3] };
        for (a, axis) in axes.iter().enumerate() {
            if let Some([lo, hi]) = *axis {
                p.on[a] = true;
                p.lo[a] = T::of(lo);
                p.len[a] = T::of(hi - lo);
            }
        }
        p
    }

    /// True when some axis wraps.
    #[inline(always)]
    pub fn any(&self) -> bool {
        self.on[0] || self.on[1] || self.on[2]
    }

    /// The shortest periodic image of a separation `d = r_i - r_j`: one period added or taken
    /// where `|d|` exceeds half of it. Exact for `|d|` below one and a half periods, which holds
    /// for any two grains of the box (wrapped at every rebuild, moved less than the skin
    /// since); compares instead of `floor`, which baseline x86-64 calls out of line.
    #[inline(always)]
    pub fn min_image(&self, mut d: Vec3<T>) -> Vec3<T> {
        let fold = |x: T, len: T| {
            let half = len * T::of(0.5);
            if x > half {
                x - len
            } else if x < -half {
                x + len
            } else {
                x
            }
        };
        if self.on[0] {
            d.x = fold(d.x, self.len[0]);
        }
        if self.on[1] {
            d.y = fold(d.y, self.len[1]);
        }
        if self.on[2] {
            d.z = fold(d.z, self.len[2]);
        }
        d
    }

    /// A position brought into `[lo, lo + len)` along every wrapping axis, and the number of
    /// periods it was moved down by per axis (add `image * len` to unwrap it).
    #[inline(always)]
    pub fn wrap(&self, mut p: Vec3<T>) -> (Vec3<T>, [i32; 3]) {
        let mut image = [0i32; 3];
        let mut c = [p.x, p.y, p.z];
        for a in 0..3 {
            if self.on[a] {
                let n = ((c[a] - self.lo[a]) / self.len[a]).floor();
                let y = c[a] - self.len[a] * n;
                // Rounding can land exactly on lo + len; that is lo, one period further.
                let (y, n) = if y >= self.lo[a] + self.len[a] { (self.lo[a], n + T::ONE) } else { (y, n) };
                c[a] = y;
                image[a] = n.f64() as i32;
            }
        }
        (p.x, p.y, p.z) = (c[0], c[1], c[2]);
        (p, image)
    }

    /// A wrapped position moved back by its image count: the continuous trajectory.
    #[inline(always)]
    pub fn unwrap(&self, p: Vec3<T>, image: [i32; 3]) -> Vec3<T> {
        let shift = |a: usize| if self.on[a] { self.len[a] * T::of(image[a] as f64) } else { T::ZERO };
        Vec3::new(p.x + shift(0), p.y + shift(1), p.z + shift(2))
    }
}

//! Compensated positions: where the engine's number type is [`Real::COMPENSATED`] (`f32`),
//! each grain's position is held as two numbers, `pos + residual`, the residual keeping what
//! rounding took off `pos` ("double-single" arithmetic, from error-free transformations:
//! Knuth's TwoSum). `pos` alone is the position to f32's 24 bits, which is what the spatial
//! hash and the rebuild check read; every separation and every distance to a wall adds the
//! residuals back, so their precision is f32's relative precision of the *separation*, wherever
//! in the domain the grains are: 1e-10 m between 1 mm grains at 1 m from the origin, where the
//! positions alone would give 6e-8 m. A drift adds `v tau` to `pos` and the sum's rounding
//! error to the residual, so a step far smaller than `pos`'s last bit still moves the grain.
//!
//! `f64` engines hold plain positions: their residuals are zero, never stored, never read,
//! and every function here is then the plain operation, with the same bits.
//!
//! The GPU's kernels (`shaders/shared/position.wgsl`) run the same operations in the same
//! order, so that the GPU stays bitwise equal to the CPU's f32 engine.

use crate::periodic::Periodic;
use crate::real::{Real, Vec3};

/// `a + b` as its rounded value `s` and the exact rounding error `e`, `a + b = s + e` exactly
/// (Knuth's TwoSum: six operations, no branch, for any magnitudes of `a` and `b`).
#[inline(always)]
pub fn two_sum<T: Real>(a: T, b: T) -> (T, T) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// A position of the scene (m, f64) in this precision: the rounded position and, when
/// compensated, what the rounding took off.
#[inline]
pub fn split<T: Real>(x: impl Into<glam::DVec3>) -> (Vec3<T>, Vec3<T>) {
    let x = x.into();
    let p: Vec3<T> = Vec3::of(x);
    let r = if T::COMPENSATED { Vec3::of([x[0] - p.x.f64(), x[1] - p.y.f64(), x[2] - p.z.f64()]) } else { Vec3::ZERO };
    (p, r)
}

/// The position `pos + residual` in f64 (m): exact for f32 parts.
#[inline]
pub fn absolute<T: Real>(pos: Vec3<T>, residual: Vec3<T>) -> glam::DVec3 {
    if T::COMPENSATED {
        glam::DVec3::new(pos.x.f64() + residual.x.f64(), pos.y.f64() + residual.y.f64(), pos.z.f64() + residual.z.f64())
    } else {
        pos.f64()
    }
}

/// The residual of slot `i`: `residual[i]` when compensated; zero otherwise, where the array
/// is empty.
#[inline(always)]
pub fn residual_at<T: Real>(residual: &[Vec3<T>], i: usize) -> Vec3<T> {
    if T::COMPENSATED { residual[i] } else { Vec3::ZERO }
}

/// `d + r`: a difference of positions' `pos` parts completed by the difference of their
/// residuals `r` (only when compensated: otherwise `d`, bit for bit).
#[inline(always)]
pub fn complete<T: Real>(d: Vec3<T>, r: Vec3<T>) -> Vec3<T> {
    if T::COMPENSATED { d + r } else { d }
}

/// The separation `r_i - r_j` (m) of two positions, minimum image: the `pos` parts' difference
/// folded by the period (exact for nearby grains: Sterbenz), plus the residuals' difference.
#[inline(always)]
pub fn separation<T: Real>(periodic: &Periodic<T>, p_i: Vec3<T>, r_i: Vec3<T>, p_j: Vec3<T>, r_j: Vec3<T>) -> Vec3<T> {
    complete(periodic.min_image(p_i - p_j), r_i - r_j)
}

/// The separation of slots `i` and `j` of a position array and its residuals.
#[inline(always)]
pub fn separation_of<T: Real>(periodic: &Periodic<T>, pos: impl Fn(usize) -> Vec3<T>, residual: &[Vec3<T>], i: usize, j: usize) -> Vec3<T> {
    separation(periodic, pos(i), residual_at(residual, i), pos(j), residual_at(residual, j))
}

/// Adds `dx` (m) to a position `(pos, residual)`: `pos` gets the rounded sum and the residual
/// what rounding took off, renormalised so that the residual stays below half of `pos`'s last
/// bit. Plain `pos += dx` when not compensated.
#[inline(always)]
pub fn advance<T: Real>(pos: &mut Vec3<T>, residual: &mut Vec3<T>, dx: Vec3<T>) {
    if !T::COMPENSATED {
        *pos += dx;
        return;
    }
    let axis = |p: T, r: T, d: T| {
        let (s, e) = two_sum(p, d);
        two_sum(s, r + e)
    };
    (pos.x, residual.x) = axis(pos.x, residual.x, dx.x);
    (pos.y, residual.y) = axis(pos.y, residual.y, dx.y);
    (pos.z, residual.z) = axis(pos.z, residual.z, dx.z);
}

/// Brings a position into `[lo, lo + len)` along every wrapping axis (see [`Periodic::wrap`]),
/// returning the periods it was moved down by. Compensated, the shift's rounding error goes to
/// the residual (the shift `len n` itself is exact for `|n| <= 2`, all a rebuild sees of grains
/// that moved less than the skin); the result may then sit below `lo` by a rounding, which the
/// grid's clamp and the minimum image absorb.
#[inline(always)]
pub fn wrap<T: Real>(periodic: &Periodic<T>, pos: &mut Vec3<T>, residual: &mut Vec3<T>) -> [i32; 3] {
    if !T::COMPENSATED {
        let (p, image) = periodic.wrap(*pos);
        *pos = p;
        return image;
    }
    let mut image = [0i32; 3];
    let mut c = [pos.x, pos.y, pos.z];
    let mut r = [residual.x, residual.y, residual.z];
    for a in 0..3 {
        if periodic.on[a] {
            let (lo, len) = (periodic.lo[a], periodic.len[a]);
            let mut n = ((c[a] - lo) / len).floor();
            let (s, e) = two_sum(c[a], -(len * n));
            let (mut s, mut e) = two_sum(s, r[a] + e);
            // Rounding can land exactly on lo + len; that is lo, one period further.
            if s >= lo + len {
                let (s2, e2) = two_sum(s, -len);
                (s, e) = two_sum(s2, e + e2);
                n += T::ONE;
            }
            (c[a], r[a]) = (s, e);
            image[a] = n.f64() as i32;
        }
    }
    (pos.x, pos.y, pos.z) = (c[0], c[1], c[2]);
    (residual.x, residual.y, residual.z) = (r[0], r[1], r[2]);
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    /// TwoSum's error is exact: `s + e` equals `a + b` in f64 for f32 inputs.
    #[test]
    fn two_sum_is_exact() {
        for (a, b) in [(1.0f32, 1e-9f32), (0.999_999_9, 3.3e-8), (-1.0e3, 7.1e-5), (1e-20, 1.0), (5.0, -5.0)] {
            let (s, e) = two_sum(a, b);
            assert_eq!(s.f64() + e.f64(), a.f64() + b.f64(), "{a} + {b}");
        }
    }

    /// A million drifts of 1e-9 m at 1 m: plain f32 does not move at all (1e-9 is below half
    /// of 1's last bit), the compensated position moves by 1e-3 m to f64's answer within the
    /// sum's rounding.
    #[test]
    fn small_steps_add_up() {
        let (mut p, mut r) = split::<f32>([1.0, 0.5, -0.25]);
        let mut plain = p;
        let dx = Vec3::new(1e-9f32, -1e-9, 1e-9);
        for _ in 0..1_000_000 {
            advance(&mut p, &mut r, dx);
            plain += dx;
        }
        assert_eq!(plain.x, 1.0, "plain f32 stays put");
        let x = absolute(p, r);
        let want = [1.0 + 1e6 * dx.x.f64(), 0.5 + 1e6 * dx.y.f64(), -0.25 + 1e6 * dx.z.f64()];
        for a in 0..3 {
            // Each addition's result is kept to about 2^-48 relative: 1e6 of them, 1e-8 m.
            assert!((x[a] - want[a]).abs() < 1e-8, "axis {a}: {} against {}", x[a], want[a]);
        }
    }
}

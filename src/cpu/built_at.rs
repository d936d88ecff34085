//! Where each grain was at the last neighbour build, kept in f32 whatever the engine's
//! precision: the rebuild check and the wall-spring candidates need it only to a small part
//! of the skin, and f64 engines save 12 bytes a grain (and as many read by every drift).
//! Rounding to f32 moves a coordinate by at most half an f32 ulp, `|x| 2^-24` (plus half the
//! smallest subnormal near zero). The engine keeps the largest distance between a kept
//! position and the one recorded (its `margin`) and adds it to the largest displacement a
//! drift finds, once per drift; so a grain is never found to have moved less than it has, nor
//! to be farther from a wall than it is. In f32 engines the position is kept exactly and the
//! margin is zero: the same bits as the GPU's rebuild check.

use crate::real::{Real, Vec3};

/// Half an f32 ulp, relative: the largest rounding of a normal f32, `2^-24`.
const HALF_ULP: f64 = 1.0 / 16_777_216.0;
/// Half the smallest f32 subnormal, `2^-150` (m): the largest rounding near zero.
const HALF_SUBNORMAL: f64 = 7.006_492_321_624_085e-46;

/// `pos` as kept.
#[inline(always)]
pub fn record<T: Real>(pos: Vec3<T>) -> Vec3<f32> {
    Vec3::new(pos.x.f64() as f32, pos.y.f64() as f32, pos.z.f64() as f32)
}

/// The kept position in `T`.
#[inline(always)]
pub fn widen<T: Real>(at: Vec3<f32>) -> Vec3<T> {
    Vec3::new(T::of(at.x.f64()), T::of(at.y.f64()), T::of(at.z.f64()))
}

/// A bound on the distance between a position kept as `at` and the one recorded, from `at`
/// alone (m; zero in f32, which rounds nothing): where the recorded one is not at hand (a
/// restored state).
#[inline(always)]
pub fn bound<T: Real>(at: Vec3<f32>) -> T {
    if exact::<T>() {
        return T::ZERO;
    }
    let r = |x: f32| x.abs().f64() * HALF_ULP + HALF_SUBNORMAL;
    T::of(Vec3::new(r(at.x), r(at.y), r(at.z)).norm())
}

/// The squared displacement of a grain now at `pos` from where it was kept, `at` (m^2).
#[inline(always)]
pub fn moved2<T: Real>(pos: Vec3<T>, at: Vec3<f32>) -> T {
    (pos - widen(at)).norm2()
}

/// A bound on the squared displacement since the recording, from the largest `moved2` and the
/// `margin` (`(sqrt(moved2) + margin)^2`; `moved2` itself, bit for bit, where the margin is
/// zero).
#[inline(always)]
pub fn with_margin<T: Real>(moved2: T, margin: T) -> T {
    if margin == T::ZERO {
        return moved2;
    }
    let d = moved2.sqrt() + margin;
    d * d
}

/// True when `T` rounds nothing on its way to f32 (the f32 engine and its GPU twin).
#[inline(always)]
fn exact<T: Real>() -> bool {
    std::mem::size_of::<T>() <= std::mem::size_of::<f32>()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At 1 km from the origin in f64, where f32 rounds by up to 3e-5 m: the kept position
    /// lies within the bound of the recorded one, and the displacement with the margin covers
    /// the true one of grains that moved 0 and 1e-5 m, adding no more than twice the margin;
    /// in f32 nothing is added.
    #[test]
    fn the_margin_covers_the_rounding_and_no_more() {
        let points: Vec<Vec3<f64>> = (0..1000).map(|k| Vec3::new(1000.0 + k as f64 * 1.37e-6, -999.5 - k as f64 * 2.9e-6, 0.1 + k as f64 * 1e-9)).collect();
        let kept: Vec<Vec3<f32>> = points.iter().map(|&p| record(p)).collect();
        let margin = points.iter().zip(&kept).map(|(&p, &at)| (p - widen(at)).norm()).fold(0.0, f64::max);
        assert!(margin > 0.0, "f32 must round these positions");
        for (&p, &at) in points.iter().zip(&kept) {
            assert!((p - widen::<f64>(at)).norm() <= bound::<f64>(at), "kept {at:?} is farther than its bound from {p:?}");
            for step in [Vec3::ZERO, Vec3::new(1.0e-5, 0.0, -3.0e-6)] {
                let truth = step.norm();
                let found = with_margin(moved2(p + step, at), margin).sqrt();
                assert!(found >= truth, "{found} below the displacement {truth}");
                assert!(found <= truth + 2.0 * margin, "{found} more than twice the margin {margin} above {truth}");
            }
        }
        let p = Vec3::new(0.3f32, -0.7, 1.1);
        assert_eq!(bound::<f32>(record(p)), 0.0);
        assert_eq!(with_margin(moved2(p + Vec3::new(1.0e-4, 0.0, 0.0), record(p)), 0.0f32), (p + Vec3::new(1.0e-4f32, 0.0, 0.0) - p).norm2());
    }
}

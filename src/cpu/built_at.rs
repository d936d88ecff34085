//! Where each grain was at the last neighbour build, kept in f32 whatever the engine's
//! precision: the rebuild check and the wall-spring candidates need it only to a small part
//! of the skin, and f64 engines save 12 bytes a grain (and as many read by every drift).
//! Rounding to f32 moves a coordinate by at most half an f32 ulp, `|x| 2^-24` (plus the
//! smallest subnormal's worth near zero); each reader adds that bound, so a grain is never
//! found to have moved less than it has, nor to be farther from a wall than it is. In f32
//! engines the position is kept exactly and nothing is added: the same bits as the GPU's
//! rebuild check.

use crate::real::{Real, Vec3};

/// True when `T` rounds nothing on its way to f32 (the f32 engine and its GPU twin).
#[inline(always)]
fn exact<T: Real>() -> bool {
    std::mem::size_of::<T>() <= std::mem::size_of::<f32>()
}

/// Half an f32 ulp, relative: the largest rounding of a normal f32, `2^-24`.
const HALF_ULP: f64 = 1.0 / 16_777_216.0;
/// Half the smallest f32 subnormal, `2^-150` (m): the largest rounding near zero.
const HALF_SUBNORMAL: f64 = 7.006_492_321_624_085e-46;

/// `pos` as kept.
#[inline(always)]
pub fn record<T: Real>(pos: Vec3<T>) -> Vec3<f32> {
    Vec3::new(pos.x.f64() as f32, pos.y.f64() as f32, pos.z.f64() as f32)
}

/// Bound on how far a coordinate kept as `x` lies from the one recorded (m).
#[inline(always)]
fn rounding<T: Real>(x: f32) -> T {
    if exact::<T>() { T::ZERO } else { T::of(x.f64()).abs() * T::of(HALF_ULP) + T::of(HALF_SUBNORMAL) }
}

/// The kept position in `T` and a bound on its distance to the one recorded (m; zero in f32).
#[inline(always)]
pub fn recorded<T: Real>(at: Vec3<f32>) -> (Vec3<T>, T) {
    let x = Vec3::new(T::of(at.x.f64()), T::of(at.y.f64()), T::of(at.z.f64()));
    let e = Vec3::new(rounding::<T>(at.x), rounding::<T>(at.y), rounding::<T>(at.z));
    (x, e.norm())
}

/// A bound on the squared displacement of a grain now at `pos` since it was recorded at `at`
/// (m^2): each axis' distance to the kept position plus its rounding bound. In f32,
/// `(pos - at)^2` exactly.
#[inline(always)]
pub fn moved2<T: Real>(pos: Vec3<T>, at: Vec3<f32>) -> T {
    let d = |p: T, a: f32| (p - T::of(a.f64())).abs() + rounding::<T>(a);
    if exact::<T>() { (pos - Vec3::new(T::of(at.x.f64()), T::of(at.y.f64()), T::of(at.z.f64()))).norm2() } else { Vec3::new(d(pos.x, at.x), d(pos.y, at.y), d(pos.z, at.z)).norm2() }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At 1 km from the origin in f64, where f32 rounds by up to 3e-5 m: the bound covers the
    /// true displacement of grains that moved 0 and 1e-5 m, and adds no more than twice the
    /// rounding; in f32 the displacement is exact.
    #[test]
    fn the_bound_covers_the_rounding_and_no_more() {
        let mut worst = 0.0f64;
        for k in 0..1000 {
            let p = Vec3::new(1000.0 + k as f64 * 1.37e-6, -999.5 - k as f64 * 2.9e-6, 0.1 + k as f64 * 1e-9);
            let at = record(p);
            let (x, e) = recorded::<f64>(at);
            assert!((x - p).norm() <= e, "kept {x:?} is farther than {e} from {p:?}");
            for step in [Vec3::ZERO, Vec3::new(1.0e-5, 0.0, -3.0e-6)] {
                let (now, truth) = (p + step, step.norm());
                let bound = moved2::<f64>(now, at).sqrt();
                assert!(bound >= truth, "bound {bound} below the displacement {truth}");
                worst = worst.max(bound - truth);
            }
        }
        // Two roundings of at most 1000 * 2^-24 = 6.0e-5 m each, in 3 axes.
        assert!(worst <= 2.0 * 3.0f64.sqrt() * 1000.0 * HALF_ULP * 1.01, "bound {worst} m above the displacement");
        let p = Vec3::new(0.3f32, -0.7, 1.1);
        assert_eq!(moved2::<f32>(p + Vec3::new(1.0e-4, 0.0, 0.0), record(p)), (Vec3::new(1.0e-4f32, 0.0, 0.0) + p - p).norm2());
    }
}

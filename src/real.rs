//! The floating-point type the CPU engine is generic over (`f32` or `f64`) and a small
//! 3-vector over it.
//!
//! The GPU works in `f32`; the CPU engine runs the same kernels in `f32` (to compare with the
//! GPU) or `f64` (the reference that errors are measured against).

use std::fmt::Debug;
use std::iter::Sum;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real scalar: `f32` or `f64`.
pub trait Real:
    Copy
    + Send
    + Sync
    + Debug
    + Default
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + Sum
    + 'static
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// Name used in reports: "f32" or "f64".
    const NAME: &'static str;
    /// True when the engines hold each position as two numbers of this type, `pos +
    /// residual`, the residual keeping what rounding took off `pos` ([`crate::position`]):
    /// `f32`, whose 24 bits at 1 m are 6e-8 m, coarser than a stiff contact's overlap.
    /// `f64` holds plain positions (1e-16 m at 1 m).
    const COMPENSATED: bool;
    /// True for the GPU's precision (`f32`): its CPU engine is the GPU's twin and adds the
    /// walls' sums in the GPU's workgroup order ([`crate::workgroup`]), so the two agree bit
    /// for bit. `f64`, the reference, keeps its running sums over fixed chunks of ids, the order
    /// every figure the documentation quotes from it was computed in.
    const GPU_TWIN: bool;
    /// Converts from `f64`, rounding to nearest.
    fn of(x: f64) -> Self;
    /// Widens to `f64`.
    fn f64(self) -> f64;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `self^e`.
    fn powf(self, e: Self) -> Self;
    /// `e^self`.
    fn exp(self) -> Self;
    /// The larger of two values.
    fn max(self, o: Self) -> Self;
    /// The smaller of two values.
    fn min(self, o: Self) -> Self;
    /// Largest integer not above `self`.
    fn floor(self) -> Self;
    /// True unless NaN or infinite.
    fn is_finite(self) -> bool;
}

macro_rules! impl_real {
    ($t:ty, $compensated:expr, $gpu_twin:expr) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const NAME: &'static str = stringify!($t);
            const COMPENSATED: bool = $compensated;
            const GPU_TWIN: bool = $gpu_twin;
            #[inline(always)]
            fn of(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn f64(self) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline(always)]
            fn powf(self, e: Self) -> Self {
                <$t>::powf(self, e)
            }
            #[inline(always)]
            fn exp(self) -> Self {
                <$t>::exp(self)
            }
            #[inline(always)]
            fn max(self, o: Self) -> Self {
                <$t>::max(self, o)
            }
            #[inline(always)]
            fn min(self, o: Self) -> Self {
                <$t>::min(self, o)
            }
            #[inline(always)]
            fn floor(self) -> Self {
                <$t>::floor(self)
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
        }
    };
}
impl_real!(f32, true, true);
impl_real!(f64, false, false);

/// A 3-vector of reals (metres, m/s, N, ... as its owner says).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec3<T> {
    /// x component.
    pub x: T,
    /// y component.
    pub y: T,
    /// z component.
    pub z: T,
}

impl<T: Real> Vec3<T> {
    /// The zero vector.
    pub const ZERO: Self = Vec3 { x: T::ZERO, y: T::ZERO, z: T::ZERO };

    /// Builds a vector from components.
    #[inline(always)]
    pub fn new(x: T, y: T, z: T) -> Self {
        Vec3 { x, y, z }
    }
    /// Converts a vector of the scene (f64: a `glam::DVec3` or `[f64; 3]`) to this precision.
    #[inline]
    pub fn of(a: impl Into<glam::DVec3>) -> Self {
        let a = a.into();
        Vec3::new(T::of(a.x), T::of(a.y), T::of(a.z))
    }
    /// Widens to the scene's f64 vector.
    #[inline]
    pub fn f64(self) -> glam::DVec3 {
        glam::DVec3::new(self.x.f64(), self.y.f64(), self.z.f64())
    }
    /// Dot product.
    #[inline(always)]
    pub fn dot(self, o: Self) -> T {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// Cross product `self x o`.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    /// Squared Euclidean norm.
    #[inline(always)]
    pub fn norm2(self) -> T {
        self.dot(self)
    }
    /// Euclidean norm.
    #[inline(always)]
    pub fn norm(self) -> T {
        self.norm2().sqrt()
    }
    /// True when every component is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

impl<T: Real> Add for Vec3<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl<T: Real> Sub for Vec3<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl<T: Real> Neg for Vec3<T> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}
impl<T: Real> Mul<T> for Vec3<T> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: T) -> Self {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl<T: Real> AddAssign for Vec3<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<T: Real> SubAssign for Vec3<T> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

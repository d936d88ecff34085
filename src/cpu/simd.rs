//! Run-time choice of the instruction set for the hot loops: one binary for every x86-64,
//! whose pair pass and gather run compiled for x86-64-v4 (AVX-512) or -v3 (AVX2) when the
//! CPU has them. Rust never fuses a multiply and an add unless asked (`mul_add`, which is
//! exact either way), and vector square roots and divisions are correctly rounded, so every
//! level gives the same bits (tests/determinism.rs checks it on the machine it runs on).

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::OnceLock;

/// An instruction-set level, narrowest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[repr(u8)]
pub enum Level {
    /// The baseline the binary was built for.
    Portable = 0,
    /// x86-64-v3: AVX, AVX2, FMA, BMI1/2, LZCNT, POPCNT, MOVBE, F16C.
    V3 = 1,
    /// x86-64-v4: v3 plus AVX-512 F, VL, DQ, BW, CD.
    V4 = 2,
}

/// The widest level the hot loops may use: `u8::MAX` until [`set_max_level`] narrows it.
static MAX_LEVEL: AtomicU8 = AtomicU8::new(u8::MAX);

/// Caps the level the hot loops use from now on (for cross-checks: every level gives the
/// same bits). The environment variable `GRAINS_SIMD=portable|v3|v4` sets the same cap.
pub fn set_max_level(level: Level) {
    MAX_LEVEL.store(level as u8, Ordering::Relaxed);
}

/// The widest level this CPU supports (detected once), capped by `GRAINS_SIMD`.
pub fn supported() -> Level {
    static DETECTED: OnceLock<Level> = OnceLock::new();
    *DETECTED.get_or_init(|| {
        let cap = match std::env::var("GRAINS_SIMD").as_deref() {
            Ok("portable") => Level::Portable,
            Ok("v3") => Level::V3,
            _ => Level::V4,
        };
        detect().min(cap)
    })
}

/// The level the hot loops use: [`supported`] capped by [`set_max_level`].
pub fn level() -> Level {
    match MAX_LEVEL.load(Ordering::Relaxed) {
        0 => Level::Portable,
        1 => supported().min(Level::V3),
        _ => supported(),
    }
}

#[cfg(target_arch = "x86_64")]
fn detect() -> Level {
    use std::arch::is_x86_feature_detected as has;
    let v3 = has!("avx") && has!("avx2") && has!("fma") && has!("bmi1") && has!("bmi2") && has!("lzcnt") && has!("popcnt") && has!("movbe") && has!("f16c");
    let v4 = v3 && has!("avx512f") && has!("avx512vl") && has!("avx512dq") && has!("avx512bw") && has!("avx512cd");
    if v4 {
        Level::V4
    } else if v3 {
        Level::V3
    } else {
        Level::Portable
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn detect() -> Level {
    Level::Portable
}

/// Defines `fn $name<T: Real>(args) [-> R]` that calls `$portable(args)` (an `#[inline(always)]`
/// function) compiled for the widest [`Level`] the CPU has.
macro_rules! dispatch {
    ($(#[$meta:meta])* $vis:vis fn $name:ident<$T:ident: Real>($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? => $portable:ident) => {
        $(#[$meta])*
        $vis fn $name<$T: Real>($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,movbe,f16c,avx512f,avx512vl,avx512dq,avx512bw,avx512cd")]
                fn v4<$T: Real>($($arg: $ty),*) $(-> $ret)? {
                    $portable($($arg),*)
                }
                #[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,movbe,f16c")]
                fn v3<$T: Real>($($arg: $ty),*) $(-> $ret)? {
                    $portable($($arg),*)
                }
                match $crate::cpu::simd::level() {
                    // SAFETY: `level()` found every feature these builds enable on this CPU.
                    #[allow(unsafe_code)]
                    $crate::cpu::simd::Level::V4 => return unsafe { v4($($arg),*) },
                    #[allow(unsafe_code)]
                    $crate::cpu::simd::Level::V3 => return unsafe { v3($($arg),*) },
                    $crate::cpu::simd::Level::Portable => {}
                }
            }
            $portable($($arg),*)
        }
    };
}
pub(crate) use dispatch;

/// Asks the CPU to bring the cache line holding `x` into its nearest cache ahead of a load (a
/// hint: it changes no result, only when the data arrive).
#[inline(always)]
pub fn prefetch<X>(x: &X) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `_mm_prefetch` needs SSE, which is part of the x86-64 baseline every build has;
    // a prefetch reads nothing the program sees and cannot fault.
    #[allow(unsafe_code)]
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>((x as *const X).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

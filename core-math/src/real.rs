//! The scalar interface the closed form is written against, once, for f64 and f32.
//!
//! Only what the model needs: field arithmetic, a correctly rounded square root,
//! and sine/cosine for the per-update work (never per pixel).

use core::ops::{Add, Mul, Neg, Sub};

/// The least a backend's scalar must offer: a widening to f64 for tools and tests.
/// [`Real`] (f64, f32) extends it; the fixed-point backend's I24F40 implements only this.
pub trait Scalar: Copy + core::fmt::Debug {
    /// The value as an f64 (exact for f32 and f64; rounded to nearest for I24F40).
    fn to_f64(self) -> f64;
}

/// A binary floating-point scalar: `f64` or `f32`.
pub trait Real:
    Scalar
    + Copy
    + PartialOrd
    + core::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + core::ops::Div<Output = Self>
    + Neg<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
    /// The distance from 1 to the next value (2^-52, 2^-23): what a truncated series
    /// must reach.
    const EPSILON: Self;
    /// Round an f64 to this type (round to nearest even).
    fn from_f64(x: f64) -> Self;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// (sin x, cos x), each within 2 ulp (f32: `trig::sin_cos_f32`, 1.54 ulp measured).
    fn sin_cos(self) -> (Self, Self);
    /// sin x, the same value as `sin_cos(x).0` (f32: `trig::sin_f32`, one polynomial
    /// instead of two).
    fn sin(self) -> Self {
        self.sin_cos().0
    }
    fn is_finite(self) -> bool;
    /// |x| (one `vabs.f32` on the target).
    fn abs(self) -> Self;
    /// Largest integer not above `self`.
    fn floor(self) -> Self;
    /// Conversion to u32, saturating at 0 and `u32::MAX` (NaN gives 0), as Rust's `as`.
    fn to_u32(self) -> u32;
    fn from_u32(n: u32) -> Self;
    /// An i16 exactly (a DEM node height in metres).
    fn from_i16(n: i16) -> Self;
    /// An f32 exactly (f64) or as is (f32).
    fn from_f32(x: f32) -> Self;
    /// atan(x) (f32: libm's `atanf`, pure f32, 0.85 ulp; used once per segment, never
    /// per pixel).
    fn atan(self) -> Self;
    /// (sin x, cos x) for |x| <= 0.15 by truncated Taylor series, to this type's
    /// precision: no call, a handful of multiply-adds. Used per pixel near the limb.
    fn small_sin_cos(x: Self) -> (Self, Self);
    /// Cube root (libm's `cbrt`, `cbrtf`): the geodetic conversion's one root of its
    /// cubic resolvent, once per call.
    fn cbrt(self) -> Self;
    /// atan2(self, x) in [-pi, pi] (libm's `atan2`, `atan2f`).
    fn atan2(self, x: Self) -> Self;
    /// sqrt(self^2 + y^2) without intermediate overflow (libm's `hypot`, `hypotf`).
    fn hypot(self, y: Self) -> Self;
}

impl Scalar for f64 {
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
}

impl Scalar for f32 {
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
}

/// The interface scalar of both fixed-point backends (the round Earth's and the real
/// Earth's): here, so that either feature alone has it.
#[cfg(feature = "earth-fixed")]
impl Scalar for fixed::types::I24F40 {
    #[inline]
    fn to_f64(self) -> f64 {
        self.to_num::<f64>()
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const EPSILON: Self = f64::EPSILON;
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        crate::trig_f64::sin_cos(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        libm::floor(self)
    }
    #[inline(always)]
    fn to_u32(self) -> u32 {
        self as u32
    }
    #[inline(always)]
    fn from_u32(n: u32) -> Self {
        n as f64
    }
    #[inline(always)]
    fn from_i16(n: i16) -> Self {
        f64::from(n)
    }
    #[inline(always)]
    fn from_f32(x: f32) -> Self {
        f64::from(x)
    }
    #[inline(always)]
    fn atan(self) -> Self {
        libm::atan(self)
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        libm::cbrt(self)
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        libm::atan2(self, x)
    }
    #[inline(always)]
    fn hypot(self, y: Self) -> Self {
        libm::hypot(self, y)
    }
    /// Terms to x^9 and x^10: the first omitted ones are below 1.2e-17 x and 2.7e-19.
    #[inline(always)]
    fn small_sin_cos(x: Self) -> (Self, Self) {
        let x2 = x * x;
        let s = x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0))));
        let c = 1.0
            - x2 / 2.0
                * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0))));
        (s, c)
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const EPSILON: Self = f32::EPSILON;
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        crate::sqrt::sqrt_f32(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        crate::trig::sin_cos_f32(self)
    }
    #[inline(always)]
    fn sin(self) -> Self {
        crate::trig::sin_f32(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        libm::floorf(self)
    }
    #[inline(always)]
    fn to_u32(self) -> u32 {
        self as u32
    }
    #[inline(always)]
    fn from_u32(n: u32) -> Self {
        n as f32
    }
    #[inline(always)]
    fn from_i16(n: i16) -> Self {
        f32::from(n)
    }
    #[inline(always)]
    fn from_f32(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn atan(self) -> Self {
        libm::atanf(self)
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        libm::cbrtf(self)
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        libm::atan2f(self, x)
    }
    #[inline(always)]
    fn hypot(self, y: Self) -> Self {
        libm::hypotf(self, y)
    }
    /// Terms to x^5 and x^4: the first omitted ones are below 3.5e-10 x and 1.6e-8,
    /// both under f32's unit roundoff (6e-8) relative to the results.
    #[inline(always)]
    fn small_sin_cos(x: Self) -> (Self, Self) {
        let x2 = x * x;
        let s = x * (1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * 0.05));
        let c = 1.0 - x2 * 0.5 * (1.0 - x2 * (1.0 / 12.0));
        (s, c)
    }
}

//! The f32 closed form with `micromath`'s sine and cosine: a variant measured by
//! `cargo xtask report`, never the shipped path.
//!
//! The closed form calls transcendental functions only in `update` (sine and cosine of
//! roll, inclination and argument of latitude); per pixel it needs one square root.
//! `micromath` 2.1 documents its `sin`/`cos` to 0.002 absolute and its `sqrt` to ~5 %
//! (a bit trick). The square root here stays `vsqrt.f32`, one instruction and correctly
//! rounded, since micromath's could only lose; the sine and cosine are micromath's. The
//! report shows what that costs in accuracy against what it saves in instructions.

use core::ops::{Add, Div, Mul, Neg, Sub};

use micromath::F32Ext;

use crate::real::{Real, Scalar};

/// An f32 whose `sin_cos` is micromath's (everything else as f32).
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct MicroF32(pub f32);

macro_rules! binary_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for MicroF32 {
            type Output = MicroF32;
            #[inline(always)]
            fn $method(self, rhs: MicroF32) -> MicroF32 {
                MicroF32(self.0 $op rhs.0)
            }
        }
    };
}
binary_op!(Add, add, +);
binary_op!(Sub, sub, -);
binary_op!(Mul, mul, *);
binary_op!(Div, div, /);

impl Neg for MicroF32 {
    type Output = MicroF32;
    #[inline(always)]
    fn neg(self) -> MicroF32 {
        MicroF32(-self.0)
    }
}

impl Scalar for MicroF32 {
    #[inline(always)]
    fn to_f64(self) -> f64 {
        f64::from(self.0)
    }
}

impl Real for MicroF32 {
    const ZERO: Self = MicroF32(0.0);
    const ONE: Self = MicroF32(1.0);
    const EPSILON: Self = MicroF32(f32::EPSILON);
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        MicroF32(<f32 as Real>::from_f64(x))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        MicroF32(crate::sqrt::sqrt_f32(self.0))
    }
    /// micromath's approximations, 0.002 absolute (its documentation).
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        (MicroF32(F32Ext::sin(self.0)), MicroF32(F32Ext::cos(self.0)))
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        self.0.is_finite()
    }
    #[inline(always)]
    fn abs(self) -> Self {
        MicroF32(self.0.abs())
    }
    #[inline(always)]
    fn floor(self) -> Self {
        MicroF32(<f32 as Real>::floor(self.0))
    }
    #[inline(always)]
    fn to_u32(self) -> u32 {
        <f32 as Real>::to_u32(self.0)
    }
    #[inline(always)]
    fn from_u32(n: u32) -> Self {
        MicroF32(<f32 as Real>::from_u32(n))
    }
    #[inline(always)]
    fn from_i16(n: i16) -> Self {
        MicroF32(f32::from(n))
    }
    #[inline(always)]
    fn from_f32(x: f32) -> Self {
        MicroF32(x)
    }
    /// micromath's atan (2.8e-3, EMBEDDED-NOTES.md), consistent with the variant.
    #[inline(always)]
    fn atan(self) -> Self {
        MicroF32(F32Ext::atan(self.0))
    }
    #[inline(always)]
    fn small_sin_cos(x: Self) -> (Self, Self) {
        let (s, c) = <f32 as Real>::small_sin_cos(x.0);
        (MicroF32(s), MicroF32(c))
    }
    /// The round-Earth model needs no geodetic conversion: libm's, as f32.
    #[inline(always)]
    fn cbrt(self) -> Self {
        MicroF32(<f32 as Real>::cbrt(self.0))
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        MicroF32(<f32 as Real>::atan2(self.0, x.0))
    }
    #[inline(always)]
    fn hypot(self, y: Self) -> Self {
        MicroF32(<f32 as Real>::hypot(self.0, y.0))
    }
}

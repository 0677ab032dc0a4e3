//! Three-vectors as plain arrays `[T; 3]`, the one set of helpers every model and tool
//! shares (f64, f32, and the reference's dual numbers alike).
//!
//! Each function fixes its order of operations, so that a caller gets the same bits
//! wherever the helper replaced a hand-written copy: `dot` sums x, y, z from the left.

use core::ops::{Add, Div, Mul, Sub};

/// a . b = a0 b0 + a1 b1 + a2 b2 (summed in that order).
// Out of line on the M3, where its products are software calls: inlined at six
// callers (docs/target.md, flash).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
#[cfg_attr(
    not(all(target_arch = "arm", not(target_abi = "eabihf"))),
    inline(always)
)]
pub fn dot<T>(a: [T; 3], b: [T; 3]) -> T
where
    T: Copy + Add<Output = T> + Mul<Output = T>,
{
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a x b.
#[inline(always)]
pub fn cross<T>(a: [T; 3], b: [T; 3]) -> [T; 3]
where
    T: Copy + Sub<Output = T> + Mul<Output = T>,
{
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// a + b.
#[inline(always)]
pub fn add<T: Copy + Add<Output = T>>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a - b.
#[inline(always)]
pub fn sub<T: Copy + Sub<Output = T>>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// s a.
#[inline(always)]
pub fn scale<T: Copy + Mul<Output = T>>(s: T, a: [T; 3]) -> [T; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

/// A scalar with a correctly rounded square root: what [`norm`] and [`unit()`] need.
pub trait Sqrt: Copy {
    fn sqrt(self) -> Self;
}

impl Sqrt for f64 {
    #[inline(always)]
    fn sqrt(self) -> f64 {
        libm::sqrt(self)
    }
}

impl Sqrt for f32 {
    #[inline(always)]
    fn sqrt(self) -> f32 {
        crate::real::Real::sqrt(self)
    }
}

/// |a| = sqrt(a . a).
#[inline(always)]
pub fn norm<T>(a: [T; 3]) -> T
where
    T: Sqrt + Add<Output = T> + Mul<Output = T>,
{
    dot(a, a).sqrt()
}

/// a / |a|; for a != 0 only (callers check).
#[inline(always)]
pub fn unit<T>(a: [T; 3]) -> [T; 3]
where
    T: Sqrt + Add<Output = T> + Mul<Output = T> + Div<Output = T>,
{
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn right_handed_and_orthogonal() {
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(cross(x, y), z);
        assert_eq!(cross(y, z), x);
        assert_eq!(cross(z, x), y);
        let (a, b) = ([1.5, -2.0, 0.25], [0.5, 3.0, -4.0]);
        let c = cross(a, b);
        assert_eq!(dot(a, c), 0.0);
        assert_eq!(dot(b, c), 0.0);
        // |a x b|^2 + (a . b)^2 = |a|^2 |b|^2 (Lagrange), exact in these dyadic values.
        assert_eq!(dot(c, c) + dot(a, b) * dot(a, b), dot(a, a) * dot(b, b));
    }

    #[test]
    fn unit_has_length_one_and_the_direction() {
        let a = [3.0f64, 4.0, 12.0];
        assert_eq!(norm(a), 13.0);
        assert_eq!(unit(a), [3.0 / 13.0, 4.0 / 13.0, 12.0 / 13.0]);
        assert_eq!(add(a, sub([0.0; 3], a)), [0.0; 3]);
        assert_eq!(scale(2.0, a), add(a, a));
    }
}

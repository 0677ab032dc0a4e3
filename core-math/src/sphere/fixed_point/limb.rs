//! The nadir angle of the limb, L = asin(1/k) = pi/2 - atan(sqrt(c0)), integer only, for
//! the per-update constants of the near-limb form.

/// Q62 multiply, rounded, on i128 operands below 2^63 in magnitude.
#[inline]
fn mul62(a: i128, b: i128) -> i128 {
    (a * b + (1 << 61)) >> 62
}

/// round(pi/3 * 2^62) and round(2^62 / sqrt(3)).
const PI_THIRD_Q62: i128 = 4_829_346_305_384_748_562;
const INV_SQRT3_Q62: i128 = 2_662_558_164_157_085_850;

/// (-1)^k / (2k + 1) in Q62, k = 0..=10: the Taylor series of atan(y)/y to y^20.
const ATAN: [i128; 11] = {
    let mut t = [0i128; 11];
    let mut k = 0;
    while k < 11 {
        let d = 2 * k as i128 + 1;
        let c = ((1i128 << 62) + d / 2) / d;
        t[k] = if k % 2 == 0 { c } else { -c };
        k += 1;
    }
    t
};

/// (L in Q62, sqrt(c0) in Q62) for c0 = k^2 - 1 in Q62, c0 in [0.06, 0.74] (the
/// envelope).
///
/// sqrt(c0) by the exact integer square root of c0 2^62 (u128). Then
/// atan(x) = pi/6 + atan(y), y = (x - 1/sqrt 3) / (1 + x/sqrt 3), |y| <= 0.285 over the
/// envelope (one i128 division), and atan(y) by its Taylor series to y^21 (truncation
/// below 0.285^23/23 = 1.4e-14): L = pi/3 - atan(y). Unit test against libm's asin:
/// within 1.7e-14 rad, four orders below what the near-limb form needs (1e-10).
pub(crate) fn limb_angle(c0_q62: i128) -> (i128, i128) {
    let x = ((c0_q62 as u128) << 62).isqrt() as i128; // Q62, in [0.25, 0.86]
    let y = ((x - INV_SQRT3_Q62) << 62) / ((1 << 62) + mul62(x, INV_SQRT3_Q62));
    let y2 = mul62(y, y);
    let mut p = ATAN[10];
    for &c in ATAN[..10].iter().rev() {
        p = c + mul62(y2, p);
    }
    (PI_THIRD_Q62 - mul62(y, p), x)
}

//! f32 sine, cosine and arc tangent in f32 arithmetic only, for the per-update work.
//!
//! `libm::sincosf` is correctly rounded to 0.5 ulp but evaluates in (soft) f64 on the
//! Cortex-M4F, many times the cost of a polynomial (counts: shared/EMBEDDED-NOTES.md,
//! docs/bench.md). Here: reduce by pi/2 with a three-part Cody-Waite constant (each
//! k * part exact for |k| < 2^13, i.e. |x| < 12 800 rad), then the minimax polynomials
//! of Cephes' `sinf`/`cosf` on [-pi/4, pi/4]. Measured error against f64 over
//! |x| <= 100 rad: at most 1.54 ulp (`core-math/tests/trig.rs`). Larger arguments, which
//! the model never produces, fall back to the f64 `sincos` of [`crate::trig_f64`],
//! rounded (NaN from 2^20 pi/2 rad on).

use crate::wide::Wide;

/// pi/2 = P1 + P2 + P3, P1 and P2 with trailing zero bits (Cephes' DP1..DP3, doubled).
const P1: f32 = 1.570_312_5;
const P2: f32 = 4.837_513e-4;
const P3: f32 = 7.549_79e-8;
const TWO_OVER_PI: f32 = core::f32::consts::FRAC_2_PI;
/// Beyond this |x| the reduction is not exact: f64 ([`sin_cos_huge`]).
const FAST_LIMIT: f32 = 12_800.0;

/// sin r and cos r for |r| <= pi/4 (Cephes coefficients).
#[inline(always)]
fn kernel(r: f32) -> (f32, f32) {
    (kernel_sin(r), kernel_cos(r))
}

#[inline(always)]
fn kernel_sin(r: f32) -> f32 {
    let z = r * r;
    r + r * z * (-1.666_665_5e-1 + z * (8.332_161e-3 + z * -1.951_529_6e-4))
}

#[inline(always)]
fn kernel_cos(r: f32) -> f32 {
    let z = r * r;
    1.0 - 0.5 * z + z * z * (4.166_664_6e-2 + z * (-1.388_731_6e-3 + z * 2.443_315_7e-5))
}

/// The nearest quadrant k of x and the remainder r = x - k pi/2 (|x| < [`FAST_LIMIT`]).
#[inline(always)]
fn reduce(x: f32) -> (i32, f32) {
    // Nearest quadrant; `as i32` of a value under 2^13 in magnitude is exact.
    let q = x * TWO_OVER_PI;
    let k = (q + if q >= 0.0 { 0.5 } else { -0.5 }) as i32;
    let kf = k as f32;
    (k, ((x - kf * P1) - kf * P2) - kf * P3)
}

/// sin x in f32: `sin_cos_f32(x).0` bit for bit, evaluating only the polynomial its
/// quadrant needs (the sinc beyond its first zero: the drift smear of an unsteered
/// camera).
#[inline(always)]
pub fn sin_f32(x: f32) -> f32 {
    if !(x.abs() < FAST_LIMIT) {
        return sin_cos_huge(x).0;
    }
    let (k, r) = reduce(x);
    let v = if k & 1 == 0 {
        kernel_sin(r)
    } else {
        kernel_cos(r)
    };
    if k & 2 == 0 {
        v
    } else {
        -v
    }
}

/// (sin x, cos x) in f32.
///
/// Inlined, with the f64 route for huge arguments kept out of line: as one function the
/// fallback's register saves made every call pay a prologue (`cargo xtask bench
/// --profile` shows it).
#[inline(always)]
pub fn sin_cos_f32(x: f32) -> (f32, f32) {
    if !(x.abs() < FAST_LIMIT) {
        return sin_cos_huge(x);
    }
    let (k, r) = reduce(x);
    let (s, c) = kernel(r);
    match k & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// (sin x, cos x) in integers, rounded once to f32, for a core without an FPU (the
/// Cortex-M3's per-update attitude: docs/fixed-point.md, "The update on the Cortex-M3"):
/// |x| in Q60, reduced by pi/2 in Q60 to r, then sin r = r S(r^2) and cos r = C(r^2),
/// the Taylor polynomials (degrees 5 and 6 in r^2) by Horner's rule in Q30 and 32 x 32
/// products, r's product by S in [`Wide`]. Within 1e-8 relative before the rounding to
/// f32 (`core-math/tests/trig.rs`); |x| >= 4 rad and non-finite arguments: the f64
/// `sincos` of the exact argument, rounded to f32 (as [`sin_cos_f32`] beyond 12 800 rad).
pub fn sin_cos_int(x: f32) -> (f32, f32) {
    let bits = x.to_bits();
    let biased = (bits >> 23) & 0xff;
    // |x| < 2^-20: sin x = x and cos x = 1 to f32's rounding (x^2 / 6 < 2^-42).
    if biased < 107 {
        return (x, 1.0);
    }
    // |x| >= 4, NaN, infinities: no attitude the scene's envelope allows, so the cold
    // f64 route (inlined, `sin_cos_f32` was a second copy of it beside the planner's).
    if biased >= 129 {
        return sin_cos_huge(x);
    }
    // |x| = mant 2^(biased - 150), in Q60: a left shift of 17 to 38, below 2^62.
    let a = u64::from((bits & 0x7f_ffff) | 0x80_0000) << (biased - 90);
    // The nearest quadrant k (|x| < 4 < 7 pi / 4: k <= 3) and r = |x| - k pi / 2.
    let k = (a > QUARTER_PI_Q60) as u64
        + (a > 3 * QUARTER_PI_Q60) as u64
        + (a > 5 * QUARTER_PI_Q60) as u64;
    let r = a as i64 - (k * HALF_PI_Q60) as i64;
    let r_abs = r.unsigned_abs();
    // r^2 in Q30 (|r| <= pi / 4: r in Q30 below 2^30), truncated.
    let r30 = (r_abs >> 30) as u32;
    let z = ((u64::from(r30) * u64::from(r30)) >> 30) as i32;
    let horner = |c: &[i32]| {
        let mut acc = c[c.len() - 1];
        for &ck in c[..c.len() - 1].iter().rev() {
            acc = ((i64::from(acc) * i64::from(z) + (1 << 29)) >> 30) as i32 + ck;
        }
        acc
    };
    // S and C in [0.7, 1]: positive.
    let s_r = (Wide::from_u64(r_abs, -60) * Wide::from_u64(horner(&SIN_Q30) as u64, -30)).to_f32();
    let s_r = if r < 0 { -s_r } else { s_r };
    let c_r = Wide::from_u64(horner(&COS_Q30) as u64, -30).to_f32();
    let (s, c) = match k {
        0 => (s_r, c_r),
        1 => (c_r, -s_r),
        2 => (-s_r, -c_r),
        _ => (-c_r, s_r),
    };
    if bits >> 31 != 0 {
        (-s, c)
    } else {
        (s, c)
    }
}

/// (sin x, cos x) in Q30 for x in Q30 on [0, pi/2] (the Cortex-M3's yaw request, from
/// its integer drift angle): x or pi/2 - x, whichever is at most pi/4, then
/// [`sin_cos_int`]'s polynomials in Q30, r S(r^2) one 32 x 32 product. Within 3 units of
/// Q30 (`core-math/tests/trig.rs`); x is clamped to [0, pi/2].
pub fn sin_cos_q30(x_q30: i32) -> (i32, i32) {
    const HALF_PI_Q30: i32 = 1_686_629_713;
    const QUARTER_PI_Q30: i32 = 843_314_857;
    let x = x_q30.clamp(0, HALF_PI_Q30);
    let (r, swap) = if x > QUARTER_PI_Q30 {
        (HALF_PI_Q30 - x, true)
    } else {
        (x, false)
    };
    let (s, c) = sin_cos_reduced_q30(r);
    if swap {
        (c, s)
    } else {
        (s, c)
    }
}

/// (sin x, cos x) in Q30 of an f32 angle |x| < 4 rad (the Cortex-M3's per-instant
/// attitude, `controller/src/update/instant.rs`): [`sin_cos_int`]'s reduction by pi/2 in
/// Q60, r rounded to Q30, then [`sin_cos_q30`]'s polynomials. Within 4 units of Q30
/// (`core-math/tests/trig.rs`); None for |x| >= 4 and non-finite x.
// Out of line: the attitude's three angles, each a copy inlined.
#[inline(never)]
pub fn sin_cos_f32_q30(x: f32) -> Option<(i32, i32)> {
    let bits = x.to_bits();
    let biased = (bits >> 23) & 0xff;
    if biased >= 129 {
        return None;
    }
    // |x| in Q60 (a left shift of 0 to 38; below 2^-20 the shift is right, and r's
    // rounding to Q30 below makes sin x = x, cos x = 1 within a unit).
    let mant = u64::from((bits & 0x7f_ffff) | 0x80_0000);
    let a = if biased == 0 {
        0
    } else if biased >= 90 {
        mant << (biased - 90)
    } else {
        mant.checked_shr(90 - biased).unwrap_or(0)
    };
    let k = (a > QUARTER_PI_Q60) as u64
        + (a > 3 * QUARTER_PI_Q60) as u64
        + (a > 5 * QUARTER_PI_Q60) as u64;
    let r = a as i64 - (k * HALF_PI_Q60) as i64;
    let r30 = ((r + (1 << 29)) >> 30) as i32;
    let (s_r, c_r) = sin_cos_reduced_q30(r30);
    let (s, c) = match k {
        0 => (s_r, c_r),
        1 => (c_r, -s_r),
        2 => (-s_r, -c_r),
        _ => (-c_r, s_r),
    };
    Some(if bits >> 31 != 0 { (-s, c) } else { (s, c) })
}

/// (sin r, cos r) in Q30 for r in Q30 with |r| <= pi/4: the Taylor polynomials of
/// [`sin_cos_int`], r S(r^2) one 32 x 32 product. Out of line: one copy for
/// [`sin_cos_q30`] and [`sin_cos_f32_q30`].
#[inline(never)]
fn sin_cos_reduced_q30(r: i32) -> (i32, i32) {
    let z = ((i64::from(r) * i64::from(r)) >> 30) as i32;
    let horner = |c: &[i32]| {
        let mut acc = c[c.len() - 1];
        for &ck in c[..c.len() - 1].iter().rev() {
            acc = ((i64::from(acc) * i64::from(z) + (1 << 29)) >> 30) as i32 + ck;
        }
        acc
    };
    let s = ((i64::from(r) * i64::from(horner(&SIN_Q30)) + (1 << 29)) >> 30) as i32;
    (s, horner(&COS_Q30))
}

/// pi/4 and pi/2 in Q60, rounded.
const QUARTER_PI_Q60: u64 = 905_502_432_259_640_355;
const HALF_PI_Q60: u64 = 1_811_004_864_519_280_711;
/// sin(r) / r = sum (-1)^k r^(2k) / (2k+1)!, k = 0..=5, in Q30 (the next term is below
/// 9e-12 on |r| <= pi/4).
const SIN_Q30: [i32; 6] = [1_073_741_824, -178_956_971, 8_947_849, -213_044, 2_959, -27];
/// cos(r) = sum (-1)^k r^(2k) / (2k)!, k = 0..=6, in Q30 (the next term below 7e-13).
const COS_Q30: [i32; 7] = [
    1_073_741_824,
    -536_870_912,
    44_739_243,
    -1_491_308,
    26_631,
    -296,
    2,
];

/// (sin x, cos x) for the arguments the reduction cannot take (|x| >= 12 800 rad, and
/// NaN, infinities): the f64 `sincos` of the exact argument, rounded to f32 (libm's
/// bit for bit; NaN from 2^20 pi/2 rad on, [`crate::trig_f64`]). Not
/// `sincosf`: its own reduction would add 3.2 KB of flash, and the f64 one is linked
/// anyway (the planner's boot-time work). Within 0.5 ulp + 1 f64 ulp.
#[cold]
#[inline(never)]
fn sin_cos_huge(x: f32) -> (f32, f32) {
    let (s, c) = crate::trig_f64::sin_cos(f64::from(x));
    (s as f32, c as f32)
}

/// tan(3 pi / 8) = 1 + sqrt 2 and tan(pi / 8) = sqrt 2 - 1: the ends of the three
/// reduction ranges of [`atan_f32`].
const TAN_3PI_8: f32 = 2.414_213_5;
const TAN_PI_8: f32 = 0.414_213_57;

/// atan x in f32 (rad), for the drift angles of every segment.
///
/// `libm::atanf` is pure f32 here but branches through four ranges and a long
/// polynomial. Here: Cephes' `atanf`, the argument
/// reduced to |x| <= tan(pi/8) by atan x = pi/4 + atan((x-1)/(x+1)) or
/// pi/2 + atan(-1/x) (one `vdiv.f32`), then its degree-9 odd minimax polynomial. Measured
/// error against f64 over every magnitude: 2.18 ulp (`core-math/tests/trig.rs`). NaN stays NaN;
/// +-inf gives +-pi/2.
///
/// Inlined up to tan(3 pi/8): below tan(pi/8) no reduction is needed (the drift
/// tangents of a steered camera: the polynomial alone), and up to tan(3 pi/8) (an
/// unsteered camera in a roll slew, drifts to 1.2 rad) the reduction is one division.
/// Beyond, and NaN, out of line. The same operations in the same order as
/// [`atan_reduced`], so bit for bit the same results.
// Out of line on the M3, whose update takes the integer arctangents: there
// this one is the cold routes', each of which inlined it (docs/target.md, flash).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
#[cfg_attr(
    not(all(target_arch = "arm", not(target_abi = "eabihf"))),
    inline(always)
)]
pub fn atan_f32(x: f32) -> f32 {
    let a = x.abs();
    if a <= TAN_PI_8 {
        // The polynomial is odd and IEEE rounding symmetric: on x itself it gives
        // copysign(p(|x|), x) exactly, without the sign's transfer. The `+ 0.0` turns the -0 of z p(z) at z = 0 into +0 and changes no
        // other value, so that atan(-0) = -0 + (-0) keeps its sign.
        let z = x * x;
        return (atan_poly(z) * z + 0.0) * x + x;
    }
    if a <= TAN_3PI_8 {
        let r = (a - 1.0) / (a + 1.0);
        return atan_from(core::f32::consts::FRAC_PI_4, PI_4_LO, r, x);
    }
    atan_reduced(x)
}

/// pi/4 - FRAC_PI_4 and pi/2 - FRAC_PI_2: the rounding errors of the base angles.
const PI_4_LO: f32 = -2.185_569_5e-8;
const PI_2_LO: f32 = -4.371_139e-8;

/// Cephes' degree-9 odd minimax polynomial of atan on |r| <= tan(pi/8), as
/// p(r^2) r^3 + r.
#[inline(always)]
fn atan_poly(z: f32) -> f32 {
    ((8.053_744_5e-2 * z - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1
}

/// atan x for every x (the polynomial's range reduced as in [`atan_f32`]): the out of
/// line part of [`atan_f32`], for |x| > tan(3 pi/8) and NaN; and [`atan_f32`] as a call
/// for callers off the per-segment path, bit for bit its results (tested below).
#[inline(never)]
pub fn atan_reduced(x: f32) -> f32 {
    let a = x.abs();
    // The base angle as an f32 plus its rounding error (pi/2 - FRAC_PI_2 and
    // pi/4 - FRAC_PI_4), added to the small part first: just above tan(pi/8) the
    // rounding of pi/4 alone is 0.7 ulp of the result.
    let (base, base_lo, r) = if a > TAN_3PI_8 {
        (core::f32::consts::FRAC_PI_2, PI_2_LO, -1.0 / a)
    } else if a > TAN_PI_8 {
        (core::f32::consts::FRAC_PI_4, PI_4_LO, (a - 1.0) / (a + 1.0))
    } else {
        (0.0, 0.0, a)
    };
    atan_from(base, base_lo, r, x)
}

/// atan x from its reduction: the base angle (an f32 plus its rounding error, added to
/// the small part first) and the reduced argument r, |r| <= tan(pi/8).
#[inline(always)]
fn atan_from(base: f32, base_lo: f32, r: f32, x: f32) -> f32 {
    let z = r * r;
    let p = atan_poly(z) * z * r + r;
    let p = p + base_lo;
    // The sign of x on the result keeps atan odd, -0 included.
    (base + p).copysign(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sin_f32` is `sin_cos_f32`'s sine, bit for bit, over every magnitude and sign.
    #[test]
    fn sin_alone_is_the_sine_of_sin_cos() {
        let mut x = 1e-30f32;
        while x < 1e30 {
            for v in [x, -x] {
                assert_eq!(
                    sin_f32(v).to_bits(),
                    sin_cos_f32(v).0.to_bits(),
                    "x = {v:e}"
                );
            }
            x = f32::from_bits(x.to_bits() + 7_919);
        }
        for v in [0.0f32, -0.0, f32::INFINITY, f32::NAN, 12_800.0, -12_800.0] {
            assert_eq!(
                sin_f32(v).to_bits(),
                sin_cos_f32(v).0.to_bits(),
                "x = {v:e}"
            );
        }
    }

    /// The inlined ranges of `atan_f32` give bit for bit what the general reduced form
    /// gives (the accuracy test in `tests/trig.rs` then covers both).
    #[test]
    fn inlined_atan_ranges_match_the_reduced_form_bit_for_bit() {
        let mut x = 1e-30f32;
        let mut checked = 0;
        while x < 1e30 {
            for v in [x, -x] {
                assert_eq!(
                    atan_f32(v).to_bits(),
                    atan_reduced(v).to_bits(),
                    "x = {v:e}"
                );
            }
            checked += 1;
            // About 130 000 arguments, dense everywhere on a log scale.
            x = f32::from_bits(x.to_bits() + 7_919);
        }
        assert!(checked > 100_000, "{checked}");
        for v in [
            0.0f32, -0.0, TAN_PI_8, -TAN_PI_8, TAN_3PI_8, -TAN_3PI_8, 1.0, -1.0,
        ] {
            assert_eq!(
                atan_f32(v).to_bits(),
                atan_reduced(v).to_bits(),
                "x = {v:e}"
            );
        }
    }
}

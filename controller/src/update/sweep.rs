//! A segment's samples swept: v1's extremes and the largest drift over them, by the f32
//! row form or the fixed-point pixels, and the drift angles from their tangents.

use super::*;

/// What a segment's samples show: v1's signed extremes, and the (|v2|, |v1|) of the
/// largest |v2/v1| over the samples and the centre.
#[derive(Clone, Copy)]
pub(super) struct Extremes {
    pub(super) centre: ImageMotion<f32>,
    pub(super) lo: f32,
    pub(super) hi: f32,
    pub(super) drift_v2: f32,
    pub(super) drift_v1: f32,
}

/// The segment's row at this update, its centre, and the samples' [`Extremes`] (the
/// centre's drift included).
///
/// Its own function, never inlined: the loop's square root is a call
/// (`core_math::sqrt`), which clobbers s0-s15; inlined into `segment`, whose values
/// then live across it, every sample reloaded many of them. Here the row's constants
/// and the running extremes nearly fit the callee-saved s16-s31. The row is formed here
/// from the update in memory: formed by the caller and passed by reference, its
/// constants went through the stack. The steered centre stays out of here: computed in
/// here too, it made the update's values reload across the calls. (The counts:
/// docs/controller.md, "What it costs".)
#[inline(never)]
pub(super) fn extremes(update: &GeneralUpdate<f32>, seg: &SegmentPlan) -> Result<Extremes, Fault> {
    let row = GENERAL_F32.row_motion(update, &seg.row);
    // The samples run from the segment's first pixel to its last, the centre between:
    // when both ends face the ground, every pixel does, and each one costs one check
    // instead of three (`GeneralRowMotion::motion_at_facing`: the same results and
    // errors). Otherwise some pixel misses, and the checked route finds which first.
    let ends = (seg.samples.get(1), seg.samples.last());
    match ends {
        (Some(a), Some(b)) if row.faces_ground_over(a.p2_m, b.p2_m) => {
            sweep(seg, |_, p2| row.motion_at_facing(p2))
        }
        _ => sweep_checked(&row, seg),
    }
}

#[cold]
#[inline(never)]
pub(super) fn sweep_checked(
    row: &GeneralRowMotion<f32>,
    seg: &SegmentPlan,
) -> Result<Extremes, Fault> {
    sweep(seg, |_, p2| row.motion_at(p2))
}

/// The centre's motion, then the extremes over the centre and the samples, by
/// `motion_at` (`SegmentPlan::samples`: the centre first).
#[inline(always)]
pub(super) fn sweep(
    seg: &SegmentPlan,
    mut motion_at: impl FnMut(usize, f32) -> Result<ImageMotion<f32>, core_math::ModelError>,
) -> Result<Extremes, Fault> {
    let Some((first, samples)) = seg.samples.split_first() else {
        return Err(Fault::InvalidScene);
    };
    let centre = motion_at(0, first.p2_m)?;
    // Comparisons, not f32::min/max: those are software calls on this core
    // (fminf/fmaxf, NaN handling). `motion_at` refuses a NaN v1.
    let mut e = Extremes {
        centre,
        lo: centre.v1_mps,
        hi: centre.v1_mps,
        drift_v2: centre.v2_mps.abs(),
        drift_v1: centre.v1_mps.abs(),
    };
    for (j, sample) in samples.iter().enumerate() {
        let m = motion_at(j + 1, sample.p2_m)?;
        if m.v1_mps < e.lo {
            e.lo = m.v1_mps;
        }
        if m.v1_mps > e.hi {
            e.hi = m.v1_mps;
        }
        let (v1, v2) = (m.v1_mps.abs(), m.v2_mps.abs());
        if v2 * e.drift_v1 > e.drift_v2 * v1 {
            (e.drift_v2, e.drift_v1) = (v2, v1);
        }
    }
    Ok(e)
}

/// The extremes of the centre and the samples by the fixed-point backend
/// (`SegmentPlan::fixed`: the centre first), integer only per pixel: v1's extremes
/// compared as I24F40 bits, the largest |v2/v1| by cross-multiplying the bits' magnitudes
/// (exact in u128).
#[cfg(feature = "earth-fixed")]
#[inline(never)]
pub(super) fn extremes_fixed(g: &Ground, seg: &SegmentPlan) -> Result<ExtremesBits, Fault> {
    use core_math::EARTH_FIXED;
    let Some(up) = g.fixed() else {
        return Err(Fault::InvalidScene);
    };
    let Some((first, pixels)) = seg.fixed.split_first() else {
        return Err(Fault::InvalidScene);
    };
    let centre = EARTH_FIXED.motion(up, first)?;
    let (c1, c2) = (centre.v1_mps.to_bits(), centre.v2_mps.to_bits());
    let (mut lo, mut hi) = (c1, c1);
    let (mut d2, mut d1) = (c2.unsigned_abs(), c1.unsigned_abs());
    for px in pixels {
        let m = EARTH_FIXED.motion(up, px)?;
        let (v1, v2) = (m.v1_mps.to_bits(), m.v2_mps.to_bits());
        lo = lo.min(v1);
        hi = hi.max(v1);
        let (a1, a2) = (v1.unsigned_abs(), v2.unsigned_abs());
        if u128::from(a2) * u128::from(d1) > u128::from(d2) * u128::from(a1) {
            (d2, d1) = (a2, a1);
        }
    }
    Ok(ExtremesBits {
        c1,
        c2,
        lo,
        hi,
        d2,
        d1,
    })
}

/// The segment's centre pixel seen by the camera turned by the yaw request
/// (`General::motion_yawed`).
#[inline(always)]
pub(super) fn steered_centre(
    update: &GeneralUpdate<f32>,
    seg: &SegmentPlan,
    sin: f32,
    cos: f32,
) -> Result<ImageMotion<f32>, core_math::ModelError> {
    GENERAL_F32.motion_yawed(update, &seg.centre, sin, cos)
}

/// A segment's drift angles from their tangents: at the centre, the worst (`tan_max`
/// >= |`tan_centre`|), and the steered centre's.
///
/// The worst is the centre's magnitude plus atan of the tangent of their difference,
/// (tan_max - |t|) / (1 + tan_max |t|): a small tangent, which `atan_f32` takes without
/// reduction, where the worst drift itself (0.8 rad in a roll slew) needs one; and the
/// sum is never below the centre's.
#[inline(always)]
pub(super) fn drift_angles_rad(tan_centre: f32, tan_max: f32, tan_residual: f32) -> [f32; 3] {
    let centre_rad = drift_angle_rad(tan_centre);
    let t = tan_centre.abs();
    let beyond_rad = drift_angle_rad((tan_max - t) / (1.0 + tan_max * t));
    [
        centre_rad,
        centre_rad.abs() + beyond_rad,
        drift_angle_rad(tan_residual),
    ]
}

/// The drift angle atan(t) (rad) of a drift tangent t = v2/v1: `core_math::trig::atan_f32`
/// (accurate to a few ulp, and cheaper than libm's `atanf`: docs/controller.md), which
/// the drift smear of keystoned outer segments (|t| up to 0.3 at 20 deg of pitch) needs
/// beyond any short series.
#[inline(always)]
pub fn drift_angle_rad(t: f32) -> f32 {
    core_math::trig::atan_f32(t)
}

/// atan(`num` / `den`) (rad) in integers, for a core without an FPU: the two f32
/// mantissas aligned to 32 bits (the smaller truncated), then [`atan_norm_rad`]. Non-finite
/// inputs and a zero `den`: `atan_f32` of the f32 quotient.
#[cfg(feature = "earth-fixed")]
#[inline(never)]
pub(super) fn atan_pair_rad(num: f32, den: f32) -> f32 {
    let (a, b) = (num.to_bits() & 0x7fff_ffff, den.to_bits() & 0x7fff_ffff);
    if a >= 0x7f80_0000 || !(0x0080_0000..0x7f80_0000).contains(&b) {
        return atan_pair_cold(num, den);
    }
    // For positive finite f32s the bits order as the values.
    let (small, big, past_one) = if a <= b { (a, b, false) } else { (b, a, true) };
    let mantissa = |x: u32| ((x & 0x7f_ffff) | 0x80_0000) << 8;
    // A subnormal or zero numerator counts as 0 (its ratio is below 2^-100).
    let m_small = if small < 0x0080_0000 {
        0
    } else {
        mantissa(small)
    };
    let shift = (big >> 23) - (small >> 23).max(1);
    atan_norm_rad(
        m_small.checked_shr(shift).unwrap_or(0),
        mantissa(big),
        past_one,
        (num.to_bits() ^ den.to_bits()) >> 31 != 0,
    )
}

/// atan(`num` / `den`) (rad) of two integer magnitudes, negated when `negative`:
/// [`atan_ratio_q30`] rounded once to f32. A zero `den`: [`atan_pair_rad`] of the two as
/// f32.
#[cfg(feature = "earth-fixed")]
#[inline(never)]
pub(super) fn atan_ratio_rad(num: u64, den: u64, negative: bool) -> f32 {
    match atan_ratio_q30(num, den) {
        Some(q) => signed_q30_to_f32(q, negative),
        None => {
            let sign = if negative { -1.0 } else { 1.0 };
            atan_pair_rad(u64_to_f32(num, 0), sign * u64_to_f32(den, 0))
        }
    }
}

/// atan(`num` / `den`) in Q30 (in [0, pi/2]) of two integer magnitudes: the larger's
/// leading one shifted to bit 63, both truncated to their top 32 bits, then
/// [`atan_norm_q30`] (docs/fixed-point.md, "The update on the Cortex-M3"). None for a
/// zero `den`.
#[cfg(feature = "earth-fixed")]
#[inline(always)]
pub(super) fn atan_ratio_q30(num: u64, den: u64) -> Option<i32> {
    if den == 0 {
        return None;
    }
    let (small, big, past_one) = if num <= den {
        (num, den, false)
    } else {
        (den, num, true)
    };
    let lz = big.leading_zeros();
    let top = |x: u64| ((x << lz) >> 32) as u32;
    Some(atan_norm_q30(top(small), top(big), past_one))
}

/// `q` 2^-30 (>= 0) as f32, negated when `negative`.
#[cfg(feature = "earth-fixed")]
#[inline(always)]
pub(super) fn signed_q30_to_f32(q: i32, negative: bool) -> f32 {
    let rad = q30_to_f32(q.max(0) as u32);
    if negative {
        -rad
    } else {
        rad
    }
}

/// [`atan_norm_q30`] rounded once to f32, negated when `negative`.
#[cfg(feature = "earth-fixed")]
#[inline(always)]
fn atan_norm_rad(s: u32, b: u32, past_one: bool, negative: bool) -> f32 {
    signed_q30_to_f32(atan_norm_q30(s, b, past_one), negative)
}

/// The tail both integer arctangents share: atan(`s` / `b`) in Q30 for `s` <= `b` and
/// `b` in [2^31, 2^32), its complement pi/2 - atan when the ratio was `past_one`. Past
/// tan(pi/8) the ratio x is reduced to (1 - x) / (1 + x), atan x = pi/4 - atan((1 - x) /
/// (1 + x)), formed from the integers before the one division, so that the odd
/// polynomial covers only [0, tan(pi/8)].
// Out of line: inlined, the polynomial was a copy in each caller.
#[cfg(feature = "earth-fixed")]
#[inline(never)]
fn atan_norm_q30(s: u32, b: u32, past_one: bool) -> i32 {
    use core_math::wide::div_64_32;
    // s / b > tan(pi/8), compared exactly in u64.
    let reduced = u64::from(s) << 32 > u64::from(TAN_PI_8_Q32) * u64::from(b);
    // The ratio in Q32, truncated (< 0.4143: inside i32). Each division's high word is
    // below its divisor, which is normalised, as `div_64_32` needs.
    let x_q32 = if !reduced {
        // s < b here (s = b is past tan(pi/8)).
        div_64_32(s, 0, b)
    } else {
        let (n, d) = (b - s, u64::from(b) + u64::from(s));
        match u32::try_from(d) {
            Ok(d) => div_64_32(n, 0, d),
            // d in [2^32, 2^33): its last bit dropped, n / d = (n / 2) / (d / 2).
            Err(_) => div_64_32(n >> 1, n << 31, (d >> 1) as u32),
        }
    };
    let at = atan_small_q30(x_q32.min(TAN_PI_8_Q32) as i32);
    let at = if reduced { QUARTER_PI_Q30 - at } else { at };
    if past_one {
        HALF_PI_Q30 - at
    } else {
        at
    }
}

#[cfg(feature = "earth-fixed")]
#[cold]
#[inline(never)]
fn atan_pair_cold(num: f32, den: f32) -> f32 {
    drift_angle_rad(num / den)
}

/// pi/2 and pi/4 in Q30, rounded.
#[cfg(feature = "earth-fixed")]
const HALF_PI_Q30: i32 = 1_686_629_713;
#[cfg(feature = "earth-fixed")]
const QUARTER_PI_Q30: i32 = 843_314_857;

/// tan(pi/8) in Q32, rounded.
#[cfg(feature = "earth-fixed")]
const TAN_PI_8_Q32: u32 = 1_779_033_704;

/// atan(x) / x as a polynomial in x^2 on [0, tan(pi/8)], Q30: a weighted least-squares
/// fit, within 1.2e-10 of atan (`docs/fixed-point.md`, "The update on the Cortex-M3").
#[cfg(feature = "earth-fixed")]
const ATAN_Q30: [i32; 6] = [
    1_073_741_820,
    -357_913_270,
    214_716_287,
    -152_729_047,
    112_523_387,
    -62_656_717,
];

/// atan(x) in Q30 for x in Q32 on [0, tan(pi/8)]: every partial sum below 1 in Q30, so
/// each step is one 32 x 32 -> 64 product.
#[cfg(feature = "earth-fixed")]
#[inline(always)]
fn atan_small_q30(x_q32: i32) -> i32 {
    let mul = |a: i32, b: i32| ((i64::from(a) * i64::from(b) + (1 << 29)) >> 30) as i32;
    let z = ((i64::from(x_q32) * i64::from(x_q32)) >> 34) as i32;
    let mut acc = ATAN_Q30[5];
    for &c in ATAN_Q30[..5].iter().rev() {
        acc = mul(acc, z) + c;
    }
    ((i64::from(x_q32) * i64::from(acc) + (1 << 31)) >> 32) as i32
}

/// `q` 2^-30 as f32, rounded to nearest (ties away from zero), without the software
/// conversion and multiplication.
#[cfg(feature = "earth-fixed")]
#[inline(always)]
pub(super) fn q30_to_f32(q: u32) -> f32 {
    if q == 0 {
        return 0.0;
    }
    let lz = q.leading_zeros();
    // The leading one at bit 31, then 24 bits of mantissa and the rounding bit below.
    let m = q << lz;
    let exp = 127 + 1 - lz; // q 2^-30 = 2^(31 - lz - 30) x 1.m
    let bits = (exp << 23) + ((m >> 8) & 0x7f_ffff) + ((m >> 7) & 1);
    f32::from_bits(bits)
}

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
    let Some(up) = &g.fixed else {
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
/// mantissas divided in Q40, the odd polynomial of degree 19 on [0, 1] in Q30 (fitted
/// to atan by weighted least squares, within 4.2e-9 evaluated this way), the octant
/// past 1 by pi/2 - atan(den/num); then rounded once to f32 (docs/fixed-point.md, "The
/// update on the Cortex-M3"). Non-finite inputs and a zero `den`: `atan_f32` of the
/// f32 quotient.
#[cfg(feature = "earth-fixed")]
#[inline(never)]
pub(super) fn atan_pair_rad(num: f32, den: f32) -> f32 {
    let (a, b) = (num.to_bits() & 0x7fff_ffff, den.to_bits() & 0x7fff_ffff);
    if a >= 0x7f80_0000 || !(0x0080_0000..0x7f80_0000).contains(&b) {
        return atan_pair_cold(num, den);
    }
    // For positive finite f32s the bits order as the values.
    let (small, big, past_one) = if a <= b { (a, b, false) } else { (b, a, true) };
    let mantissa = |x: u32| u64::from((x & 0x7f_ffff) | 0x80_0000);
    // A subnormal or zero numerator counts as 0 (its ratio is below 2^-100).
    let m_small = if small < 0x0080_0000 {
        0
    } else {
        mantissa(small)
    };
    let shift = (big >> 23) - (small >> 23).max(1);
    // m_small / m_big (< 2) in Q40 by five steps of long division, 8 bits each, in the
    // core's 32-bit divide (the remainder stays below 2^24: no 64-bit division call);
    // then over 2^shift, in Q30 rounded.
    let m_big = mantissa(big) as u32;
    let (mut q, mut rem) = (0u64, m_small as u32);
    for _ in 0..5 {
        let n = rem << 8;
        let d = n.checked_div(m_big).unwrap_or(0);
        q = (q << 8) + u64::from(d);
        rem = n - d * m_big;
    }
    let r = (q.checked_shr(shift).unwrap_or(0) + (1 << 9)) >> 10;
    let r = r.min(1 << 30) as i32;
    atan_q30_rad(r, past_one, (num.to_bits() ^ den.to_bits()) >> 31 != 0)
}

/// atan(`num` / `den`) (rad) of two integer magnitudes, negated when `negative`: the
/// ratio of the smaller over the larger in [`Wide`], truncated to Q30, then
/// [`atan_pair_rad`]'s polynomial and rounding (docs/fixed-point.md, "The update on the
/// Cortex-M3"). A zero `den`: [`atan_pair_rad`] of the two as f32.
#[cfg(feature = "earth-fixed")]
#[inline(never)]
pub(super) fn atan_ratio_rad(num: u64, den: u64, negative: bool) -> f32 {
    use core_math::wide::Wide;
    if den == 0 {
        let sign = if negative { -1.0 } else { 1.0 };
        return atan_pair_rad(u64_to_f32(num, 0), sign * u64_to_f32(den, 0));
    }
    let (small, big, past_one) = if num <= den {
        (num, den, false)
    } else {
        (den, num, true)
    };
    // <= 1 in Q30.
    let r = (Wide::from_u64(small, 0) / Wide::from_u64(big, 0))
        .to_u64_scaled(30)
        .min(1 << 30) as i32;
    atan_q30_rad(r, past_one, negative)
}

/// The tail both integer arctangents share: atan(`r`) of the ratio `r` in Q30 on [0, 1],
/// its complement when the ratio was `past_one`, rounded once to f32 and negated when
/// `negative`.
// Out of line: inlined, the unrolled polynomial was a copy in each of the two.
#[cfg(feature = "earth-fixed")]
#[inline(never)]
fn atan_q30_rad(r: i32, past_one: bool, negative: bool) -> f32 {
    let at = atan_unit_q30(r);
    let q = if past_one { HALF_PI_Q30 - at } else { at };
    let rad = q30_to_f32(q.max(0) as u32);
    if negative {
        -rad
    } else {
        rad
    }
}

#[cfg(feature = "earth-fixed")]
#[cold]
#[inline(never)]
fn atan_pair_cold(num: f32, den: f32) -> f32 {
    drift_angle_rad(num / den)
}

/// pi/2 in Q30, rounded.
#[cfg(feature = "earth-fixed")]
const HALF_PI_Q30: i32 = 1_686_629_713;

/// atan(x) / x as a polynomial in x^2 on [0, 1], Q30 (a weighted least-squares fit:
/// `docs/fixed-point.md`, "The update on the Cortex-M3").
#[cfg(feature = "earth-fixed")]
const ATAN_Q30: [i32; 10] = [
    1_073_741_803,
    -357_912_299,
    214_710_104,
    -152_978_376,
    116_801_687,
    -88_194_453,
    59_085_752,
    -30_591_534,
    10_272_750,
    -1_620_580,
];

/// atan(x) for x in Q30 on [0, 1], in Q30: every partial sum below 1.1 in Q30, so
/// each step is one 32 x 32 -> 64 product.
#[cfg(feature = "earth-fixed")]
#[inline(always)]
fn atan_unit_q30(x: i32) -> i32 {
    let mul = |a: i32, b: i32| ((i64::from(a) * i64::from(b) + (1 << 29)) >> 30) as i32;
    let z = ((i64::from(x) * i64::from(x)) >> 30) as i32;
    let mut acc = ATAN_Q30[9];
    for &c in ATAN_Q30[..9].iter().rev() {
        acc = mul(acc, z) + c;
    }
    mul(x, acc)
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

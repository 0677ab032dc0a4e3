//! A segment's period, ticks and mismatch from the fixed-point extremes, in integers: the
//! Cortex-M3's route (`Config::fixed_point_pixels`), where each f32 operation is a
//! software call (docs/fixed-point.md, "The update on the Cortex-M3"). The f32 route
//! (`Controller::segment`) is the M4F boards' and stays as it is.

use super::*;
use core_math::wide::Wide;
use core_math::ModelError;

pub(crate) use core_math::wide::{i64_to_f32, u64_to_f32};

/// A finite f32 >= 0 in I24F40 bits, truncated, saturating; 0 for any other.
#[inline(always)]
pub(super) fn f32_to_i24f40(x: f32) -> u64 {
    Wide::from_f32(x).map_or(0, |w| w.to_u64_scaled(40))
}

/// [`f32_to_i24f40`] of |x|, with x's sign (saturating at `i64::MAX`).
// Out of line: six conversions inlined were most of the DEM route's way in.
#[inline(never)]
fn signed_i24f40(x: f32) -> i64 {
    let m = f32_to_i24f40(f32::from_bits(x.to_bits() & 0x7fff_ffff)).min(i64::MAX as u64) as i64;
    if x.to_bits() >> 31 != 0 {
        -m
    } else {
        m
    }
}

/// The steered centre's drift angle in f32, where the turn left the fixed formats'
/// envelope: rare, so out of line (inlined, it was a fifth of `segment_fixed`).
#[cold]
#[inline(never)]
fn steered_drift_cold(
    update: &core_math::earth::GeneralUpdate<f32>,
    seg: &SegmentPlan,
    sin: f32,
    cos: f32,
) -> Result<f32, Fault> {
    let m = steered_centre(update, seg, sin, cos)?;
    Ok(atan_pair_rad(m.v2_mps, m.v1_mps))
}

/// The plan's constants of [`period_fixed`].
#[derive(Clone, Copy)]
pub(super) struct PeriodConsts {
    /// pixel x clock (m/s).
    line_speed: Wide,
    /// The physical period bounds times the clock (ticks).
    bounds_ticks: (Wide, Wide),
}

impl PeriodConsts {
    #[inline(always)]
    pub(super) fn of(plan: &crate::plan::Plan) -> PeriodConsts {
        let wide = |x: f32| Wide::from_f32(x).unwrap_or(Wide::ZERO);
        let clock = wide(plan.line_clock_hz);
        let (lo_s, hi_s) = plan.period_bounds_s;
        PeriodConsts {
            line_speed: wide(plan.pixel_m) * clock,
            bounds_ticks: (wide(lo_s) * clock, wide(hi_s) * clock),
        }
    }
}

/// What the period and the mismatch come out as: the ticks and the worst relative
/// mismatch, None when the image is slower than the interpolation bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PeriodFixed {
    pub(super) ticks: u32,
    pub(super) worst_mismatch: Option<Wide>,
}

/// The segment's period in ticks and the worst mismatch of the programmed period, from
/// its positive |v1| extremes `v_min_bits` <= `v_max_bits` and its interpolation bound
/// (I24F40 bits): the f32 route's formulas (`Controller::segment`) in [`Wide`].
/// `line_speed` is pixel x clock (m/s), `bounds_ticks` the physical periods times the
/// clock.
#[inline(always)]
pub(super) fn period_fixed(
    v_min_bits: u64,
    v_max_bits: u64,
    interpolation_bits: u64,
    line_speed: Wide,
    bounds_ticks: (Wide, Wide),
) -> Result<PeriodFixed, Fault> {
    // Every speed in m/s 2^40.
    let v_min = Wide::from_u64(v_min_bits, -40);
    let v_max = Wide::from_u64(v_max_bits, -40);
    // The mean of the extremes' periods, in ticks.
    let exact = line_speed.scale(-1) * (v_min.recip() + v_max.recip());
    let (lo, hi) = bounds_ticks;
    if line_speed.is_zero() || v_min.is_zero() || lo.gt(exact) || exact.gt(hi) {
        return Err(Fault::PeriodOutOfRange);
    }
    // Half up, as `nearest_ticks`; 1 to u32::MAX.
    let ticks = exact
        .to_u64_scaled(32)
        .checked_add(1 << 31)
        .map(|q| q >> 32);
    let ticks = match ticks.map(u32::try_from) {
        Some(Ok(t)) if t >= 1 => t,
        _ => return Err(Fault::from(ModelError::LinePeriodOutOfRange)),
    };
    let worst_mismatch = match v_min_bits.checked_sub(interpolation_bits) {
        Some(v_lo) if v_lo > 0 => {
            let v_hi = v_max_bits.saturating_add(interpolation_bits);
            let t = Wide::from_u64(u64::from(ticks), 0);
            let ratio = |v: u64| line_speed / (t * Wide::from_u64(v, -40));
            let below = ratio(v_lo).abs_diff(Wide::ONE);
            let above = ratio(v_hi).abs_diff(Wide::ONE);
            Some(if below.gt(above) { below } else { above })
        }
        _ => None,
    };
    Ok(PeriodFixed {
        ticks,
        worst_mismatch,
    })
}

/// What a segment's fixed-point samples show, in I24F40 bits: the centre's (v1, v2),
/// v1's signed extremes, and the (|v2|, |v1|) of the largest |v2/v1| over the samples
/// and the centre.
#[derive(Clone, Copy, Debug)]
pub(super) struct ExtremesBits {
    pub(super) c1: i64,
    pub(super) c2: i64,
    pub(super) lo: i64,
    pub(super) hi: i64,
    pub(super) d2: u64,
    pub(super) d1: u64,
}

impl ExtremesBits {
    /// The DEM route's f32 [`Extremes`] in I24F40 bits: exact for every magnitude from
    /// 2^-16 to 2^23 m/s (an f32's 24 bits then lie within the format's 64), truncated
    /// below, saturating above; NaN as 0.
    pub(super) fn of(e: &Extremes) -> ExtremesBits {
        let signed = signed_i24f40;
        ExtremesBits {
            c1: signed(e.centre.v1_mps),
            c2: signed(e.centre.v2_mps),
            lo: signed(e.lo),
            hi: signed(e.hi),
            d2: signed(e.drift_v2).unsigned_abs(),
            d1: signed(e.drift_v1).unsigned_abs(),
        }
    }
}

impl Controller {
    /// [`Controller::segment`] with fixed-point pixels: the period, its ticks, the
    /// mismatch and the drift tangent from the samples' I24F40 extremes (or the DEM
    /// route's `dem`) in integers ([`period_fixed`]), the MTF, stage limit and drift
    /// angles by the integer forms.
    #[inline(never)]
    pub(super) fn segment_fixed(
        &self,
        update: &Ground,
        seg: &SegmentPlan,
        steer: Option<(f32, f32, f32)>,
        dem: Option<ExtremesBits>,
    ) -> Result<SegmentOutput, Fault> {
        let e = match dem {
            Some(e) => e,
            None => extremes_fixed(update, seg)?,
        };
        let reversed = e.c1 > 0;
        // Every sample must move the same way as the centre.
        let (v_min, v_max) = if reversed {
            (e.lo, e.hi)
        } else {
            (e.hi.saturating_neg(), e.lo.saturating_neg())
        };
        if v_min <= 0 {
            return Err(Fault::PeriodOutOfRange);
        }
        let p = period_fixed(
            v_min as u64,
            v_max as u64,
            f32_to_i24f40(seg.interpolation_mps),
            update.period.line_speed,
            update.period.bounds_ticks,
        )?;
        // |v2| / |v1| (|v1| >= v_min > 0).
        let tan_max = (Wide::from_u64(e.d2, 0) / Wide::from_u64(e.d1, 0)).to_f32();
        let stages = u32::from(seg.tdi_stages);
        let (worst_mismatch, mtf, max_stages) = match p.worst_mismatch {
            Some(w) => {
                let worst = w.to_f32();
                let (mtf, m) = self.mtf_and_stages(stages, worst, tan_max)?;
                (worst, mtf, m as u16)
            }
            None => (f32::MAX, 0.0, 0),
        };
        // The drift angles from the integer pairs; the worst never below the centre's
        // magnitude (both >= 0: their bits order as their values).
        let signed = |v2: i64, v1: i64| {
            atan_ratio_rad(v2.unsigned_abs(), v1.unsigned_abs(), (v2 < 0) != (v1 < 0))
        };
        let drift_rad = signed(e.c2, e.c1);
        let worst_drift_rad = atan_ratio_rad(e.d2, e.d1, false);
        let worst_drift_rad = if worst_drift_rad.to_bits() < drift_rad.abs().to_bits() {
            drift_rad.abs()
        } else {
            worst_drift_rad
        };
        let residual_drift_rad = match (steer, update.yawed(), seg.fixed.first()) {
            (None, _, _) => drift_rad,
            // The centre on the turned fixed-point update, in integers.
            (Some(_), Some(up), Some(px)) => {
                let m = core_math::EARTH_FIXED.motion(up, px)?;
                signed(m.v2_mps.to_bits(), m.v1_mps.to_bits())
            }
            // The f32 ground is made wherever the turn left the fixed formats.
            (Some((sin, cos, _)), _, _) if update.float_ok => {
                steered_drift_cold(&update.float, seg, sin, cos)?
            }
            (Some(_), _, _) => return Err(Fault::InvalidScene),
        };
        Ok(SegmentOutput {
            index: seg.index,
            ticks: p.ticks,
            worst_mismatch,
            mtf,
            max_stages,
            drift_rad,
            worst_drift_rad,
            residual_drift_rad,
            reversed,
            held: false,
        })
    }
}

/// The yaw request from the boresight's (v1/f, v2/f) in Q63 (`vf1` not 0), in integers:
/// the angle atan(v2/v1) in Q30 ([`atan_ratio_q30`]), its sine and cosine in Q30
/// (`trig::sin_cos_q30`: sin = sign(v1) v2 / |v|, cos = |v1| / |v|, as [`steer_from`]
/// forms them), and the f32 (sin, cos, angle) of [`Steer`], each rounded once from Q30.
#[inline(always)]
pub(super) fn steer_fixed(vf1: i64, vf2: i64) -> Option<(i32, i32, (f32, f32, f32))> {
    let negative = (vf1 < 0) != (vf2 < 0);
    let q = atan_ratio_q30(vf2.unsigned_abs(), vf1.unsigned_abs())?;
    let (s, c) = core_math::trig::sin_cos_q30(q);
    let s = if negative { -s } else { s };
    let f32_of = |x: i32| signed_q30_to_f32(x.saturating_abs(), x < 0);
    Some((s, c, (f32_of(s), f32_of(c), signed_q30_to_f32(q, negative))))
}

/// A sine or cosine in Q30, truncated toward zero: `(x * 2^30) as i32` from the f32's
/// bits, without the software product and conversion (the same value for every |x| < 2,
/// and 0 for NaN; `controller/src/update/fixed_tests.rs`).
#[inline(always)]
pub(super) fn q30(x: f32) -> i32 {
    let bits = x.to_bits();
    let biased = ((bits >> 23) & 0xff) as i32;
    // |x| 2^30 = m 2^(biased - 120), m the 24-bit mantissa.
    let m = (bits & 0x7f_ffff) | 0x80_0000;
    let mag = match biased - 120 {
        _ if biased == 0 => 0,
        _ if biased == 0xff => {
            if bits & 0x7f_ffff != 0 {
                return 0;
            }
            u32::MAX
        }
        sh if sh >= 8 => u32::MAX,
        sh if sh >= 0 => m << sh,
        sh => m.checked_shr(sh.unsigned_abs()).unwrap_or(0),
    };
    if bits >> 31 != 0 {
        (mag.min(1 << 31) as i32).wrapping_neg()
    } else {
        mag.min(i32::MAX as u32) as i32
    }
}

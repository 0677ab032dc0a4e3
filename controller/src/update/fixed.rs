//! A segment's period, ticks and mismatch from the fixed-point extremes, in integers: the
//! Cortex-M3's route (`Config::fixed_point_pixels`), where each f32 operation is a
//! software call (docs/fixed-point.md, "The update on the Cortex-M3"). The f32 route
//! (`Controller::segment`) is the M4F boards' and stays as it is.

use super::*;
use core_math::ModelError;

/// A positive number m 2^e with a 32-bit mantissa (m in [2^31, 2^32), or 0): the few
/// operations the period and the mismatch need, each truncated once (a relative error
/// below 2^-31), with no NaN, infinity or subnormal to handle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Wide {
    m: u32,
    e: i32,
}

impl Wide {
    /// Zero: below every other value in [`Wide::gt`]'s order, and far from any sum of
    /// the exponents used here.
    pub(super) const ZERO: Wide = Wide {
        m: 0,
        e: -(1 << 20),
    };
    pub(super) const ONE: Wide = Wide { m: 1 << 31, e: -31 };

    /// `x` 2^`e`, truncated to 32 bits.
    #[inline(always)]
    pub(super) fn from_u64(x: u64, e: i32) -> Wide {
        if x == 0 {
            return Wide::ZERO;
        }
        let lz = x.leading_zeros();
        Wide {
            m: ((x << lz) >> 32) as u32,
            e: e + 32 - lz as i32,
        }
    }

    /// A finite f32 >= 0, exactly (subnormals as 0); None for any other.
    #[inline(always)]
    pub(super) fn from_f32(x: f32) -> Option<Wide> {
        let bits = x.to_bits();
        let biased = (bits >> 23) as i32;
        if bits >> 31 != 0 || biased == 0xff {
            return (bits == 0x8000_0000).then_some(Wide::ZERO);
        }
        if biased == 0 {
            return Some(Wide::ZERO);
        }
        // x = (2^23 + f) 2^(biased - 150).
        Some(Wide {
            m: ((bits & 0x7f_ffff) | 0x80_0000) << 8,
            e: biased - 158,
        })
    }

    /// (m, e).
    #[cfg(test)]
    pub(super) fn parts(self) -> (u32, i32) {
        (self.m, self.e)
    }

    #[inline(always)]
    pub(super) fn mul(self, o: Wide) -> Wide {
        if self.m == 0 || o.m == 0 {
            return Wide::ZERO;
        }
        // In [2^62, 2^64).
        let p = u64::from(self.m) * u64::from(o.m);
        let top = (p >> 63) as u32;
        Wide {
            m: (p >> (31 + top)) as u32,
            e: self.e + o.e + 31 + top as i32,
        }
    }

    /// `self` / `o`; `o` not 0 (0 for a 0 divisor, which no caller passes).
    #[inline(always)]
    pub(super) fn div(self, o: Wide) -> Wide {
        if self.m == 0 || o.m == 0 {
            return Wide::ZERO;
        }
        // The quotient of the mantissas scaled into [2^31, 2^32): m 2^32 / o.m when
        // m < o.m, else m 2^31 / o.m (the high word then below o.m either way).
        if self.m < o.m {
            Wide {
                m: div_64_32(self.m, 0, o.m),
                e: self.e - o.e - 32,
            }
        } else {
            Wide {
                m: div_64_32(self.m >> 1, self.m << 31, o.m),
                e: self.e - o.e - 31,
            }
        }
    }

    #[inline(always)]
    pub(super) fn recip(self) -> Wide {
        Wide::ONE.div(self)
    }

    /// The larger of the two first, by exponent then mantissa (both normalised).
    #[inline(always)]
    pub(super) fn gt(self, o: Wide) -> bool {
        (self.e, self.m) > (o.e, o.m)
    }

    #[inline(always)]
    pub(super) fn add(self, o: Wide) -> Wide {
        let (a, b) = if o.gt(self) { (o, self) } else { (self, o) };
        let d = (a.e - b.e) as u32;
        // The larger's leading one at bit 62: the sum stays below 2^64.
        let sum = (u64::from(a.m) << 31) + (u64::from(b.m) << 31).checked_shr(d).unwrap_or(0);
        Wide::from_u64(sum, a.e - 31)
    }

    /// |`self` - `o`|.
    #[inline(always)]
    pub(super) fn abs_diff(self, o: Wide) -> Wide {
        let (a, b) = if o.gt(self) { (o, self) } else { (self, o) };
        let d = (a.e - b.e) as u32;
        let big = u64::from(a.m) << 32;
        let small = (u64::from(b.m) << 32).checked_shr(d).unwrap_or(0);
        Wide::from_u64(big - small, a.e - 32)
    }

    /// `self` 2^32, saturating at `u64::MAX`.
    #[inline(always)]
    pub(super) fn q32(self) -> u64 {
        let s = self.e + 32;
        if s > 32 {
            u64::MAX
        } else if s >= 0 {
            u64::from(self.m) << s
        } else {
            u64::from(self.m).checked_shr(s.unsigned_abs()).unwrap_or(0)
        }
    }

    /// As f32, rounded to nearest even; `f32::MAX` above its range, 0 below its normals.
    #[inline(always)]
    pub(super) fn to_f32(self) -> f32 {
        if self.m == 0 {
            return 0.0;
        }
        let (mant, rest) = (self.m >> 8, self.m & 0xff);
        let up = rest > 0x80 || (rest == 0x80 && mant & 1 == 1);
        let mant = mant + u32::from(up);
        // mant 2^(e + 8), mant in [2^23, 2^24]: biased exponent e + 158; a carry to
        // 2^24 moves into the exponent by itself.
        let biased = self.e + 158;
        if biased < 1 {
            0.0
        } else if biased > 254 {
            f32::MAX
        } else {
            let bits = ((biased as u32 - 1) << 23) + mant;
            if bits >= 0x7f80_0000 {
                f32::MAX
            } else {
                f32::from_bits(bits)
            }
        }
    }
}

/// (`hi` 2^32 + `lo`) / `d`, truncated, for `d` >= 2^31 and `hi` < `d` (so the quotient
/// fits 32 bits): two 16-bit digits by the core's 32-bit divide (Knuth's algorithm D,
/// as Hacker's Delight's `divlu`), where a 64-bit division is a software call.
#[inline(always)]
pub(super) fn div_64_32(hi: u32, lo: u32, d: u32) -> u32 {
    let (d1, d0) = (d >> 16, d & 0xffff);
    // One quotient digit of (`top` 2^16 + `next`) / d, and the remainder; `top` < d.
    let digit = |top: u32, next: u32| -> (u32, u32) {
        let mut q = top.checked_div(d1).unwrap_or(0);
        let mut r = top - q * d1;
        while q >= 1 << 16 || q * d0 > (r << 16) + next {
            q -= 1;
            r += d1;
            if r >= 1 << 16 {
                break;
            }
        }
        // The remainder is below d: exact modulo 2^32.
        let rem = (top << 16)
            .wrapping_add(next)
            .wrapping_sub(q.wrapping_mul(d));
        (q, rem)
    };
    let (q1, rem) = digit(hi, lo >> 16);
    let (q0, _) = digit(rem, lo & 0xffff);
    (q1 << 16) | q0
}

/// `x` 2^`exp2` as f32, rounded to nearest even: `x as f32` times the power of two,
/// exactly, without the software conversion and product. For |x| 2^`exp2` inside f32's
/// normal range (the callers': `exp2` 0 or -40, I24F40 bits).
#[inline(always)]
pub(super) fn i64_to_f32(x: i64, exp2: i32) -> f32 {
    let sign = if x < 0 { 1 << 31 } else { 0 };
    f32::from_bits(u64_to_f32(x.unsigned_abs(), exp2).to_bits() | sign)
}

/// [`i64_to_f32`] of a magnitude.
#[inline(always)]
pub(super) fn u64_to_f32(x: u64, exp2: i32) -> f32 {
    if x == 0 {
        return 0.0;
    }
    let lz = x.leading_zeros();
    let top = x << lz;
    let (mant, rest) = ((top >> 40) as u32, top & ((1 << 40) - 1));
    let half = 1u64 << 39;
    let up = rest > half || (rest == half && mant & 1 == 1);
    // x 2^exp2 = (mant 2^40 + rest) 2^(exp2 - lz): about mant 2^(exp2 + 40 - lz), a
    // biased exponent of exp2 + 190 - lz; a carry to 2^24 moves into it by itself.
    let biased = (exp2 + 190 - lz as i32) as u32;
    f32::from_bits(((biased - 1) << 23) + mant + u32::from(up))
}

/// A finite f32 >= 0 in I24F40 bits, truncated, saturating; 0 for any other.
#[inline(always)]
pub(super) fn f32_to_i24f40(x: f32) -> u64 {
    match Wide::from_f32(x) {
        Some(w) if w.m != 0 => {
            let s = w.e + 40;
            if s >= 32 {
                u64::MAX
            } else if s >= 0 {
                u64::from(w.m) << s
            } else {
                u64::from(w.m).checked_shr(s.unsigned_abs()).unwrap_or(0)
            }
        }
        _ => 0,
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
    let exact = Wide {
        m: line_speed.m,
        e: line_speed.e - 1,
    }
    .mul(v_min.recip().add(v_max.recip()));
    let (lo, hi) = bounds_ticks;
    if line_speed.m == 0 || v_min.m == 0 || lo.gt(exact) || exact.gt(hi) {
        return Err(Fault::PeriodOutOfRange);
    }
    // Half up, as `nearest_ticks`; 1 to u32::MAX.
    let ticks = exact.q32().checked_add(1 << 31).map(|q| q >> 32);
    let ticks = match ticks.map(u32::try_from) {
        Some(Ok(t)) if t >= 1 => t,
        _ => return Err(Fault::from(ModelError::LinePeriodOutOfRange)),
    };
    let worst_mismatch = match v_min_bits.checked_sub(interpolation_bits) {
        Some(v_lo) if v_lo > 0 => {
            let v_hi = v_max_bits.saturating_add(interpolation_bits);
            let t = Wide::from_u64(u64::from(ticks), 0);
            let ratio = |v: u64| line_speed.div(t.mul(Wide::from_u64(v, -40)));
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

impl Controller {
    /// [`Controller::segment`] with fixed-point pixels and no DEM tile: the period, its
    /// ticks, the mismatch and the drift tangent from the samples' I24F40 extremes in
    /// integers ([`period_fixed`]), the MTF, stage limit and drift angles by the integer
    /// forms.
    #[inline(never)]
    pub(super) fn segment_fixed(
        &self,
        update: &Ground,
        seg: &SegmentPlan,
        steer: Option<(f32, f32, f32)>,
    ) -> Result<SegmentOutput, Fault> {
        let e = extremes_fixed(update, seg)?;
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
        let plan = &self.plan;
        let wide = |x: f32| Wide::from_f32(x).unwrap_or(Wide::ZERO);
        let clock = wide(plan.line_clock_hz);
        let (lo_s, hi_s) = plan.period_bounds_s;
        let p = period_fixed(
            v_min as u64,
            v_max as u64,
            f32_to_i24f40(seg.interpolation_mps),
            wide(plan.pixel_m).mul(clock),
            (wide(lo_s).mul(clock), wide(hi_s).mul(clock)),
        )?;
        // |v2| / |v1| (|v1| >= v_min > 0).
        let tan_max = Wide::from_u64(e.d2, 0)
            .div(Wide::from_u64(e.d1, 0))
            .to_f32();
        let stages = u32::from(seg.tdi_stages);
        let (worst_mismatch, mtf, max_stages) = match p.worst_mismatch {
            Some(w) => {
                let worst = w.to_f32();
                let (mtf, m) = self.mtf_and_stages(stages, worst, tan_max)?;
                (worst, mtf, m as u16)
            }
            None => (f32::MAX, 0.0, 0),
        };
        let residual = match steer {
            Some((sin, cos, _)) => Some(self.steered_centre(update, seg, sin, cos)?),
            None => None,
        };
        let centre = ImageMotion {
            v1_mps: i64_to_f32(e.c1, -40),
            v2_mps: i64_to_f32(e.c2, -40),
        };
        let drift = (u64_to_f32(e.d2, -40), u64_to_f32(e.d1, -40));
        let [drift_rad, worst_drift_rad, residual_drift_rad] =
            self.drift_angles(&centre, drift, tan_max, residual);
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

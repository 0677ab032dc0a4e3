//! A positive number with a 32-bit mantissa, for the per-update arithmetic of a core
//! without an FPU, where each f32 operation is a software call of 50 to 100
//! instructions: the controller's period, ticks and mismatch on the Cortex-M3 and the
//! stage limit's guess (docs/fixed-point.md, "The update on the Cortex-M3"). Each
//! operation truncates once, a relative error below 2^-31; there is no NaN, infinity or
//! subnormal to handle. Tests: `core-math/tests/wide.rs`.

/// A positive number m 2^e with a 32-bit mantissa (m in [2^31, 2^32), or 0): the few
/// operations the period and the mismatch need, each truncated once (a relative error
/// below 2^-31), with no NaN, infinity or subnormal to handle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wide {
    m: u32,
    e: i32,
}

impl Wide {
    /// Zero: below every other value in [`Wide::gt`]'s order, and far from any sum of
    /// the exponents used here.
    pub const ZERO: Wide = Wide {
        m: 0,
        e: -(1 << 20),
    };
    pub const ONE: Wide = Wide { m: 1 << 31, e: -31 };

    /// `x` 2^`e`, truncated to 32 bits.
    #[inline(always)]
    pub fn from_u64(x: u64, e: i32) -> Wide {
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
    pub fn from_f32(x: f32) -> Option<Wide> {
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

    /// (m, e): the value is m 2^e.
    pub fn parts(self) -> (u32, i32) {
        (self.m, self.e)
    }

    #[inline(always)]
    pub fn recip(self) -> Wide {
        Wide::ONE / self
    }

    /// `self` > `o`: by exponent then mantissa (both normalised; zero's exponent is
    /// below every other), as one 64-bit comparison of e 2^32 + m.
    #[inline(always)]
    pub fn gt(self, o: Wide) -> bool {
        let key = |w: Wide| (i64::from(w.e) << 32) | i64::from(w.m);
        key(self) > key(o)
    }

    /// |`self` - `o`|.
    #[inline(always)]
    pub fn abs_diff(self, o: Wide) -> Wide {
        let (a, b) = if o.gt(self) { (o, self) } else { (self, o) };
        let d = (a.e - b.e) as u32;
        let big = u64::from(a.m) << 32;
        let small = (u64::from(b.m) << 32).checked_shr(d).unwrap_or(0);
        Wide::from_u64(big - small, a.e - 32)
    }

    #[inline(always)]
    pub fn is_zero(self) -> bool {
        self.m == 0
    }

    /// `self` 2^`k`, exactly.
    #[inline(always)]
    pub fn scale(self, k: i32) -> Wide {
        if self.m == 0 {
            self
        } else {
            Wide {
                m: self.m,
                e: self.e + k,
            }
        }
    }

    /// `self` 2^`k` truncated to an integer, saturating at `u64::MAX`.
    #[inline(always)]
    pub fn to_u64_scaled(self, k: i32) -> u64 {
        if self.m == 0 {
            return 0;
        }
        let s = self.e + k;
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
    pub fn to_f32(self) -> f32 {
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
impl core::ops::Mul for Wide {
    type Output = Wide;

    #[inline(always)]
    fn mul(self, o: Wide) -> Wide {
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
}

impl core::ops::Div for Wide {
    type Output = Wide;

    /// `self` / `o`; `o` not 0 (0 for a 0 divisor, which no caller passes).
    #[inline(always)]
    fn div(self, o: Wide) -> Wide {
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
}

impl core::ops::Add for Wide {
    type Output = Wide;

    #[inline(always)]
    fn add(self, o: Wide) -> Wide {
        let (a, b) = if o.gt(self) { (o, self) } else { (self, o) };
        let d = (a.e - b.e) as u32;
        // The larger's leading one at bit 62: the sum stays below 2^64.
        let sum = (u64::from(a.m) << 31) + (u64::from(b.m) << 31).checked_shr(d).unwrap_or(0);
        Wide::from_u64(sum, a.e - 31)
    }
}

/// (`hi` 2^32 + `lo`) / `d`, truncated, for `d` >= 2^31 and `hi` < `d` (so the quotient
/// fits 32 bits): two 16-bit digits by the core's 32-bit divide (Knuth's algorithm D,
/// with the remainder in i64), where a 64-bit division is a software call.
// Out of line on the M3, the one core that divides `Wide`s in its update: five copies
// inlined there, against a call per division (docs/target.md, flash).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
#[cfg_attr(
    not(all(target_arch = "arm", not(target_abi = "eabihf"))),
    inline(always)
)]
pub fn div_64_32(hi: u32, lo: u32, d: u32) -> u32 {
    let d1 = d >> 16;
    // One quotient digit of (`top` 2^16 + `next`) / d, and the remainder; `top` < d.
    // The estimate from d's top half, capped at 2^16 - 1, is at most 2 above the digit
    // (d normalised: Knuth's theorem B); the remainder then corrects it, in i64.
    let digit = |top: u32, next: u32| -> (u32, u32) {
        let mut q = top.checked_div(d1).unwrap_or(0).min(0xffff);
        let n = (i64::from(top) << 16) | i64::from(next);
        let mut rem = n - i64::from(q) * i64::from(d);
        if rem < 0 {
            q -= 1;
            rem += i64::from(d);
            if rem < 0 {
                q -= 1;
                rem += i64::from(d);
            }
        }
        (q, rem as u32)
    };
    let (q1, rem) = digit(hi, lo >> 16);
    let (q0, _) = digit(rem, lo & 0xffff);
    (q1 << 16) | q0
}

/// `x` 2^`exp2` as f32, rounded to nearest even: `x as f32` times the power of two,
/// exactly, without the software conversion and product. For |x| 2^`exp2` inside f32's
/// normal range (the controller's callers: I24F40 bits, the Cortex-M3's integer instant and
/// propagation).
#[inline(always)]
pub fn i64_to_f32(x: i64, exp2: i32) -> f32 {
    let sign = if x < 0 { 1 << 31 } else { 0 };
    f32::from_bits(u64_to_f32(x.unsigned_abs(), exp2).to_bits() | sign)
}

/// [`i64_to_f32`] out of line: the NAV route's per-update conversions (the propagated
/// state's, the integer instant's fields) share one copy (docs/target.md, flash).
#[inline(never)]
pub fn i64_to_f32_call(x: i64, exp2: i32) -> f32 {
    i64_to_f32(x, exp2)
}

/// [`i64_to_f32`] of a magnitude.
#[inline(always)]
pub fn u64_to_f32(x: u64, exp2: i32) -> f32 {
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

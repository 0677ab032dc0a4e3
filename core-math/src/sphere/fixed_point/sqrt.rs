//! Square root per pixel: q = sqrt(m (2 - m)) for m in Q31, with a 896-entry seed
//! table, one Newton step for the reciprocal square root and one coupled (Heron)
//! correction, 32x32 -> 64 multiplies only. No division, no 64-bit variable shift.

use crate::fixed_int::RSQRT_SEED;

/// High word of a 32x32 -> 64 product.
#[inline(always)]
fn mulhi(a: u32, b: u32) -> u32 {
    ((a as u64 * b as u64) >> 32) as u32
}

/// q = sqrt(m (2 - m)) in Q30 for m = `mq` 2^-(31 + 2 e) (m in (0, 1], `mq` >= 1),
/// `t` = 2 - m in Q31 (in [2^31, 2^32)), `e` = `extra` (0 for m in Q31, 4 for m in Q39).
///
/// Normalise m by an even shift z (one `clz`): mz = mq << z in [2^30, 2^32); the high
/// word of mz t is f = q^2 2^(z + 2e - 2) in Q32, f in [1/8, 1). Seed r0 from f's top 10 bits (error
/// e0 <= 2^-9), Newton r1 = r0 (3 - f r0^2) / 2 (error about 1.5 e0^2 = 5.7e-6),
/// s = f r1, then the Heron correction s + r1 (f - s^2) / 2, whose error is about
/// 1.5 e1^2 = 5e-11 plus roundings of 2^-31; finally q = sqrt(f) 2^(1 - z/2 - e).
/// Measured: within 1.004 units of Q30 (9.4e-10) of the exact value (tests).
#[inline(always)]
pub(crate) fn q_from_m(mq: u32, t: u32, extra: u32) -> u32 {
    debug_assert!(mq >= 1 && t >= 1 << 31 && extra <= 4);
    let z = mq.leading_zeros() & !1;
    let mz = mq << z;
    let x = mz as u64 * t as u64; // q^2 2^(z - 2), Q64
    let f = (x >> 32) as u32; // Q32, in [2^29, 2^32)
    let r0 = RSQRT_SEED[(f >> 22) as usize & 1023] as u32; // Q14
    let u = (3 << 28) - mulhi(f, r0 * r0); // 3 - f r0^2, Q28 (about 2^29)
    let r1 = ((r0 as u64 * u as u64) >> 14) as u32; // Q29, < 2^30.5
    let s = ((f as u64 * r1 as u64) >> 30) as u32; // Q31, about sqrt(f)
    let d = (x >> 2) as i64 - (s as u64 * s as u64) as i64; // f - s^2, Q62, all 64 bits
    let corr = ((r1 as i64 * (d >> 16)) >> 45) as i32; // r1 d / 2, Q31
    let y = (s as i32 + corr) as u32; // Q31 of sqrt(f)
    let half = (z >> 1) + extra;
    (y + ((1 << half) >> 1)) >> half
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the exact value in f64 (which has 53 bits, ample here) over all
    /// magnitudes of m, including the extreme ones.
    #[test]
    fn within_one_unit_of_q30() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut worst = 0f64;
        let mut check = |m31: u32| {
            let m = m31 as f64 / 2f64.powi(31);
            let exact = libm::sqrt(m * (2.0 - m)) * 2f64.powi(30);
            let got = q_from_m(m31, m31.wrapping_neg(), 0) as f64;
            worst = worst.max((got - exact).abs());
        };
        for i in 0..2_000_000u32 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let m31 = ((x as u32) >> (i % 31)).clamp(1, 1 << 31);
            check(m31);
        }
        for m31 in [
            1,
            2,
            3,
            4,
            5,
            (1 << 30) - 1,
            1 << 30,
            (1 << 31) - 1,
            1 << 31,
        ] {
            check(m31);
        }
        assert!(worst <= 1.01, "{worst}");
    }

    /// The near-limb call: m in Q39 (m < 2^-8), 2 - m as 2^32 - 1 - m/2^8.
    #[test]
    fn q39_within_one_unit_of_q30() {
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        let mut worst = 0f64;
        for i in 0..1_000_000u32 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let m39 = ((x as u32) >> (1 + i % 31)).max(1);
            let m = m39 as f64 / 2f64.powi(39);
            let exact = libm::sqrt(m * (2.0 - m)) * 2f64.powi(30);
            let got = q_from_m(m39, !(m39 >> 8), 4) as f64;
            worst = worst.max((got - exact).abs());
        }
        assert!(worst <= 1.01, "{worst}");
    }
}

//! The fixed route's period arithmetic against u64/u128 and f64 computations.
extern crate std;
use super::fixed::*;
use core_math::sample::SplitMix64;
use core_math::wide::Wide;

/// x 2^e, drawn over every magnitude a caller may pass.
fn draw_u64(rng: &mut SplitMix64) -> u64 {
    let x = rng.next_u64();
    x >> (rng.next_u64() % 64)
}

/// The hand conversions give exactly what the software conversion and the product by
/// the power of two give.
#[test]
fn integer_to_f32_is_the_rounded_conversion() {
    let mut rng = SplitMix64(0x5EED_2026_1127_0001);
    let lsb = 1.0 / (1u64 << 40) as f32;
    let check = |x: i64| {
        assert_eq!(i64_to_f32(x, 0).to_bits(), (x as f32).to_bits(), "{x}");
        assert_eq!(
            i64_to_f32(x, -40).to_bits(),
            (x as f32 * lsb).to_bits(),
            "{x}"
        );
        let u = x.unsigned_abs();
        assert_eq!(u64_to_f32(u, -40).to_bits(), (u as f32 * lsb).to_bits());
    };
    for _ in 0..1_000_000 {
        let x = draw_u64(&mut rng) as i64;
        check(x);
        check(x.wrapping_neg());
        // Ties: 24 significant bits and a half.
        let lz = (rng.next_u64() % 39) as u32;
        let tie = (((rng.next_u64() >> 40) | (1 << 23)) << 1 | 1) << (39 - lz);
        check(tie as i64);
    }
    for x in [
        0,
        1,
        -1,
        i64::MAX,
        i64::MIN,
        1 << 40,
        (1 << 24) - 1,
        (1 << 25) - 1,
    ] {
        check(x);
    }
}

/// f32 to I24F40 bits: the exact product by 2^40, truncated, saturating.
#[test]
fn f32_to_bits_is_the_truncated_product() {
    for x in [1.0f32, 0.5, 3.0, 1e-30, 1.5e30, f32::MAX, f32::MIN_POSITIVE] {
        let bits = f32_to_i24f40(x);
        let want = f64::from(x) * libm::exp2(40.0);
        let want = if want >= libm::exp2(64.0) {
            u64::MAX
        } else {
            want as u64
        };
        assert_eq!(bits, want, "{x}");
    }
    assert_eq!(f32_to_i24f40(f32::INFINITY), 0);
    assert_eq!(f32_to_i24f40(-1.0), 0);
}

/// The period, its ticks and the worst mismatch against the f32 route's formulas
/// evaluated in f64 on the same extremes: the ticks the nearest to the f64 count (half
/// up), except where its fraction lies within 1e-8 relative of a half; the mismatch
/// within 4e-9 of the speed ratio (five truncations of 2^-31) plus its f32 rounding.
#[test]
fn period_and_mismatch_match_f64() {
    let mut rng = SplitMix64(0x5EED_2026_1127_0004);
    let mut worst = 0f64;
    let mut cases = (0, 0, 0);
    for _ in 0..300_000 {
        let pixel = (libm::exp(rng.uniform(-13.0, -9.0))) as f32;
        let clock = (libm::exp(rng.uniform(12.0, 20.0))) as f32;
        let v_max = libm::exp(rng.uniform(-12.0, 3.0));
        let v_min = v_max * rng.uniform(0.2, 1.0);
        let (min_bits, max_bits) = (
            (v_min * libm::exp2(40.0)) as u64,
            (v_max * libm::exp2(40.0)) as u64,
        );
        if min_bits == 0 {
            continue;
        }
        let interp = (v_min * libm::exp(rng.uniform(-16.0, 0.5))) as f32;
        let interp_bits = f32_to_i24f40(interp);
        let (lo_s, hi_s) = (
            (rng.uniform(1e-7, 1e-4)) as f32,
            (rng.uniform(1e-3, 100.0)) as f32,
        );
        let w = |x: f32| Wide::from_f32(x).unwrap();
        let got = period_fixed(
            min_bits,
            max_bits,
            interp_bits,
            w(pixel) * w(clock),
            (w(lo_s) * w(clock), w(hi_s) * w(clock)),
        );
        let (vmin, vmax) = (
            min_bits as f64 * libm::exp2(-40.0),
            max_bits as f64 * libm::exp2(-40.0),
        );
        let line = f64::from(pixel) * f64::from(clock);
        let exact = 0.5 * line * (1.0 / vmin + 1.0 / vmax);
        let (lo_t, hi_t) = (
            f64::from(lo_s) * f64::from(clock),
            f64::from(hi_s) * f64::from(clock),
        );
        let margin = 1e-8 * exact;
        if exact < lo_t - margin || exact > hi_t + margin || exact + 0.5 >= 4_294_967_296.0 {
            assert!(got.is_err(), "{exact} outside [{lo_t}, {hi_t}]: {got:?}");
            cases.0 += 1;
            continue;
        }
        if exact < lo_t + margin || exact > hi_t - margin || exact < 0.5 {
            continue;
        }
        let p = got.expect("inside the bounds");
        let frac = exact - libm::floor(exact);
        if libm::fabs(frac - 0.5) > margin {
            assert_eq!(f64::from(p.ticks), libm::floor(exact + 0.5), "{exact}");
        }
        let ticks = f64::from(p.ticks);
        let interp_v = interp_bits as f64 * libm::exp2(-40.0);
        let (v_lo, v_hi) = (vmin - interp_v, vmax + interp_v);
        match p.worst_mismatch {
            Some(m) => {
                assert!(v_lo > 0.0);
                let (r_lo, r_hi) = (line / (ticks * v_lo), line / (ticks * v_hi));
                let want = libm::fabs(r_lo - 1.0).max(libm::fabs(1.0 - r_hi));
                let got = f64::from(m.to_f32());
                let bound = 4e-9 * r_lo.max(1.0) + 0.5 * f64::from(f32::EPSILON) * want;
                let err = libm::fabs(got - want);
                assert!(err <= bound, "mismatch {got:e} vs {want:e}");
                worst = worst.max(err / bound);
                cases.1 += 1;
            }
            None => {
                assert!(v_lo <= 0.0, "{v_lo}");
                cases.2 += 1;
            }
        }
    }
    assert!(
        cases.0 > 1_000 && cases.1 > 100_000 && cases.2 > 1_000,
        "{cases:?}"
    );
    std::eprintln!("period_fixed: {cases:?} (refused, checked, unbounded); worst mismatch error / bound {worst:.3}");
}

/// The drift angle of an integer pair (the Cortex-M3's segments) against atan in f64 of
/// the same integers: within 3.5e-9 rad (the operands' truncation to 32 bits, the
/// quotient's to Q32, the polynomial with its roundings and pi/4, pi/2 in Q30:
/// docs/fixed-point.md) plus half an f32 ulp of the result, over pairs of every
/// magnitude and ratio (so both sides of tan(pi/8)), and the edge cases.
#[test]
fn integer_pair_drift_angle_matches_atan() {
    use super::sweep::{atan_pair_rad, atan_ratio_rad};
    let mut rng = SplitMix64(0x5EED_2026_1127_0007);
    let mut worst = 0f64;
    let mut check = |num: u64, den: u64, negative: bool| {
        let got = f64::from(atan_ratio_rad(num, den, negative));
        let want = libm::atan(num as f64 / den as f64) * if negative { -1.0 } else { 1.0 };
        let err = libm::fabs(got - want);
        assert!(
            err <= 3.5e-9 + 0.5 * f64::from(f32::EPSILON) * libm::fabs(want),
            "atan({num} / {den}) = {got} vs {want}"
        );
        worst = worst.max(err - 0.5 * f64::from(f32::EPSILON) * libm::fabs(want));
    };
    for i in 0..400_000 {
        let den = draw_u64(&mut rng).max(1);
        let ratio = libm::exp(rng.uniform(-25.0, 25.0));
        let num = (den as f64 * ratio).min(1.8e19) as u64;
        check(num, den, i % 2 == 1);
    }
    for (num, den) in [
        (0, 1),
        (1, 1),
        (u64::MAX, u64::MAX),
        (u64::MAX, 1),
        (1, u64::MAX),
        (1 << 63, (1 << 63) - 1),
        (7, 1 << 40),
        // Either side of tan(pi/8) (1 779 033 703.95 in Q32).
        (1_779_033_703, 1 << 32),
        (1_779_033_704, 1 << 32),
        (1 << 32, 1_779_033_704),
    ] {
        check(num, den, false);
        check(num, den, true);
    }
    // A zero denominator: the f32 form's (pi/2, or NaN for 0/0).
    assert_eq!(atan_ratio_rad(5, 0, false), atan_pair_rad(5.0, 0.0));
    assert_eq!(atan_ratio_rad(5, 0, true), atan_pair_rad(5.0, -0.0));
    assert!(atan_ratio_rad(0, 0, false).is_nan());
    std::eprintln!("integer pair drift angle: worst error beyond the f32 rounding {worst:.2e} rad");
}

/// `q30` from the bits gives what the product and the saturating conversion give, for
/// every sign, magnitude and special value drawn.
#[test]
fn q30_from_bits_is_the_conversion() {
    use super::fixed::q30;
    let mut rng = SplitMix64(0x5EED_2026_1127_0011);
    let scale = (1u32 << 30) as f32;
    let check = |x: f32| assert_eq!(q30(x), (x * scale) as i32, "{x:e} ({:#x})", x.to_bits());
    for _ in 0..2_000_000 {
        check(f32::from_bits(rng.next_u64() as u32));
        // Mostly |x| <= 1, the sines and cosines it is given.
        check(rng.uniform(-1.0, 1.0) as f32);
    }
    for x in [
        0.0,
        -0.0,
        1.0,
        -1.0,
        2.0,
        -2.0,
        1.999_999_9,
        -1.999_999_9,
        f32::MIN_POSITIVE,
        1e-40,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ] {
        check(x);
    }
}

/// The yaw request in integers from the boresight's (v1/f, v2/f) against f64 of the same
/// integers: the sine and cosine (sign(v1) v2 / |v|, |v1| / |v|) within 7e-9 in Q30 (the
/// angle's 3.5e-9 and sin_cos_q30's three units), their f32 forms and the angle within
/// the same plus half an f32 ulp, over pairs of every magnitude, sign and ratio.
#[test]
fn integer_yaw_request_matches_f64() {
    use super::fixed::steer_fixed;
    let mut rng = SplitMix64(0x5EED_2026_1127_0012);
    let mut worst = 0f64;
    let q30 = (1u64 << 30) as f64;
    for i in 0..300_000 {
        let vf1 = (draw_u64(&mut rng) >> 1).max(1) as i64;
        let ratio = libm::exp(rng.uniform(-12.0, 12.0));
        let vf2 = (vf1 as f64 * ratio).min(9.2e18) as i64;
        let (vf1, vf2) = (
            if i % 2 == 0 { vf1 } else { -vf1 },
            if i % 3 == 0 { vf2 } else { -vf2 },
        );
        let (v1, v2) = (vf1 as f64, vf2 as f64);
        let speed = libm::sqrt(v1 * v1 + v2 * v2);
        let sign = if v1 < 0.0 { -1.0 } else { 1.0 };
        let (want_sin, want_cos, want_rad) =
            (sign * v2 / speed, sign * v1 / speed, libm::atan(v2 / v1));
        let (s, c, (sf, cf, rad)) = steer_fixed(vf1, vf2).expect("v1 != 0");
        let half_ulp = |x: f64| 0.5 * f64::from(f32::EPSILON) * libm::fabs(x);
        for (got, want) in [
            (f64::from(s) / q30, want_sin),
            (f64::from(c) / q30, want_cos),
        ] {
            let err = libm::fabs(got - want);
            assert!(err <= 7e-9, "({vf1}, {vf2}): {got} vs {want}");
            worst = worst.max(err);
        }
        for (got, want, bound) in [
            (sf, want_sin, 7e-9),
            (cf, want_cos, 7e-9),
            (rad, want_rad, 3.5e-9),
        ] {
            let err = libm::fabs(f64::from(got) - want);
            assert!(
                err <= bound + half_ulp(want),
                "({vf1}, {vf2}): {got} vs {want}"
            );
        }
    }
    assert!(steer_fixed(0, 5).is_none());
    std::eprintln!("integer yaw request: sine and cosine within {worst:.2e} in Q30");
}

//! MTF_mismatch, the TDI stage limit and the line period, each against an independent
//! computation (libm's sin, a brute-force search, exact integer arithmetic).

use core_math::sphere::speed_line_period_s;
use core_math::{line_period_ticks, mtf_mismatch, nearest_ticks, sinc, ModelError, StageRule};

#[test]
fn sinc_polynomial_matches_libm() {
    let mut worst64 = 0.0f64;
    let mut worst32 = 0.0f64;
    for i in 1..=20_000 {
        let x = i as f64 * (std::f64::consts::PI / 20_000.0);
        let exact = libm::sin(x) / x;
        worst64 = worst64.max((sinc(x) - exact).abs());
        worst32 = worst32.max((sinc(x as f32) as f64 - exact).abs());
    }
    assert!(worst64 < 1e-10, "f64 sinc error {worst64}");
    assert!(worst32 < 2e-7, "f32 sinc error {worst32}");
    println!("sinc on (0, pi]: f64 error {worst64:.1e}, f32 {worst32:.1e}");
    assert_eq!(sinc(0.0f64), 1.0);
    // Beyond pi the direct quotient is used; check it too.
    assert!((sinc(4.0f64) - libm::sin(4.0) / 4.0).abs() < 1e-15);
    // Never above 1 in f32 (the MTF, |sinc|, is not clamped): every f32 in
    // [0, pi] near 0 and a dense grid beyond, and the quotient past pi.
    let mut x = 0.0f32;
    while x < 1e-3 {
        assert!(sinc(x) <= 1.0 && sinc(-x) <= 1.0, "{x:e}");
        x = f32::from_bits(x.to_bits() + 1_009);
    }
    for i in 0..=2_000_000 {
        let x = i as f32 * 1e-5;
        assert!(sinc(x) <= 1.0, "{x}");
    }
    assert_eq!(sinc(0.0f32), 1.0);
}

/// Issue 25, item 2: past the first zero the MTF is the modulus of the sinc, not 0 and
/// not negative (`../shared/EARTH-MODEL.md`: |sinc(d/2)|). The derivation's test case:
/// 48 stages at a drift of 0.0624 rad smear 3.0 pixels, MTF 0.212.
#[test]
fn the_mtf_is_the_modulus_past_the_first_zero() {
    let tan = libm::tan(0.0624);
    let x = std::f64::consts::FRAC_PI_2 * 48.0 * tan;
    let want = libm::fabs(libm::sin(x) / x);
    assert!((want - 0.212).abs() < 5e-4, "{want}");
    let drift64 = core_math::mtf_drift(48, tan).unwrap();
    let drift32 = core_math::mtf_drift(48, tan as f32).unwrap();
    assert!((drift64 - want).abs() < 1e-12, "f64 {drift64} vs {want}");
    assert!(
        (f64::from(drift32) - want).abs() < 1e-6,
        "f32 {drift32} vs {want}"
    );
    // Mismatch and drift are the same function of M x.
    assert_eq!(mtf_mismatch(48, tan).unwrap(), drift64);
    // Over the first lobes, both signs: in [0, 1] and |sin(x)/x|.
    for i in 1..=40_000 {
        let x = i as f64 * 1e-3;
        let want = libm::fabs(libm::sin(x) / x);
        for x in [x, -x] {
            let got64 = core_math::smear_mtf(x);
            let got32 = core_math::smear_mtf(x as f32);
            assert!(
                (got64 - want).abs() < 1e-10,
                "f64 at {x}: {got64} vs {want}"
            );
            assert!(
                (f64::from(got32) - want).abs() < 3e-7,
                "f32 at {x}: {got32} vs {want}"
            );
            assert!((0.0..=1.0).contains(&got32) && (0.0..=1.0).contains(&got64));
        }
    }
}

#[test]
fn mtf_mismatch_is_eq_19() {
    // Eq. 19: sin(pi M dv/(2v)) / (pi M dv/(2v)).
    for (m, d) in [(16u32, 0.01f64), (48, 0.019), (96, 0.001), (1, 0.5)] {
        let x = std::f64::consts::PI * m as f64 * d / 2.0;
        let expect = libm::sin(x) / x;
        assert!((mtf_mismatch(m, d).unwrap() - expect).abs() < 1e-10);
        assert!(
            (mtf_mismatch(m, -d).unwrap() - expect).abs() < 1e-10,
            "even in dv"
        );
    }
    assert_eq!(mtf_mismatch(48, 0.0f64).unwrap(), 1.0);
    assert_eq!(
        mtf_mismatch(48, f64::NAN),
        Err(ModelError::NonFinite(core_math::Param::RelativeMismatch))
    );
}

/// The largest M with sin(x)/x >= floor, by walking M upward with libm.
fn brute_max_stages(d: f64, floor: f64, limit: u32) -> u32 {
    let mut best = 0;
    for m in 1..=limit {
        let x = std::f64::consts::PI * m as f64 * d.abs() / 2.0;
        let v = if x == 0.0 { 1.0 } else { libm::sin(x) / x };
        if v >= floor {
            best = m;
        } else {
            break;
        }
    }
    best
}

#[test]
fn stage_rule_matches_brute_force() {
    for floor in [0.5, 0.8, 0.9, 0.95, 0.99, 0.999] {
        let rule = StageRule::<f64>::new(floor).unwrap();
        let rule32 = StageRule::<f32>::new(floor).unwrap();
        for i in 0..2_000 {
            let d = 1e-5 * 1.005f64.powi(i);
            let expect = brute_max_stages(d, floor, 256);
            assert_eq!(
                rule.max_stages(d, 256).unwrap(),
                expect,
                "floor {floor} d {d}"
            );
            let got32 = rule32.max_stages(d as f32, 256).unwrap();
            // f32 may decide a case that sits on the floor to within its rounding either way.
            assert!(
                got32.abs_diff(expect) <= 1,
                "f32: floor {floor} d {d}: {got32} vs {expect}"
            );
        }
        assert_eq!(
            rule.max_stages(0.0, 96).unwrap(),
            96,
            "no mismatch: the sensor's limit"
        );
    }
}

#[test]
fn stage_rule_refuses_bad_floors() {
    for f in [0.0, 1.0, -0.1, 1.5] {
        assert!(matches!(
            StageRule::<f64>::new(f),
            Err(ModelError::OutOfDomain(_))
        ));
    }
    assert!(matches!(
        StageRule::<f64>::new(f64::NAN),
        Err(ModelError::NonFinite(_))
    ));
}

#[test]
fn line_period_and_ticks() {
    // 13 um at 5.81 mm/s.
    let t = speed_line_period_s(13e-6, 5.81e-3f64).unwrap();
    assert!((t - 13e-6 / 5.81e-3).abs() < 1e-18);
    // 10 MHz clock: exact integer rounding and its error.
    let ticks = line_period_ticks(t, 10e6).unwrap();
    let exact = t * 10e6;
    assert_eq!(ticks.ticks as f64, (exact + 0.5).floor());
    assert!((ticks.rounding_error_s - (ticks.ticks as f64 - exact) / 10e6).abs() < 1e-18);
    assert!(ticks.rounding_error_s.abs() <= 0.5 / 10e6);
    // The same in f32.
    let t32 = speed_line_period_s(13e-6f32, 5.81e-3).unwrap();
    assert_eq!(line_period_ticks(t32, 10e6f32).unwrap().ticks, ticks.ticks);
}

/// `nearest_ticks` (the controller's route, no input checks) gives a count in range or
/// the error for any input: half up against exact integer arithmetic in f64, and every
/// non-finite, negative or out-of-range count refused.
#[test]
fn nearest_ticks_takes_any_input() {
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    for _ in 0..100_000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        // Counts from 1e-3 to 1e10, and exact halves.
        let exact = 10f64.powf((x % 13_000) as f64 / 1_000.0 - 3.0);
        for e in [exact, (exact * 2.0).round() / 2.0] {
            let want = (e + 0.5).floor();
            let ok = want >= 1.0 && want <= u32::MAX as f64;
            assert_eq!(
                nearest_ticks(e),
                if ok {
                    Ok(want as u32)
                } else {
                    Err(ModelError::LinePeriodOutOfRange)
                },
                "{e}"
            );
        }
    }
    for bad in [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -1.0,
        0.0,
        0.49,
        4.3e9,
    ] {
        assert_eq!(
            nearest_ticks(bad),
            Err(ModelError::LinePeriodOutOfRange),
            "{bad}"
        );
    }
    assert_eq!(nearest_ticks(0.5f32), Ok(1));
    assert_eq!(nearest_ticks(4_294_967_040.0f32), Ok(4_294_967_040));
}

#[test]
fn line_period_refusals() {
    assert_eq!(
        speed_line_period_s(13e-6, 0.0f64),
        Err(ModelError::NoImageMotion)
    );
    assert_eq!(
        speed_line_period_s(13e-6, -1.0f64),
        Err(ModelError::NoImageMotion)
    );
    assert_eq!(
        speed_line_period_s(13e-6, f64::NAN),
        Err(ModelError::NoImageMotion)
    );
    assert_eq!(
        speed_line_period_s(13e-6f32, 1e-44),
        Err(ModelError::NoImageMotion),
        "overflow to inf"
    );
    assert_eq!(
        speed_line_period_s(0.0, 1.0f64),
        Err(ModelError::NonPositivePixelPitch)
    );
    // Largest and smallest periods the 32-bit counter holds.
    assert_eq!(
        line_period_ticks(u32::MAX as f64 / 1e6, 1e6).unwrap().ticks,
        u32::MAX
    );
    assert_eq!(
        line_period_ticks(4.3e9 / 1e6, 1e6f64),
        Err(ModelError::LinePeriodOutOfRange)
    );
    assert_eq!(line_period_ticks(1e-6, 1e6f64).unwrap().ticks, 1);
    assert_eq!(
        line_period_ticks(0.4e-6, 1e6f64),
        Err(ModelError::LinePeriodOutOfRange)
    );
    assert!(line_period_ticks(1e-3, 0.0f64).is_err());
    assert!(line_period_ticks(1e-3, f64::INFINITY).is_err());
}

#[test]
fn dual_numbers_differentiate_exactly() {
    use core_math::dual::Dual;
    // d/dt [sin(3t) * cos(t) / (2 + t)] at t = 0.7, against the hand derivative.
    let t0 = 0.7f64;
    let t = Dual::new(t0, 1.0);
    let f = (Dual::constant(3.0) * t).sin() * t.cos() / (Dual::constant(2.0) + t);
    let (s3, c3, s, c) = (
        libm::sin(3.0 * t0),
        libm::cos(3.0 * t0),
        libm::sin(t0),
        libm::cos(t0),
    );
    let num = s3 * c;
    let dnum = 3.0 * c3 * c - s3 * s;
    let expect = (dnum * (2.0 + t0) - num) / ((2.0 + t0) * (2.0 + t0));
    assert!((f.du - expect).abs() < 1e-15, "{} vs {}", f.du, expect);
    assert!((f.re - num / (2.0 + t0)).abs() < 1e-16);
}

/// The combined MTF (mismatch x drift smear) at `m` stages in f64 with libm's sine:
/// each factor the modulus |sin(x)/x|.
fn product(m: u32, e: f64, t: f64) -> f64 {
    let s = |x: f64| {
        if x == 0.0 {
            1.0
        } else {
            libm::fabs(libm::sin(x) / x)
        }
    };
    let h = std::f64::consts::FRAC_PI_2 * m as f64;
    s(h * e) * s(h * t)
}

/// Uniform draws in [0, 1) from a 64-bit LCG seeded with `state` (Knuth's MMIX
/// constants; the top 53 bits).
fn uniform(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The stage limit of the combined MTF (mismatch x drift smear) against a brute-force
/// search in f64 with libm's sine: the count returned meets the floor and the next one
/// does not (or the limit is reached), over mismatches and drifts from none to large.
#[test]
fn stage_limit_with_drift_is_the_largest_count_meeting_the_floor() {
    let mut next = uniform(0x5EED_u64);
    let mut checked = 0;
    for floor in [0.25, 0.5, 0.8, 0.9, 0.95, 0.99] {
        let rule = StageRule::<f64>::new(floor).unwrap();
        let rule32 = StageRule::<f32>::new(floor).unwrap();
        for _ in 0..2_000 {
            let e = 10f64.powf(-6.0 + 5.0 * next()) * if next() < 0.1 { 0.0 } else { 1.0 };
            let t = 10f64.powf(-6.0 + 5.0 * next()) * if next() < 0.1 { 0.0 } else { 1.0 };
            let limit = 1 + (next() * 300.0) as u32;
            // Brute force: the largest M meeting the floor at every count up to it;
            // and no later count meets it either (the later lobes stay under 0.25),
            // so it is also the largest count that meets it at all.
            let mut expect = 0;
            while expect < limit && product(expect + 1, e, t) >= floor {
                expect += 1;
            }
            assert!(
                (expect + 1..=limit).all(|m| product(m, e, t) < floor),
                "floor {floor}, e {e:e}, t {t:e}: a later lobe meets the floor"
            );
            let got = rule.max_stages_with_drift(e, t, limit).unwrap();
            assert_eq!(
                got, expect,
                "floor {floor}, e {e:e}, t {t:e}, limit {limit}"
            );
            // f32: meets the floor in f64 to its own rounding, and at most one stage
            // from the f64 answer.
            let got32 = rule32
                .max_stages_with_drift(e as f32, t as f32, limit)
                .unwrap();
            assert!(got32.abs_diff(expect) <= 1, "f32 {got32} vs {expect}");
            assert!(got32 == 0 || product(got32, e, t) >= floor - 1e-6);
            checked += 1;
        }
    }
    assert_eq!(checked, 12_000);
    // Counts from one stage to MAX_STAGE_LIMIT (mismatch and drift down to 1e-9, where
    // the guess is tens of thousands of stages off and the fallback answers): the
    // guess-and-check rule agrees with the bracket-and-bisection one in f64, and in
    // f32 its count meets the floor while the next one does not, to f32 rounding.
    let mut large_counts = 0;
    for floor in [0.25, 0.5, 0.9, 0.99] {
        let rule = StageRule::<f64>::new(floor).unwrap();
        let rule32 = StageRule::<f32>::new(floor).unwrap();
        for _ in 0..3_000 {
            let e = 10f64.powf(-9.0 + 8.0 * next()) * if next() < 0.1 { 0.0 } else { 1.0 };
            let t = 10f64.powf(-9.0 + 8.0 * next()) * if next() < 0.1 { 0.0 } else { 1.0 };
            let limit = if next() < 0.5 {
                core_math::mtf::MAX_STAGE_LIMIT
            } else {
                1 + (next() * 1_000.0) as u32
            };
            let got = rule.max_stages_with_drift(e, t, limit).unwrap();
            let bisected = rule
                .max_stages_with_drift_by_bisection(e, t, limit)
                .unwrap();
            assert_eq!(
                got, bisected,
                "floor {floor}, e {e:e}, t {t:e}, limit {limit}"
            );
            if got > 10_000 && got < limit {
                large_counts += 1;
            }
            let got32 = rule32
                .max_stages_with_drift(e as f32, t as f32, limit)
                .unwrap();
            let tol = 1e-6;
            assert!(
                got32 == 0 || product(got32, e, t) >= floor - tol,
                "f32 {got32}"
            );
            assert!(
                got32 >= limit.min(core_math::mtf::MAX_STAGE_LIMIT)
                    || product(got32 + 1, e, t) < floor + tol,
                "f32 {got32}: the next count meets the floor too (e {e:e}, t {t:e})"
            );
        }
    }
    eprintln!("counts over 10 000 stages checked: {large_counts} (the guess alone cannot reach most of them)");
    assert!(
        large_counts > 100,
        "too few large counts: the fallback went unexercised"
    );
    // No drift: the same as the mismatch-only rule.
    let rule = StageRule::<f64>::new(0.95).unwrap();
    for e in [0.0, 1e-4, 3.7e-3, 0.02] {
        assert_eq!(
            rule.max_stages_with_drift(e, 0.0, 256).unwrap(),
            rule.max_stages(e, 256).unwrap()
        );
    }
}

/// The fixed-point sinc (`mtf::int`, the Cortex-M3's) against libm's sine in f64 over
/// its whole range, y = 0 ... 1 (x = pi y up to the first zero): within 5e-9.
#[test]
fn fixed_point_sinc_matches_libm() {
    use core_math::mtf::int::sinc_pi_q30;
    let mut worst = 0f64;
    let n = 1u32 << 20;
    for i in 0..=n {
        let y_q30 = ((u64::from(i) << 30) / u64::from(n)) as u32;
        let x = std::f64::consts::PI * f64::from(y_q30) / (1u64 << 30) as f64;
        let exact = if x == 0.0 { 1.0 } else { libm::sin(x) / x };
        let got = f64::from(sinc_pi_q30(y_q30)) / (1u64 << 30) as f64;
        worst = worst.max((got - exact).abs());
    }
    assert!(worst <= 5e-9, "{worst:e}");
    eprintln!("fixed-point sinc: worst error {worst:.2e}");
}

/// The fixed-point smear MTF and stage limit (`mtf::int`) against f64 with libm's
/// sine: the MTF within 1e-8 plus f32's rounding on every lobe, the stage limit meeting the floor to
/// 1e-8 and the next count missing it, over mismatches and drifts from none to past the
/// first zero.
#[test]
fn fixed_point_mtf_and_stage_limit_match_libm() {
    use core_math::mtf::int::smear_mtf_pair;
    let mut next = uniform(0x5EED_2024_u64);
    let (mut worst_mtf, mut differ) = (0f64, 0);
    for floor in [0.25, 0.5, 0.8, 0.9, 0.95, 0.99] {
        let rule32 = StageRule::<f32>::new(floor).unwrap();
        for _ in 0..5_000 {
            let e = (10f64.powf(-7.0 + 6.5 * next()) * if next() < 0.1 { 0.0 } else { 1.0 }) as f32;
            let t = (10f64.powf(-7.0 + 6.5 * next()) * if next() < 0.1 { 0.0 } else { 1.0 }) as f32;
            let (e64, t64) = (f64::from(e), f64::from(t));
            let limit = 1 + (next() * 300.0) as u32;
            let stages = 1 + (next() * 300.0) as u32;
            let mtf = f64::from(smear_mtf_pair(stages, e, t));
            let want = product(stages, e64, t64);
            let err = (mtf - want).abs();
            assert!(
                err <= 1e-8 + want * f64::from(f32::EPSILON),
                "stages {stages}, e {e:e}, t {t:e}: {mtf} vs {want}"
            );
            worst_mtf = worst_mtf.max(err);
            let got = rule32.max_stages_with_drift_int(e, t, limit).unwrap();
            assert!(
                got == 0 || product(got, e64, t64) >= floor - 1e-8,
                "floor {floor}, e {e:e}, t {t:e}: {got} misses the floor"
            );
            assert!(
                got == limit || product(got + 1, e64, t64) < floor + 1e-8,
                "floor {floor}, e {e:e}, t {t:e}: {got} not the largest"
            );
            if got != rule32.max_stages_with_drift(e, t, limit).unwrap() {
                differ += 1;
            }
        }
    }
    eprintln!("fixed-point MTF: worst error {worst_mtf:.2e}; stage limits differing from f32's: {differ} of 30 000");
}

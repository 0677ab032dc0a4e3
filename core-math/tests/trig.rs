//! The f32 sine/cosine against f64 libm, and the f64 sine/cosine against libm's.

use core_math::trig::{atan_f32, sin_cos_f32, sin_cos_f32_q30, sin_cos_int, sin_cos_q30};
use core_math::trig_f64;

fn ulp_err(got: f32, exact: f64) -> f64 {
    // Error in units of the f32 spacing at the exact value.
    let e = (got as f64 - exact).abs();
    let spacing = f64::from(f32::EPSILON)
        * exact
            .abs()
            .max(f64::from(f32::MIN_POSITIVE))
            .log2()
            .floor()
            .exp2();
    e / spacing
}

#[test]
fn within_one_ulp_over_the_angles_the_model_uses() {
    let mut worst = (0.0f64, 0.0f32);
    // Dense over [-100, 100] rad plus exact multiples of pi/4 and tiny arguments.
    let mut xs: Vec<f32> = (0..2_000_001)
        .map(|i| (i as f32 - 1_000_000.0) * 1e-4)
        .collect();
    xs.extend((-120..=120).map(|k| (k as f64 * std::f64::consts::FRAC_PI_4) as f32));
    xs.extend([1e-30, -1e-30, 1e-7, 0.0, -0.0, 3.0e-39]);
    for &x in &xs {
        let (s, c) = sin_cos_f32(x);
        let (es, ec) = (libm::sin(f64::from(x)), libm::cos(f64::from(x)));
        for (g, e) in [(s, es), (c, ec)] {
            // Near a zero of sin or cos the absolute error is what can be asked for.
            let u = if e.abs() < 1e-3 {
                (g as f64 - e).abs() / 1e-10
            } else {
                ulp_err(g, e)
            };
            if u > worst.0 {
                worst = (u, x);
            }
        }
    }
    eprintln!("worst {:.3} ulp at x = {}", worst.0, worst.1);
    assert!(
        worst.0 <= 2.0,
        "worst {:.3} ulp at x = {}",
        worst.0,
        worst.1
    );
}

#[test]
fn large_and_special_arguments() {
    assert_eq!(sin_cos_f32(0.0), (0.0, 1.0));
    // Beyond the fast range: the f64 sincos of the exact argument, rounded; that is
    // sincosf's correctly rounded value here (and at every argument within 1 ulp).
    for x in [1e5f32, -1.6e6, 12_800.0] {
        let (s, c) = sin_cos_f32(x);
        let (s64, c64) = libm::sincos(f64::from(x));
        assert_eq!((s, c), (s64 as f32, c64 as f32), "{x}");
        let (sf, cf) = libm::sincosf(x);
        assert!(
            (s - sf).abs() <= f32::EPSILON && (c - cf).abs() <= f32::EPSILON,
            "{x}"
        );
    }
    assert_eq!(sin_cos_f32(1e5), libm::sincosf(1e5));
    // Beyond 2^20 pi/2 rad the f64 reduction stops: NaN, as for NaN and infinities.
    for x in [f32::NAN, f32::INFINITY, -3.0e7, 1.7e38, 1.648e6] {
        let (s, c) = sin_cos_f32(x);
        assert!(s.is_nan() && c.is_nan(), "{x}");
    }
}

/// Every f64 argument from 1e-30 to past the limit, both signs, dense on a log scale and
/// at the multiples of pi/4 where fdlibm's reduction changes case: `trig_f64` is libm's
/// `sincos`, `sin` and `cos` bit for bit below [`trig_f64::SIN_COS_LIMIT_RAD`], NaN
/// above.
#[test]
fn f64_sin_cos_is_libm_bit_for_bit_below_the_limit() {
    let mut xs = Vec::new();
    let mut x = 1e-30f64;
    while x < 1e7 {
        xs.push(x);
        x = f64::from_bits(x.to_bits() + 0x0000_0a7f_0000_0001);
    }
    for k in 1..=40_000 {
        let m = f64::from(k) * core::f64::consts::FRAC_PI_4;
        for d in -3i64..=3 {
            xs.push(f64::from_bits((m.to_bits() as i64 + d) as u64));
        }
    }
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    for _ in 0..200_000 {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        xs.push((seed >> 11) as f64 / (1u64 << 53) as f64 * 30.0);
    }
    let mut below = 0;
    for &x in &xs {
        for v in [x, -x] {
            let (s, c) = trig_f64::sin_cos(v);
            if v.abs() < trig_f64::SIN_COS_LIMIT_RAD {
                below += 1;
                let (ls, lc) = libm::sincos(v);
                assert_eq!(
                    (s.to_bits(), c.to_bits()),
                    (ls.to_bits(), lc.to_bits()),
                    "{v:e}"
                );
                assert_eq!(trig_f64::sin(v).to_bits(), libm::sin(v).to_bits(), "{v:e}");
                assert_eq!(trig_f64::cos(v).to_bits(), libm::cos(v).to_bits(), "{v:e}");
                // The pair's halves are the single functions: the flight binary's DEM
                // route takes its sines and cosines from the pair.
                assert_eq!(
                    (s.to_bits(), c.to_bits()),
                    (trig_f64::sin(v).to_bits(), trig_f64::cos(v).to_bits()),
                    "{v:e}"
                );
            } else if v.abs() >= 1_647_100.0 {
                assert!(s.is_nan() && c.is_nan(), "{v:e}");
                assert!(
                    trig_f64::sin(v).is_nan() && trig_f64::cos(v).is_nan(),
                    "{v:e}"
                );
            }
        }
    }
    assert!(below > 500_000, "{below}");
    for v in [f64::NAN, f64::INFINITY, -f64::INFINITY] {
        let (s, c) = trig_f64::sin_cos(v);
        assert!(s.is_nan() && c.is_nan());
        assert!(trig_f64::sin(v).is_nan() && trig_f64::cos(v).is_nan());
    }
    assert_eq!(trig_f64::sin_cos(-0.0).0.to_bits(), (-0.0f64).to_bits());
}

/// atan over every magnitude the drift tangent can take (10^-30 ... 10^30, dense near
/// the reduction boundaries), against f64 libm: within 2.5 ulp of the exact value
/// (measured 2.18, just under tan(pi/8), where the polynomial meets its range end;
/// Cephes states 1.9e-7 relative for its `atanf`).
#[test]
fn atan_within_two_and_a_half_ulp_over_every_magnitude() {
    let mut xs: Vec<f32> = (0..=600_000)
        .map(|i| 10f32.powf(-30.0 + 60.0 * i as f32 / 600_000.0))
        .collect();
    xs.extend((0..=400_000).map(|i| i as f32 * 1e-5));
    for edge in [0.414_213_57f32, 2.414_213_5, 1.0] {
        let mut y = edge;
        for _ in 0..64 {
            xs.extend([
                y,
                f32::from_bits(edge.to_bits() + (edge.to_bits() - y.to_bits())),
            ]);
            y = f32::from_bits(y.to_bits() - 1);
        }
    }
    let mut worst = (0.0f64, 0.0f32);
    for &x in &xs {
        for x in [x, -x] {
            let u = ulp_err(atan_f32(x), libm::atan(f64::from(x)));
            if u > worst.0 {
                worst = (u, x);
            }
        }
    }
    eprintln!("atan_f32: worst {:.3} ulp at x = {:e}", worst.0, worst.1);
    assert!(
        worst.0 <= 2.5,
        "worst {:.3} ulp at x = {}",
        worst.0,
        worst.1
    );
}

#[test]
fn atan_special_arguments() {
    assert_eq!(atan_f32(0.0).to_bits(), 0.0f32.to_bits());
    assert_eq!(atan_f32(-0.0).to_bits(), (-0.0f32).to_bits());
    assert_eq!(atan_f32(f32::INFINITY), core::f32::consts::FRAC_PI_2);
    assert_eq!(atan_f32(f32::NEG_INFINITY), -core::f32::consts::FRAC_PI_2);
    assert!(atan_f32(f32::NAN).is_nan());
    assert_eq!(atan_f32(1e-40), 1e-40, "subnormal: atan x = x");
}

/// The integer sine and cosine (the Cortex-M3's) against libm in f64: within 1e-8 of the
/// exact value relative, plus its rounding to f32 (half a spacing), at every magnitude
/// below 4 rad including the zeros of the cosine (relative there too: r is exact);
/// beyond, libm's f64 values rounded to f32; NaN for NaN and infinities.
#[test]
fn integer_sin_cos_within_1e8_and_the_rounding() {
    // xorshift64: uniform in [0, 1).
    let mut state = 0x5EED_2026_1127_0006u64;
    let mut unit = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut worst = 0f64;
    let mut check = |x: f32| {
        let (s, c) = sin_cos_int(x);
        for (g, e) in [(s, libm::sin(f64::from(x))), (c, libm::cos(f64::from(x)))] {
            let spacing = f64::from(f32::EPSILON) * e.abs().log2().floor().exp2();
            let err = (f64::from(g) - e).abs();
            let rel = (err - 0.5 * spacing).max(0.0) / e.abs();
            assert!(rel <= 1e-8, "x = {x:e}: {g:e} vs {e:e}");
            worst = worst.max(rel);
        }
    };
    for i in 0..2_000_000 {
        let x = if i % 2 == 0 {
            (8.0 * unit() - 4.0) as f32
        } else {
            (libm::exp2(32.0 * unit() - 30.0) * if i % 4 == 1 { 1.0 } else { -1.0 }) as f32
        };
        check(x);
    }
    // The f32s nearest each multiple of pi/4 and their neighbours.
    for k in -5i32..=5 {
        let x = (f64::from(k) * std::f64::consts::FRAC_PI_4) as f32;
        for d in -3i32..=3 {
            let y = f32::from_bits((x.to_bits() as i32 + d) as u32);
            if y != 0.0 && y.abs() < 4.0 {
                check(y);
            }
        }
    }
    eprintln!("integer sin/cos: worst error beyond the f32 rounding {worst:.2e} relative");
    for x in [
        0.0f32,
        -0.0,
        1e-30,
        -3.0e-39,
        4.0,
        -7.5,
        1e4,
        f32::NAN,
        f32::INFINITY,
    ] {
        let (s, c) = sin_cos_int(x);
        if !x.is_finite() {
            assert!(s.is_nan() && c.is_nan(), "{x}");
            continue;
        }
        let (fs, fc) = if x.abs() < 1e-6 {
            (x, 1.0)
        } else {
            let x = f64::from(x);
            (libm::sin(x) as f32, libm::cos(x) as f32)
        };
        assert_eq!(
            (s.to_bits(), c.to_bits()),
            (fs.to_bits(), fc.to_bits()),
            "{x}"
        );
    }
}

/// The Q30 sine and cosine on [0, pi/2] against f64 libm of the same Q30 argument: within
/// 3 units of Q30 (the polynomials' truncation below 9e-12, six roundings of half a
/// unit each through factors below 1, r^2's truncation), over 2^20 arguments and the
/// ends.
#[test]
fn q30_sin_cos_within_three_units() {
    let half_pi_q30 = 1_686_629_713i32;
    let mut worst = 0f64;
    let mut check = |x: i32| {
        let (s, c) = sin_cos_q30(x);
        let xf = f64::from(x) / (1u64 << 30) as f64;
        for (got, want) in [(s, libm::sin(xf)), (c, libm::cos(xf))] {
            let err = (f64::from(got) - want * (1u64 << 30) as f64).abs();
            assert!(err <= 3.0, "sin_cos_q30({x}): {got} vs {want}");
            worst = worst.max(err);
        }
    };
    let mut x = 0x9E37_79B9u32;
    for i in 0..(1u32 << 20) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        check(((u64::from(x) * half_pi_q30 as u64) >> 32) as i32);
        check(((u64::from(i) * half_pi_q30 as u64) >> 20) as i32);
    }
    for x in [
        0,
        1,
        843_314_856,
        843_314_857,
        843_314_858,
        half_pi_q30 - 1,
        half_pi_q30,
    ] {
        check(x);
    }
    std::eprintln!("sin_cos_q30: worst {worst:.2} units of Q30");
}

/// The Q30 sine and cosine of an f32 angle against f64 libm of the same f32: within 4
/// units of Q30 (the reduction's r rounded to Q30, then `sin_cos_q30`'s three), over 2^21
/// angles below 4 rad of either sign, tiny and subnormal ones, and the quadrant edges;
/// None from 4 rad on and for non-finite angles.
#[test]
fn f32_angle_q30_sin_cos_within_four_units() {
    let mut worst = 0f64;
    let mut check = |x: f32| {
        let (s, c) = sin_cos_f32_q30(x).expect("below 4 rad");
        let xf = f64::from(x);
        for (got, want) in [(s, libm::sin(xf)), (c, libm::cos(xf))] {
            let err = (f64::from(got) - want * (1u64 << 30) as f64).abs();
            assert!(err <= 4.0, "sin_cos_f32_q30({x:e}): {got} vs {want}");
            worst = worst.max(err);
        }
    };
    let mut u = 0x9E37_79B9u32;
    for _ in 0..(1u32 << 21) {
        u ^= u << 13;
        u ^= u >> 17;
        u ^= u << 5;
        let x = (f64::from(u) / f64::from(u32::MAX) * 8.0 - 4.0) as f32;
        if x.abs() < 4.0 {
            check(x);
        }
        // Every magnitude below 1.
        check(f32::from_bits(u % 0x3f80_0000));
        check(-f32::from_bits(u % 0x3f80_0000));
    }
    for x in [
        0.0f32,
        -0.0,
        1e-30,
        1e-45,
        core::f32::consts::FRAC_PI_4,
        2.356_194_5,
        3.926_990_8,
        3.999_999_8,
    ] {
        check(x);
        check(-x);
    }
    for x in [4.0f32, -4.0, 100.0, f32::NAN, f32::INFINITY] {
        assert!(sin_cos_f32_q30(x).is_none(), "{x}");
    }
    std::eprintln!("sin_cos_f32_q30: worst {worst:.2} units of Q30");
}

//! The drift angles against atan in f64, by both routes.
extern crate std;
use super::drift_angles_rad;

/// The three drift angles against atan in f64: the worst one by its difference form
/// within 4 f32 ulp of 1 rad, never below the centre's magnitude.
#[test]
fn drift_angles_match_atan() {
    let mut rng = core_math::sample::SplitMix64(0x5EED_2026_1124);
    let mut next = || rng.uniform(0.0, 1.0);
    let mut worst_err = 0f64;
    for _ in 0..200_000 {
        // Tangents over drifts of 0 to 1.5 rad, either sign.
        let c = libm::tan(1.5 * next()) * if next() < 0.5 { -1.0 } else { 1.0 };
        let m = libm::fabs(c) + libm::tan(1.5 * next()) * next();
        let r = libm::tan(0.3 * next() - 0.15);
        let (c, m, r) = (c as f32, (m as f32).max((c as f32).abs()), r as f32);
        let [dc, dm, dr] = drift_angles_rad(c, m, r);
        for (got, t) in [(dc, c), (dm, m), (dr, r)] {
            let want = libm::atan(f64::from(t));
            worst_err = worst_err.max(libm::fabs(f64::from(got) - want));
        }
        assert!(dm >= dc.abs(), "{c} {m}: {dm} < |{dc}|");
    }
    assert!(
        worst_err <= 4.0 * f64::from(f32::EPSILON) / 2.0,
        "{worst_err:e}"
    );
    std::eprintln!("drift angles: worst error {worst_err:.2e} rad");
}

/// The integer drift angle of a (v2, v1) pair (the Cortex-M3's) against atan2 in
/// f64 of the same f32 inputs: within 3.5e-9 rad plus half an f32 ulp of the result,
/// over ratios from 1e-9 to 1e9, either sign, and the edge cases.
#[cfg(feature = "earth-fixed")]
#[test]
fn integer_drift_angle_matches_atan() {
    use super::sweep::{atan_pair_rad, q30_to_f32};
    let mut rng = core_math::sample::SplitMix64(0x5EED_2026_1127);
    let mut worst_err = 0f64;
    let mut check = |num: f32, den: f32| {
        let got = f64::from(atan_pair_rad(num, den));
        let want = libm::atan(f64::from(num) / f64::from(den));
        let err = libm::fabs(got - want);
        assert!(
            err <= 3.5e-9 + 0.5 * f64::from(f32::EPSILON) * libm::fabs(want),
            "atan({num:e} / {den:e}) = {got} vs {want}"
        );
        worst_err = worst_err.max(err);
    };
    for _ in 0..400_000 {
        let den = (libm::exp(rng.uniform(-20.0, 20.0)) * rng.uniform(-1.0, 1.0)) as f32;
        let ratio = libm::exp(rng.uniform(-21.0, 21.0)) * rng.uniform(-1.0, 1.0);
        let num = (f64::from(den) * ratio) as f32;
        if den != 0.0 && den.is_normal() {
            check(num, den);
        }
    }
    for (num, den) in [
        (0.0, 1.0),
        (-0.0, 1.0),
        (1.0, 1.0),
        (-1.0, 1.0),
        (1.0, -1.0),
        (7_000.0, 1e-30),
        (1e-30, 7_000.0),
        (f32::MAX, 1.0),
        (1.0, f32::MAX),
        (f32::MIN_POSITIVE, 3.0),
    ] {
        check(num, den);
    }
    // Non-finite inputs and a zero denominator take atan_f32 of the quotient.
    assert_eq!(
        atan_pair_rad(1.0, 0.0),
        drift_angles_rad(f32::INFINITY, 0.0, 0.0)[0]
    );
    assert!(atan_pair_rad(f32::NAN, 1.0).is_nan());
    std::eprintln!("integer drift angle: worst error {worst_err:.2e} rad");
    // Q30 to f32 against the conversion and scaling in f32 (round to nearest even:
    // they may differ at exact ties only, by one ulp).
    let mut x = 0x9E37_79B9u32;
    for i in 0..1_000_000u32 {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        let q = x >> (i % 32);
        let want = q as f32 * (1.0 / (1u32 << 30) as f32);
        let got = q30_to_f32(q);
        let exact = f64::from(q) / (1u64 << 30) as f64;
        assert!(
            libm::fabs(f64::from(got) - exact) <= 0.5 * f64::from(want) * f64::from(f32::EPSILON),
            "{q}: {got} vs {want}"
        );
    }
    assert_eq!(q30_to_f32(0), 0.0);
}

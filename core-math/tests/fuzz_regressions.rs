//! The findings of the fuzzers (docs/fuzzing.md, F1-F5), each kept as a test.

use core_math::sphere::speed_line_period_s;
use core_math::sphere::{Geometry, Reference, CLOSED_F32, CLOSED_F64};
use core_math::{mtf_mismatch, Backend, Camera, ModelError, StageRule};
use std::f64::consts::TAU;

/// F1: an overflowing sinc argument gave NaN; the limit is 0.
#[test]
fn f1_mtf_of_an_overflowing_argument_is_zero_not_nan() {
    assert_eq!(mtf_mismatch::<f64>(2, 1e308).unwrap(), 0.0);
    assert_eq!(mtf_mismatch::<f32>(u32::MAX, 1e30).unwrap(), 0.0);
    assert_eq!(
        mtf_mismatch::<f64>(2_425_393_296, -1.404_447_091_918_304_8e306).unwrap(),
        0.0
    );
}

/// F7: from 1 647 099 rad on the sine (no huge-argument reduction) is NaN, and so was
/// sinc there; |sinc x| <= 1/|x| bounds the answer, which must be finite.
#[test]
fn f7_mtf_beyond_the_sines_domain_is_within_its_bound() {
    let fuzzed = 0.1f32 - f32::EPSILON / 16.0; // 0.1 less one ulp (the fuzzer's case)
    let cases: [(u32, f64); 5] = [
        (u32::MAX, f64::from(fuzzed)),
        (1_048_576, 1.0),          // x = 1 647 099.3, just past the limit
        (1_048_575, 1.0),          // x = 1 647 097.8, just inside: the sine is computed
        (256, 5_000.0),            // x = 2.0e6
        (2_000_000_000, -0.002_5), // x = -7.9e6
    ];
    for (stages, rel) in cases {
        let x = std::f64::consts::FRAC_PI_2 * f64::from(stages) * rel.abs();
        let f64_mtf = mtf_mismatch::<f64>(stages, rel).unwrap();
        let f32_mtf = mtf_mismatch::<f32>(stages, rel as f32).unwrap();
        for m in [f64_mtf, f64::from(f32_mtf)] {
            assert!(
                m.is_finite() && (0.0..=1.0 / x).contains(&m),
                "{stages} {rel}: {m}"
            );
        }
    }
}

/// F2: an infinite speed, or an underflowing quotient, gave a zero period.
#[test]
fn f2_no_zero_line_period() {
    assert_eq!(
        speed_line_period_s(13e-6, f64::INFINITY),
        Err(ModelError::LinePeriodOutOfRange)
    );
    assert_eq!(
        speed_line_period_s(13e-6f32, f32::INFINITY),
        Err(ModelError::LinePeriodOutOfRange)
    );
    assert_eq!(
        speed_line_period_s::<f64>(1e-300, 1e300),
        Err(ModelError::LinePeriodOutOfRange)
    );
}

/// F3: a roll beyond pi put the limb distance 2 pi away: NaN for a ray that misses the
/// Earth, a refusal for one that meets it. The closed forms now agree with the reference.
#[test]
fn f3_rolls_beyond_pi_agree_with_the_reference() {
    let cases = [
        (
            Camera {
                focal_m: 1.0,
                pixel_m: 1.0,
            },
            Geometry::circular(0.0657 + 166.0 * TAU, 0.5, 0.3, 20e6, 32.8e6),
            -344.5,
        ),
        (
            Camera {
                focal_m: 0.555,
                pixel_m: 13e-6,
            },
            Geometry::circular(0.1 + TAU, 1.71, 0.3, 645e3, 6.371e6),
            20_000.0,
        ),
        (
            Camera {
                focal_m: 0.555,
                pixel_m: 13e-6,
            },
            Geometry::circular(0.1 - 3.0 * TAU, 1.71, 0.3, 645e3, 6.371e6),
            -20_000.0,
        ),
    ];
    for (cam, g, n) in cases {
        let r = Reference.evaluate(&cam, &g, n);
        let m64 = CLOSED_F64.evaluate(&cam, &g, n);
        match r {
            Ok(v) => {
                let m = m64.unwrap();
                assert!(
                    (m.speed_mps() - v.speed_mps()).abs() <= 1e-9 * v.speed_mps(),
                    "{m:?} vs {v:?}"
                );
            }
            Err(e) => assert_eq!(m64, Err(e)),
        }
        // f32: the same verdict (its own roll, rounded to f32, wraps the same way).
        let g32 = g.to::<f32>();
        let r32 = Reference.evaluate(&cam, &g32.to_f64(), n);
        let m32 = CLOSED_F32.evaluate(&cam, &g32, n);
        assert_eq!(r32.is_ok(), m32.is_ok(), "{r32:?} vs {m32:?}");
        if let Ok(m) = m32 {
            assert!(m.speed_mps().is_finite());
        }
    }
}

/// F4: the stage search could walk one stage at a time up to a huge limit. Floors are now
/// kept in [0.25, 0.9999] and the correction is bounded.
#[test]
fn f4_stage_search_is_bounded_and_floors_are_in_the_main_lobe() {
    assert!(StageRule::<f32>::new(1.0 - 67.0 * f64::from(f32::EPSILON) / 2.0).is_err());
    assert!(StageRule::<f64>::new(1.04e-13).is_err());
    assert!(
        StageRule::<f64>::new(0.2).is_err(),
        "below sinc's first side lobe"
    );
    for floor in [0.25, 0.5, 0.95, 0.9999] {
        let rule = StageRule::<f64>::new(floor).unwrap();
        for d in [1e-15, 1e-9, 1e-6, 1e-3, 0.1, 1.0, 131_072.000_000_059_6] {
            let m = rule.max_stages(d, u32::MAX).unwrap();
            let mtf = |m: u32| mtf_mismatch(m, d).unwrap();
            // The limit is capped (F5): M is the largest up to MAX_STAGE_LIMIT.
            let cap = core_math::mtf::MAX_STAGE_LIMIT;
            assert!(m <= cap);
            if m > 0 {
                assert!(
                    mtf(m) >= floor - 1e-12,
                    "floor {floor} d {d}: M {m} gives {}",
                    mtf(m)
                );
            }
            if m < cap {
                assert!(
                    mtf(m + 1) < floor + 1e-12,
                    "floor {floor} d {d}: M + 1 = {} still meets",
                    m + 1
                );
            }
        }
    }
}

/// F5: in f32, `max_stages` with a stage limit beyond ~2^23 returned an M that missed
/// the floor. Its guess floor(budget / dv/v) was then off by more than the two
/// correction steps F4 allows (and above 2^24, M +/- 1 may round to the same f32, so a
/// step changes nothing). Fixed by capping the limit at `MAX_STAGE_LIMIT` (2^23), where
/// the next test proves the search. The fuzzer's input (docs/fuzzing.md, run of
/// 2026-11-21) and the smallest case found by a sweep.
#[test]
fn f5_f32_stage_search_meets_the_floor_for_huge_limits() {
    let cases: [(f64, f32, u32); 2] = [
        (
            2_425_393_296.0 / u32::MAX as f64,
            7.041_529e-9,
            2_425_393_296,
        ),
        (0.5, 7.074_536_5e-8, u32::MAX),
    ];
    for (floor, d, limit) in cases {
        let rule = StageRule::<f32>::new(floor).unwrap();
        let m = rule.max_stages(d, limit).unwrap();
        assert!(m <= core_math::mtf::MAX_STAGE_LIMIT);
        let mtf = mtf_mismatch(m, d).unwrap();
        assert!(
            m == 0 || mtf >= rule.mtf_floor(),
            "floor {floor} d {d:e}: M {m} gives {mtf} < {}",
            rule.mtf_floor()
        );
    }
}

/// F5's boundary: up to 2^23 stages the f32 search meets the floor (a sweep of floors
/// and mismatches, each checked against `mtf_mismatch` itself).
#[test]
fn f5_f32_stage_search_meets_the_floor_up_to_2_pow_23() {
    let mut d = 1e-9f64;
    while d < 1e-2 {
        for floor in [0.25, 0.5, 0.8, 0.95, 0.9999] {
            let rule = StageRule::<f32>::new(floor).unwrap();
            let m = rule.max_stages(d as f32, 1 << 23).unwrap();
            if m > 0 {
                let mtf = mtf_mismatch(m, d as f32).unwrap();
                assert!(
                    mtf >= rule.mtf_floor(),
                    "floor {floor} d {d:e}: M {m}, {mtf}"
                );
            }
        }
        d *= 1.0137;
    }
}

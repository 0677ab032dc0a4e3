//! The fixed-point backend against the f64 reference chain: property tests over the
//! envelope (altitude 200-2000 km, roll up to 45 deg, field angles up to 40 deg, any
//! inclination and argument of latitude), its corners, refusals outside it, and the
//! error survey quoted in docs/fixed-point.md (`#[ignore]`d; run with
//! `cargo test --release -p core-math --test fixed_point -- --ignored --nocapture`).
//!
//! Overflow: `cargo test` (dev profile) builds core-math with overflow checks and debug
//! assertions, so every multiply, add and shift of `Fixed::update` and `Fixed::motion`
//! that could wrap panics there instead, and the narrowing casts are bounded by
//! `debug_assert!`s. The corner test runs every corner in that build too.

mod common;

use core_math::sphere::accuracy::limb_margin_rad;
use core_math::sphere::fixed_point::{geometry_from_f64, motion_to_f64};
use core_math::sphere::{FixedReal, Geometry, Reference, FIXED};
use core_math::{Backend, Camera, ImageMotion, ModelError, Param};
use proptest::prelude::*;

/// Relative error of |v_P| and v1, and error of v2 over |v_P|, accepted anywhere in the
/// envelope, the limb included (measured maximum: 1.1e-7, docs/fixed-point.md; the
/// requirement is 2e-6).
const REL_TOL: f64 = common::FIXED_REL_TOLERANCE;
/// The far-from-the-limb property test keeps this margin (rad); the other goes to 1e-6.
const FAR_MARGIN_RAD: f64 = 1.0e-3;

const CAMERA: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13e-6,
};

#[derive(Clone, Copy, Debug)]
struct Case {
    camera: Camera,
    geometry: Geometry<f64>,
    n_px: f64,
}

/// The reference at exactly the fixed backend's inputs, and the fixed result, in f64.
fn both(c: &Case) -> Result<(ImageMotion<f64>, ImageMotion<f64>), ModelError> {
    let gq = geometry_from_f64(&c.geometry)?;
    let m = FIXED.evaluate(&c.camera, &gq, c.n_px)?;
    let r = Reference.evaluate(&c.camera, &gq.to_f64(), c.n_px)?;
    Ok((motion_to_f64(&m), r))
}

/// (rel. error of |v|, of v1, error of v2 over |v|).
fn errors(m: &ImageMotion<f64>, r: &ImageMotion<f64>) -> (f64, f64, f64) {
    let sp = r.speed_mps();
    (
        (m.speed_mps() - sp).abs() / sp,
        (m.v1_mps - r.v1_mps).abs() / r.v1_mps.abs(),
        (m.v2_mps - r.v2_mps).abs() / sp,
    )
}

/// q^2 = (1 - k sin eta)(1 + k sin eta) in f64.
fn q2(c: &Case) -> f64 {
    let g = &c.geometry;
    let eta = g.roll_rad + libm::atan(c.n_px * c.camera.pixel_m / c.camera.focal_m);
    let s = (1.0 + g.altitude_m / g.earth_radius_m) * libm::sin(eta);
    (1.0 - s) * (1.0 + s)
}

fn tolerance(_c: &Case) -> f64 {
    REL_TOL
}

/// A case in the envelope whose line of sight meets the Earth at least
/// `min_margin_rad` inside the limb (same construction as tests/agreement.rs, with the
/// field angle kept within 40 deg).
fn case(min_margin_rad: f64) -> impl Strategy<Value = Case> {
    (
        200e3..=2000e3f64,
        prop_oneof![Just(6_371e3f64), Just(6_378_137.0f64), 6_350e3..6_390e3f64],
        -45f64..=45.0,
        0f64..180.0,
        0f64..360.0,
        -1f64..1.0,
        0.1f64..2.0,
        5e-6f64..2e-5,
    )
        .prop_filter_map(
            "field angle beyond 40 deg",
            move |(h, r, roll, i0, g0, frac, f, a)| {
                let g =
                    Geometry::circular(roll.to_radians(), i0.to_radians(), g0.to_radians(), h, r);
                let limb = libm::asin(r / (r + h));
                let eta = frac * (limb - min_margin_rad);
                let alpha = eta - g.roll_rad;
                if alpha.abs() > 40f64.to_radians() {
                    return None;
                }
                Some(Case {
                    camera: Camera {
                        focal_m: f,
                        pixel_m: a,
                    },
                    geometry: g,
                    n_px: libm::tan(alpha) * f / a,
                })
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20000, ..ProptestConfig::default() })]

    /// At least 1e-3 rad from the limb (the direct form).
    #[test]
    fn fixed_matches_reference(c in case(FAR_MARGIN_RAD)) {
        let (m, r) = both(&c).unwrap();
        let (ev, e1, e2) = errors(&m, &r);
        let tol = tolerance(&c);
        prop_assert!(ev <= tol && e1 <= tol && e2 <= tol, "{ev:e} {e1:e} {e2:e} > {tol:e} ({c:?})");
    }

    /// Up to 1e-6 rad from the limb (the near-limb form within 9.7e-4 rad): same tolerance.
    #[test]
    fn fixed_matches_reference_near_limb(c in case(1e-6)) {
        let (m, r) = both(&c).unwrap();
        let (ev, e1, e2) = errors(&m, &r);
        let tol = tolerance(&c);
        prop_assert!(ev <= tol && e1 <= tol && e2 <= tol, "{ev:e} {e1:e} {e2:e} > {tol:e} ({c:?})");
    }
}

/// The envelope's corners: altitude 200 and 2000 km, roll -45/0/+45 deg, field
/// -40/0/+40 deg, inclination 0/90/180 deg, argument of latitude 0/90/180/270 deg, each
/// with R = 6 371 km and the two extreme Earth radii, Earth rate +/- its bound and the
/// orbit rate at its circular value and at the bound. Every case either matches the
/// reference or is refused by both as beyond the limb; none may overflow (this test is
/// meant to run in the dev profile, with overflow checks, as well).
#[test]
fn corners_of_the_envelope() {
    let mut checked = 0;
    for h in [200e3, 2000e3] {
        for r in [6_300e3, 6_371e3, 6_400e3] {
            for roll in [-45.0f64, 0.0, 45.0] {
                for field in [-40.0f64, 0.0, 40.0] {
                    for i0 in [0.0f64, 90.0, 180.0] {
                        for g0 in [0.0f64, 90.0, 180.0, 270.0] {
                            for rates in 0..3 {
                                let mut g = Geometry::circular(
                                    roll.to_radians(),
                                    i0.to_radians(),
                                    g0.to_radians(),
                                    h,
                                    r,
                                );
                                match rates {
                                    1 => {
                                        g.earth_rate_rad_s = 1e-4;
                                        g.orbit_rate_rad_s = 2e-3;
                                    }
                                    2 => {
                                        g.earth_rate_rad_s = -1e-4;
                                        g.orbit_rate_rad_s = -2e-3;
                                    }
                                    _ => {}
                                }
                                let n_px =
                                    libm::tan(field.to_radians()) * CAMERA.focal_m / CAMERA.pixel_m;
                                let c = Case {
                                    camera: CAMERA,
                                    geometry: g,
                                    n_px,
                                };
                                let gq = geometry_from_f64(&g).unwrap();
                                let fixed = FIXED.evaluate(&CAMERA, &gq, n_px);
                                let reference = Reference.evaluate(&CAMERA, &gq.to_f64(), n_px);
                                match (fixed, reference) {
                                    (Ok(m), Ok(r)) => {
                                        let (ev, e1, e2) = errors(&motion_to_f64(&m), &r);
                                        let tol = tolerance(&c);
                                        assert!(
                                            ev <= tol && e1 <= tol && e2 <= tol,
                                            "{ev:e} {e1:e} {e2:e} > {tol:e} ({c:?})"
                                        );
                                        checked += 1;
                                    }
                                    (Err(a), Err(b)) => {
                                        assert_eq!(a, ModelError::LineOfSightMissesEarth, "{c:?}");
                                        assert_eq!(b, ModelError::LineOfSightMissesEarth, "{c:?}");
                                    }
                                    (a, b) => panic!("{a:?} vs {b:?} ({c:?})"),
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    println!("{checked} corners evaluated, the others beyond the limb for both");
    assert!(checked > 1000, "{checked}");
}

/// The largest and smallest focal lengths of the envelope, at the nadir and at 40 deg.
#[test]
fn focal_length_extremes() {
    for f in [0.01, 1.0, 1000.0] {
        for field in [-40.0f64, 0.0, 40.0] {
            let camera = Camera {
                focal_m: f,
                pixel_m: 1e-5,
            };
            let n_px = libm::tan(field.to_radians()) * f / camera.pixel_m;
            let g = Geometry::circular(0.3, 1.7, 2.0, 645e3, 6_371e3);
            let c = Case {
                camera,
                geometry: g,
                n_px,
            };
            let (m, r) = both(&c).unwrap();
            let (ev, e1, e2) = errors(&m, &r);
            assert!(
                ev <= REL_TOL && e1 <= REL_TOL && e2 <= REL_TOL,
                "{ev:e} {e1:e} {e2:e} ({c:?})"
            );
        }
    }
}

/// Outside the envelope: a typed error, never a value.
#[test]
fn outside_the_envelope_is_refused() {
    let base = Geometry::circular(0.1, 1.7, 0.5, 645e3, 6_371e3);
    let px = FIXED.pixel(&CAMERA, 0.0).unwrap();
    let refuse = |g: Geometry<f64>, p: Param| {
        let gq = geometry_from_f64(&g).unwrap();
        assert_eq!(FIXED.update(&gq), Err(ModelError::OutOfDomain(p)), "{g:?}");
    };
    let mut g = base;
    g.altitude_m = 199_999.0;
    refuse(g, Param::Altitude);
    g.altitude_m = 2_000_001.0;
    refuse(g, Param::Altitude);
    g.altitude_m = 36_000e3; // beyond I24F40's range itself
    assert_eq!(
        geometry_from_f64(&g),
        Err(ModelError::OutOfDomain(Param::Altitude))
    );
    let mut g = base;
    g.roll_rad = 45.01f64.to_radians();
    refuse(g, Param::Roll);
    g.roll_rad = -45.01f64.to_radians();
    refuse(g, Param::Roll);
    let mut g = base;
    g.earth_radius_m = 3_390e3; // Mars
    refuse(g, Param::EarthRadius);
    let mut g = base;
    g.inclination_rad = 2e5;
    refuse(g, Param::Inclination);
    let mut g = base;
    g.arg_latitude_rad = -2e5;
    refuse(g, Param::ArgLatitude);
    let mut g = base;
    g.earth_rate_rad_s = 2e-4;
    refuse(g, Param::EarthRate);
    let mut g = base;
    g.orbit_rate_rad_s = -3e-3;
    refuse(g, Param::OrbitRate);
    let mut g = base;
    g.altitude_m = 0.0;
    assert_eq!(
        FIXED.update(&geometry_from_f64(&g).unwrap()),
        Err(ModelError::NonPositiveAltitude)
    );
    let mut g = base;
    g.earth_radius_m = -1.0;
    assert_eq!(
        FIXED.update(&geometry_from_f64(&g).unwrap()),
        Err(ModelError::NonPositiveEarthRadius)
    );
    // Field angle beyond 40 deg, focal length below 1 cm.
    let n41 = libm::tan(41f64.to_radians()) * CAMERA.focal_m / CAMERA.pixel_m;
    assert_eq!(
        FIXED.pixel(&CAMERA, n41),
        Err(ModelError::OutOfDomain(Param::PixelOffset))
    );
    let tiny = Camera {
        focal_m: 0.005,
        pixel_m: 1e-6,
    };
    assert_eq!(
        FIXED.pixel(&tiny, 0.0),
        Err(ModelError::OutOfDomain(Param::FocalLength))
    );
    // Inside, the same pixel works.
    let u = FIXED.update(&geometry_from_f64(&base).unwrap()).unwrap();
    assert!(FIXED.motion(&u, &px).is_ok());
}

/// Non-finite inputs: typed errors from pixel() and from the conversion of a geometry.
#[test]
fn non_finite_inputs_are_refused() {
    for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(
            FIXED.pixel(&CAMERA, x),
            Err(ModelError::NonFinite(Param::PixelOffset))
        );
        let bad = Camera {
            focal_m: x,
            pixel_m: 13e-6,
        };
        assert_eq!(
            FIXED.pixel(&bad, 0.0),
            Err(ModelError::NonFinite(Param::FocalLength))
        );
        let bad = Camera {
            focal_m: 0.5,
            pixel_m: x,
        };
        assert_eq!(
            FIXED.pixel(&bad, 0.0),
            Err(ModelError::NonFinite(Param::PixelPitch))
        );
        let mut g = Geometry::circular(0.1, 1.7, 0.5, 645e3, 6_371e3);
        g.roll_rad = x;
        assert_eq!(
            geometry_from_f64(&g),
            Err(ModelError::NonFinite(Param::Roll))
        );
    }
}

/// Beyond the limb and above the horizon: refused like the other backends.
#[test]
fn beyond_the_limb_is_refused() {
    let g = Geometry::circular(45f64.to_radians(), 1.7, 0.5, 2000e3, 6_371e3);
    let n = libm::tan(20f64.to_radians()) * CAMERA.focal_m / CAMERA.pixel_m;
    let gq = geometry_from_f64(&g).unwrap();
    assert_eq!(
        FIXED.evaluate(&CAMERA, &gq, n),
        Err(ModelError::LineOfSightMissesEarth)
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20000, ..ProptestConfig::default() })]

    /// Any I24F40 geometry at all (any bit pattern) and any optics: a value or a typed
    /// error, never a panic (in the dev profile: never an overflow either).
    #[test]
    fn fixed_is_total(
        bits in proptest::collection::vec(any::<i64>(), 7),
        focal in prop_oneof![Just(0.01f64), Just(1000.0), 1e-3f64..2e3],
        n_px in -1e6f64..1e6,
    ) {
        let g = Geometry {
            roll_rad: FixedReal::from_bits(bits[0] >> (bits[1] & 63)),
            inclination_rad: FixedReal::from_bits(bits[1]),
            arg_latitude_rad: FixedReal::from_bits(bits[2]),
            altitude_m: FixedReal::from_bits(bits[3] >> 2),
            earth_radius_m: FixedReal::from_bits(bits[4] >> 1),
            earth_rate_rad_s: FixedReal::from_bits(bits[5] >> 20),
            orbit_rate_rad_s: FixedReal::from_bits(bits[6] >> 20),
        };
        let camera = Camera { focal_m: focal, pixel_m: 1e-5 };
        let _ = FIXED.evaluate(&camera, &g, n_px);
    }

    /// Anywhere inside the envelope, lines of sight included up to the limb and beyond:
    /// a value or `LineOfSightMissesEarth`, never a panic or an overflow.
    #[test]
    fn fixed_is_total_in_the_envelope(
        h in 200e3..=2000e3f64,
        r in 6_300e3..=6_400e3f64,
        roll in -45f64..=45.0,
        field in -40f64..=40.0,
        i0 in -1e5f64..1e5,
        g0 in -1e5f64..1e5,
        w in -1e-4f64..=1e-4,
        om in -2e-3f64..=2e-3,
        focal in prop_oneof![Just(0.01f64), Just(1000.0), 0.01f64..1000.0],
    ) {
        let g = Geometry {
            roll_rad: roll.to_radians(),
            inclination_rad: i0,
            arg_latitude_rad: g0,
            altitude_m: h,
            earth_radius_m: r,
            earth_rate_rad_s: w,
            orbit_rate_rad_s: om,
        };
        let camera = Camera { focal_m: focal, pixel_m: 1e-5 };
        let n_px = libm::tan(field.to_radians()) * focal / camera.pixel_m;
        let gq = geometry_from_f64(&g).unwrap();
        match FIXED.evaluate(&camera, &gq, n_px) {
            Ok(_) | Err(ModelError::LineOfSightMissesEarth) => {}
            Err(e) => prop_assert!(false, "{e:?} ({g:?}, {field})"),
        }
    }
}

/// The error survey of docs/fixed-point.md: the accuracy grid of docs/accuracy.md
/// (altitudes 200-2000 km, inclination and argument of latitude every 15 deg, roll every
/// 1.5 deg, field every 1 deg plus the lines of sight 3 deg to 1e-5 deg short of each
/// limb), restricted to field angles within 40 deg, bucketed by limb margin.
#[test]
#[ignore]
fn error_survey() {
    let buckets = [1.0f64, 0.1, 0.01, 1e-3, 1e-4, 0.0];
    let names = [
        ">= 1 deg",
        "0.1 - 1 deg",
        "0.01 - 0.1 deg",
        "1e-3 - 0.01 deg",
        "1e-4 - 1e-3 deg",
        "< 1e-4 deg",
    ];
    let mut stats = [(0usize, 0f64, 0f64, 0f64, 0f64); 6];
    let near = [3.0, 1.0, 0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5];
    let r = 6_371e3;
    for h in [200e3, 400e3, 645e3, 1000e3, 1500e3, 2000e3] {
        let limb = libm::asin(r / (r + h)).to_degrees();
        for i0 in (0..=12).map(|k| 15.0 * k as f64) {
            for g0 in (0..24).map(|k| 15.0 * k as f64) {
                let g0: f64 = g0;
                for roll in (-30..=30).map(|k| 1.5 * k as f64) {
                    let g = Geometry::circular(
                        roll.to_radians(),
                        i0.to_radians(),
                        g0.to_radians(),
                        h,
                        r,
                    );
                    let mut fields: Vec<f64> = (-40..=40).map(|k| k as f64).collect();
                    for d in near {
                        fields.push(limb - d - roll);
                        fields.push(-(limb - d) - roll);
                    }
                    for field in fields {
                        if field.abs() > 40.0 {
                            continue;
                        }
                        let n_px = libm::tan(field.to_radians()) * CAMERA.focal_m / CAMERA.pixel_m;
                        let c = Case {
                            camera: CAMERA,
                            geometry: g,
                            n_px,
                        };
                        let Ok((m, rf)) = both(&c) else { continue };
                        let margin = limb_margin_rad(&CAMERA, &g, n_px).unwrap().to_degrees();
                        let b = buckets.iter().position(|&t| margin >= t).unwrap_or(5);
                        let (ev, e1, e2) = errors(&m, &rf);
                        let s = &mut stats[b];
                        s.0 += 1;
                        s.1 = s.1.max(ev);
                        s.2 = s.2.max(e1);
                        s.3 = s.3.max(e2);
                        s.4 = s.4.max(ev * libm::sqrt(q2(&c)));
                    }
                }
            }
        }
    }
    println!("| limb margin | cases | max rel err \\|v\\| | max rel err v1 | max err v2/\\|v\\| | max err \\|v\\| x q |");
    println!("|---|---|---|---|---|---|");
    for (name, s) in names.iter().zip(stats) {
        println!(
            "| {name} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} |",
            s.0, s.1, s.2, s.3, s.4
        );
    }
}

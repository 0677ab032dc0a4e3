//! Named stiff and extreme cases, each with its expected behaviour.

use core_math::accuracy::{F32_REL_TOLERANCE, F32_V2_TOLERANCE};
use core_math::{Backend, Camera, Geometry, ModelError, Param, Reference, CLOSED_F32, CLOSED_F64};

const CAM: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13e-6,
};
const R: f64 = 6_370e3;
const H: f64 = 645e3;

fn geo(roll_deg: f64, i0_deg: f64, g0_deg: f64) -> Geometry<f64> {
    Geometry::circular(
        roll_deg.to_radians(),
        i0_deg.to_radians(),
        g0_deg.to_radians(),
        H,
        R,
    )
}

/// The pixel (fractional) whose line of sight is `margin_rad` short of the left limb.
fn pixel_at_margin(g: &Geometry<f64>, margin_rad: f64) -> f64 {
    let limb = libm::asin(g.earth_radius_m / (g.earth_radius_m + g.altitude_m));
    libm::tan(limb - margin_rad - g.roll_rad) * CAM.focal_m / CAM.pixel_m
}

/// f32 and f64 closed forms against the reference, at f32-exact inputs.
fn check_all(g: &Geometry<f64>, n: f64) {
    let g32 = g.to::<f32>();
    let gx = g32.to_f64();
    let r = Reference.evaluate(&CAM, &gx, n).expect("reference");
    let m64 = CLOSED_F64.evaluate(&CAM, &gx, n).expect("f64");
    let m32 = CLOSED_F32.evaluate(&CAM, &g32, n).expect("f32");
    let sp = r.speed_mps();
    let e32 = (m32.speed_mps() as f64 - sp).abs() / sp;
    assert!(
        e32 <= F32_REL_TOLERANCE,
        "f32 |v| rel err {e32:e} at n {n} {g:?}"
    );
    assert!((m32.v2_mps as f64 - r.v2_mps).abs() <= F32_V2_TOLERANCE * sp);
    let e64 = (m64.speed_mps() - sp).abs() / sp;
    // The reference itself is the limit near the limb: ~1e-16 / q^2.
    assert!(e64 <= 1e-9, "f64 |v| rel err {e64:e}");
}

#[test]
fn near_the_limb() {
    let g = geo(25.0, 97.98, 30.0);
    for margin_deg in [1.0, 0.1, 0.01] {
        check_all(&g, pixel_at_margin(&g, f64::to_radians(margin_deg)));
    }
    check_all(&g, pixel_at_margin(&g, 1e-5));
}

#[test]
fn at_and_beyond_the_limb_is_an_error() {
    let g = geo(25.0, 97.98, 30.0);
    let at = pixel_at_margin(&g, 0.0);
    let beyond = pixel_at_margin(&g, -1e-4);
    // The mirror image: rolled right, looking past the right limb.
    let mirror = geo(-25.0, 97.98, 30.0);
    for (g, n) in [(g, beyond), (g, beyond * 1.5), (mirror, -beyond)] {
        assert_eq!(
            Reference.evaluate(&CAM, &g, n),
            Err(ModelError::LineOfSightMissesEarth)
        );
        assert_eq!(
            CLOSED_F64.evaluate(&CAM, &g, n),
            Err(ModelError::LineOfSightMissesEarth)
        );
        assert_eq!(
            CLOSED_F32.evaluate(&CAM, &g.to(), n),
            Err(ModelError::LineOfSightMissesEarth)
        );
        // A hair inside the same limb is accepted by all three.
        let inside = if n > 0.0 {
            pixel_at_margin(&g, 1e-4)
        } else {
            -pixel_at_margin(&geo(25.0, 97.98, 30.0), 1e-4)
        };
        assert!(CLOSED_F32.evaluate(&CAM, &g.to(), inside).is_ok());
        assert!(Reference.evaluate(&CAM, &g, inside).is_ok());
    }
    // Exactly at the limb (to the rounding of its pixel): refused, or, if rounding put the
    // pixel a hair inside, a finite answer. Never NaN.
    let at_limb = [
        Reference.evaluate(&CAM, &g, at).map(|m| m.speed_mps()),
        CLOSED_F64.evaluate(&CAM, &g, at).map(|m| m.speed_mps()),
        CLOSED_F32
            .evaluate(&CAM, &g.to(), at)
            .map(|m| m.speed_mps() as f64),
    ];
    for r in at_limb {
        match r {
            Ok(v) => assert!(v.is_finite() && v > 0.0, "{v}"),
            Err(e) => assert_eq!(e, ModelError::LineOfSightMissesEarth),
        }
    }
    // A ray pointing above the horizontal.
    let up = geo(100.0, 97.98, 30.0);
    assert_eq!(
        CLOSED_F64.evaluate(&CAM, &up, 0.0),
        Err(ModelError::LineOfSightMissesEarth)
    );
    assert_eq!(
        Reference.evaluate(&CAM, &up, 0.0),
        Err(ModelError::LineOfSightMissesEarth)
    );
}

#[test]
fn nadir_with_zero_roll() {
    let g = geo(0.0, 97.98, 30.0);
    check_all(&g, 0.0);
    // g2 = 0 exactly: the ground point is the sub-satellite point.
    let r = Reference::chain(&g, &Reference.pixel(&CAM, 0.0).unwrap()).unwrap();
    assert_eq!(r.g_m[1], 0.0);
}

#[test]
fn equatorial_orbits_have_no_drift_from_the_spin_axis_tilt() {
    // i0 = 0: sin(i0) = 0 exactly, so a = c = 0 and v2 vanishes exactly.
    let g = geo(25.0, 0.0, 40.0);
    let m = CLOSED_F64.evaluate(&CAM, &g, 12_000.0).unwrap();
    assert_eq!(m.v2_mps, 0.0);
    check_all(&g, 12_000.0);
    // i0 = 180 deg: sin(pi) in floating point is 1.2e-16, so v2 is that small, not 0.
    let g = geo(25.0, 180.0, 40.0);
    let m = CLOSED_F64.evaluate(&CAM, &g, 12_000.0).unwrap();
    assert!(m.v2_mps.abs() <= 1e-15 * m.speed_mps());
    check_all(&g, 12_000.0);
}

#[test]
fn arg_latitude_90_and_270() {
    for g0 in [90.0, 270.0] {
        let g = geo(25.0, 97.98, g0);
        let m = CLOSED_F64.evaluate(&CAM, &g, -20_000.0).unwrap();
        assert!(m.v2_mps.abs() <= 1e-15 * m.speed_mps(), "v2 {}", m.v2_mps);
        check_all(&g, -20_000.0);
    }
}

#[test]
fn altitudes_and_rolls_at_the_envelope_edges() {
    for h in [200e3, 2_000e3] {
        for roll in [-45.0f64, 45.0] {
            let g = Geometry::circular(roll.to_radians(), 1.7, 0.3, h, R);
            for n in [-30_000.0, 0.0, 30_000.0] {
                match Reference.evaluate(&CAM, &g, n) {
                    Ok(_) => check_all(&g, n),
                    Err(e) => {
                        assert_eq!(e, ModelError::LineOfSightMissesEarth);
                        assert_eq!(CLOSED_F64.evaluate(&CAM, &g, n), Err(e));
                        assert_eq!(CLOSED_F32.evaluate(&CAM, &g.to(), n), Err(e));
                    }
                }
            }
        }
    }
}

#[test]
fn invalid_inputs_get_their_own_errors() {
    let g = geo(25.0, 97.98, 30.0);
    let bad_cam = Camera {
        focal_m: 0.0,
        ..CAM
    };
    assert_eq!(
        CLOSED_F64.evaluate(&bad_cam, &g, 0.0),
        Err(ModelError::NonPositiveFocalLength)
    );
    let bad_cam = Camera {
        pixel_m: -1.0,
        ..CAM
    };
    assert_eq!(
        CLOSED_F32.evaluate(&bad_cam, &g.to(), 0.0),
        Err(ModelError::NonPositivePixelPitch)
    );
    let low = Geometry {
        altitude_m: 0.0,
        ..g
    };
    assert_eq!(
        CLOSED_F64.evaluate(&CAM, &low, 0.0),
        Err(ModelError::NonPositiveAltitude)
    );
    assert_eq!(
        Reference.evaluate(&CAM, &low, 0.0),
        Err(ModelError::NonPositiveAltitude)
    );
    let nan = Geometry {
        roll_rad: f64::NAN,
        ..g
    };
    assert_eq!(
        CLOSED_F32.evaluate(&CAM, &nan.to(), 0.0),
        Err(ModelError::NonFinite(Param::Roll))
    );
    assert_eq!(
        CLOSED_F64.evaluate(&CAM, &g, f64::INFINITY),
        Err(ModelError::NonFinite(Param::PixelOffset))
    );
    let far = Geometry {
        altitude_m: 1e9,
        ..g
    };
    assert_eq!(
        CLOSED_F64.evaluate(&CAM, &far, 0.0),
        Err(ModelError::OutOfDomain(Param::Altitude))
    );
}

//! Named stiff and extreme cases, one test each, with the behaviour expected of every
//! backend: `Reference` (the golden f64 chain), `CLOSED_F64`, `CLOSED_F32`, `FIXED`
//! (fed through `fixed_point::geometry_from_f64`) and `NaiveF32` (the paper's route in
//! f32). Each backend is compared with the reference evaluated at exactly its own
//! (rounded) inputs, to its documented tolerance (`core_math::accuracy`,
//! docs/fixed-point.md, tests/naive.rs; helpers in `common/mod.rs`), or with an exact
//! physical argument where there is one.
//!
//! | case | test |
//! |---|---|
//! | line of sight 1 deg from the limb | [`limb_margin_1_deg`] |
//! | 0.1 deg from the limb | [`limb_margin_0_1_deg`] |
//! | 0.01 deg from the limb | [`limb_margin_0_01_deg`] |
//! | 1e-5 rad from the limb | [`limb_margin_1e_5_rad`] |
//! | exactly at the limb | [`at_the_limb`] |
//! | just beyond the limb (typed error) | [`just_beyond_the_limb`] |
//! | nadir with zero roll (g2 = 0) | [`nadir_with_zero_roll`] |
//! | equatorial orbit, i0 = 0 (v2 exactly 0) | [`equatorial_orbit`] |
//! | retrograde equatorial orbit, i0 = 180 deg | [`retrograde_equatorial_orbit`] |
//! | gamma0 = 90 and 270 deg | [`arg_latitude_90_and_270_deg`] |
//! | the poles (i0 = 90 deg, gamma0 = 90/270 deg) | [`the_poles`] |
//! | extreme field angles | [`extreme_field_angles`] |
//! | altitudes at both ends | [`altitudes_at_both_ends`] |
//! | roll of +/-45 deg | [`roll_of_plus_minus_45_deg`] |
//! | the fixed-point format's saturation corners | [`fixed_point_saturation_corners`] (and, in tests/fixed_point.rs, `corners_of_the_envelope`, `outside_the_envelope_is_refused`) |
//! | largest and smallest line periods of the tick counter | [`tick_counter_largest_and_smallest_periods`] |
//! | invalid inputs | [`invalid_inputs_get_their_own_errors`] |
//!
//! What a reader might expect and does not hold, each checked exactly below:
//! - "v2 = 0" for i0 = 180 deg and gamma0 = 90/270 deg: the float backends give the v2
//!   of the radian angle they were given (fl(pi) is not pi), sin(i0) or cos(g0) times
//!   a finite v2; `FIXED` gives exactly 0 (the tiny rate rounds to 0 in I7F25);
//! - the reference chain leaves v2 at a few 1e-17 |v_P| for i0 = 0 (its rotations by
//!   gamma0 and back do not cancel exactly in f64), and is itself the less accurate
//!   side at the domain's edges (6 mm altitude: ulp(R + H)/H; |tan alpha| = 1e4:
//!   ~tan(alpha) u);
//! - `F32_V2_TOLERANCE` (1e-7 |v_P|) holds where v2 is small against v1, as on the
//!   accuracy grid; where v2 is the larger component (16 R, |tan alpha| = 1e4) its f32
//!   error reaches ~1.1e-7 |v_P| and the |v_P| bound is used;
//! - exactly at the limb the verdict of a float backend depends on which side its
//!   rounded input falls; `FIXED` refuses the last ~7e-12 rad inside the limb.

mod common;

use common::*;
use core_math::sphere::accuracy::{f64_rel_tolerance, limb_margin_rad, F32_REL_TOLERANCE};
use core_math::sphere::fixed_point::{envelope, geometry_from_f64, motion_to_f64};
use core_math::sphere::{FixedReal, Geometry, NaiveF32, Reference, CLOSED_F32, CLOSED_F64, FIXED};
use core_math::{domain, line_period_ticks, Backend, Camera, ImageMotion, ModelError, Param};

const R: f64 = 6_370e3;
const H: f64 = 645e3;
const I0_DEG: f64 = 97.98;
const G0_DEG: f64 = 30.0;

fn geo(roll_deg: f64, i0_deg: f64, g0_deg: f64) -> Geometry<f64> {
    Geometry::circular(
        roll_deg.to_radians(),
        i0_deg.to_radians(),
        g0_deg.to_radians(),
        H,
        R,
    )
}

// ---------------------------------------------------------------------------------
// Near the limb.

/// (altitude, roll) whose lines of sight near the limb have field angles of 29-36 deg,
/// inside the fixed backend's envelope, so that all five backends take them.
const LIMB_SETUPS: [(f64, f64); 3] = [(645e3, 30.0), (200e3, 45.0), (2_000e3, 20.0)];

/// Every backend at `margin_rad` inside the limb, toward the left limb (roll > 0,
/// positive field angle) and the right one (the mirror image).
fn at_limb_margin(margin_rad: f64) {
    for (h, roll_deg) in LIMB_SETUPS {
        for side in [1.0, -1.0] {
            let g = Geometry::circular(
                side * roll_deg.to_radians(),
                I0_DEG.to_radians(),
                G0_DEG.to_radians(),
                h,
                R,
            );
            let left = Geometry {
                roll_rad: roll_deg.to_radians(),
                ..g
            };
            let n = side * pixel_at_margin(&CAMERA, &left, margin_rad);
            // The construction puts the ray where intended (independent limb formula).
            let m = limb_margin_rad(&CAMERA, &g, n).unwrap();
            assert!(
                (m - margin_rad).abs() <= 1e-9 * margin_rad.max(1e-3),
                "{m} vs {margin_rad}"
            );
            check_all(&CAMERA, &g, n);
        }
    }
}

#[test]
fn limb_margin_1_deg() {
    at_limb_margin(1f64.to_radians());
}

#[test]
fn limb_margin_0_1_deg() {
    at_limb_margin(0.1f64.to_radians());
}

#[test]
fn limb_margin_0_01_deg() {
    at_limb_margin(0.01f64.to_radians());
}

/// 1e-5 rad (5.7e-4 deg): q = cos(incidence) ~ 3e-3. The f32 and fixed backends keep
/// their far-field tolerance (split-precision limb distance); `NaiveF32` is held to
/// its bound for the 1e-4 - 1e-3 deg bucket (1e-3) or refuses (documented).
#[test]
fn limb_margin_1e_5_rad() {
    at_limb_margin(1e-5);
}

/// The 7/8 geometry: R / (R + H) = 6 370 / 7 280 = 7/8 exactly, so the limb's nadir
/// angle is L = asin(7/8); roll 0.5 rad is exact in f32 and I24F40 too. Every backend
/// then sees the same limb, and the distance to it is set by the f64 pixel alone.
const R78: f64 = 6_370_000.0;
const H78: f64 = 910_000.0;
const ROLL78: f64 = 0.5;

/// The pixel `margin_rad` inside the limb (< 0: beyond) on the side `side` (+1 left).
fn pixel78(margin_rad: f64, side: f64) -> (Geometry<f64>, f64) {
    let limb = libm::asin(0.875);
    let g = Geometry::circular(
        side * ROLL78,
        I0_DEG.to_radians(),
        G0_DEG.to_radians(),
        H78,
        R78,
    );
    let n = side * libm::tan(limb - margin_rad - ROLL78) * CAMERA.focal_m / CAMERA.pixel_m;
    (g, n)
}

/// Exactly at the limb (to the ~2e-16 rad of the f64 pixel): the ray is tangent, the
/// model's verdict is `LineOfSightMissesEarth` ("at or beyond the limb"), but which side
/// of the tangent a rounded input falls on is not defined, so a float backend may also
/// answer with a finite speed, never NaN. `FIXED` must refuse: it documents a refusal
/// within about 7e-12 rad of the limb (m = 1 - k|sin eta| below 2^-39). One picoradian
/// either side the verdict is defined for every backend but `NaiveF32`, whose f32
/// resolution there is ~1e-7 rad.
#[test]
fn at_the_limb() {
    for side in [1.0, -1.0] {
        let (g, n) = pixel78(0.0, side);
        for (name, v) in verdicts(&CAMERA, &g, n) {
            match v {
                Ok(speed) => {
                    assert!(name != "FIXED", "FIXED accepted a tangent ray: {speed}");
                    assert!(speed.is_finite() && speed > 0.0, "{name}: {speed}");
                }
                Err(e) => assert_eq!(e, ModelError::LineOfSightMissesEarth, "{name}"),
            }
        }

        // 1e-12 rad inside: a ground point exists (q^2 ~ 1.1e-12).
        let (g, n) = pixel78(1e-12, side);
        check_closed_f64(&CAMERA, &g, n);
        check_closed_f32(&CAMERA, &g, n);
        let gq = geometry_from_f64(&g).unwrap();
        assert_eq!(
            FIXED.evaluate(&CAMERA, &gq, n),
            Err(ModelError::LineOfSightMissesEarth),
            "FIXED refuses within ~7e-12 rad of the limb (docs/fixed-point.md)"
        );
        match NaiveF32.evaluate(&CAMERA, &g.to(), n) {
            Ok(m) => assert!(m.speed_mps().is_finite()),
            Err(e) => assert_eq!(e, ModelError::LineOfSightMissesEarth),
        }

        // 1e-12 rad beyond.
        let (g, n) = pixel78(-1e-12, side);
        for (name, v) in verdicts(&CAMERA, &g, n) {
            match (name, v) {
                ("NaiveF32", Ok(speed)) => assert!(speed.is_finite()),
                (_, v) => assert_eq!(v, Err(ModelError::LineOfSightMissesEarth), "{name}"),
            }
        }
    }
}

/// Beyond the limb: `LineOfSightMissesEarth` from every backend, from 1e-10 rad out
/// (`NaiveF32` from 1e-5 rad out, beyond its f32 resolution; closer in it may answer
/// with a finite value). A ray above the horizontal: the same error from the float
/// backends; `FIXED` refuses its roll (`OutOfDomain(Roll)`, beyond 45 deg).
#[test]
fn just_beyond_the_limb() {
    for side in [1.0, -1.0] {
        for margin in [-1e-10, -1e-7, -1e-5, -1e-4, -1e-2] {
            for (g, n) in [pixel78(margin, side), {
                let g = geo(side * 30.0, I0_DEG, G0_DEG);
                let left = geo(30.0, I0_DEG, G0_DEG);
                (g, side * pixel_at_margin(&CAMERA, &left, margin))
            }] {
                for (name, v) in verdicts(&CAMERA, &g, n) {
                    match (name, v) {
                        ("NaiveF32", Ok(speed)) if margin > -1e-5 => assert!(speed.is_finite()),
                        (_, v) => assert_eq!(
                            v,
                            Err(ModelError::LineOfSightMissesEarth),
                            "{name} at margin {margin} rad, side {side}"
                        ),
                    }
                }
            }
        }
    }
    let up = geo(100.0, I0_DEG, G0_DEG);
    for (name, v) in verdicts(&CAMERA, &up, 0.0) {
        let expect = if name == "FIXED" {
            ModelError::OutOfDomain(Param::Roll)
        } else {
            ModelError::LineOfSightMissesEarth
        };
        assert_eq!(v, Err(expect), "{name}");
    }
}

// ---------------------------------------------------------------------------------
// Nadir, special orbits and arguments of latitude.

/// At nadir (roll 0, pixel 0) the ground point is the sub-satellite point (g2 = g3 = 0
/// in the chain, exactly) and the image moves at f/H times the ground point's velocity
/// relative to the satellite's track: along track R (w cos i0 - Omega), across track
/// -R w sin i0 cos g0 (the Earth's surface velocity seen from the orbit):
/// v1 = f (w cos i0 - Omega) R / H, v2 = -f w sin i0 cos g0 R / H.
/// For a pixel of field angle alpha whose ray is rolled back to the nadir
/// (roll = -alpha) the pinhole projection scales them by sec(alpha) (along track: the
/// depth is H cos alpha) and sec^2(alpha) (along the array: d(f tan alpha)).
fn nadir_physics_sec(g: &Geometry<f64>, camera: &Camera, sec: f64) -> ImageMotion<f64> {
    let scale = camera.focal_m * g.earth_radius_m / g.altitude_m;
    let w = g.earth_rate_rad_s;
    ImageMotion {
        v1_mps: sec * scale * (w * libm::cos(g.inclination_rad) - g.orbit_rate_rad_s),
        v2_mps: -sec
            * sec
            * scale
            * w
            * libm::sin(g.inclination_rad)
            * libm::cos(g.arg_latitude_rad),
    }
}

fn nadir_physics(g: &Geometry<f64>, camera: &Camera) -> ImageMotion<f64> {
    nadir_physics_sec(g, camera, 1.0)
}

#[test]
fn nadir_with_zero_roll() {
    for (i0, g0) in [(I0_DEG, G0_DEG), (51.6, 123.0), (30.0, 0.0), (150.0, 200.0)] {
        let g = geo(0.0, i0, g0);
        let chain = Reference::chain(&g, &Reference.pixel(&CAMERA, 0.0).unwrap()).unwrap();
        assert_eq!(
            chain.g_m,
            [0.0, 0.0, 0.0],
            "g2 = 0: the sub-satellite point"
        );
        let r = chain.motion;
        let p = nadir_physics(&g, &CAMERA);
        assert_close("Reference vs nadir physics", &r, &p, 1e-13, 1e-13, &g);
        check_all(&CAMERA, &g, 0.0);
    }
}

/// i0 = 0: sin(i0) = 0 exactly in every backend's sine (libm `sincos`, `trig::sin_cos_f32`,
/// the fixed binary-angle series, libm `sinf` of 0), so a = w sin i0 cos g0 = 0 and
/// v2 = -(f/cos^2 alpha)(a/c0) q den is exactly 0, for any pixel and g0.
/// The reference is the exception: its chain rotates the ground point by g0 (M2) and
/// back (M6 at t = 0), which in f64 leaves it ~1e-10 m off the orbit plane, and v2 at
/// a few 1e-17 |v_P| (its noise floor: asserted <= 1e-15 |v_P|).
#[test]
fn equatorial_orbit() {
    for g0 in [0.0, 40.0, 90.0, 233.0] {
        for (roll, n) in [(0.0, 0.0), (25.0, 12_000.0), (-40.0, -5_000.0)] {
            let g = geo(roll, 0.0, g0);
            let all = check_all(&CAMERA, &g, n);
            assert_eq!(all.f64.v2_mps, 0.0, "CLOSED_F64");
            assert_eq!(all.f32.v2_mps, 0.0, "CLOSED_F32");
            assert_eq!(all.fixed.v2_mps, 0.0, "FIXED");
            assert_eq!(
                all.naive.expect("far from the limb").v2_mps,
                0.0,
                "NaiveF32"
            );
            let r = all.reference;
            assert!(
                r.v2_mps.abs() <= 1e-15 * r.speed_mps(),
                "Reference v2 {:e}",
                r.v2_mps
            );
        }
    }
}

/// v2 of the geometry `g` with the inclination replaced by 90 deg (sin i0 = 1 exactly
/// in f64), from the reference: v2 is proportional to sin(i0) (through a alone), so
/// the v2 of any inclination is sin(i0) times this.
fn ref_v2_at(g: &Geometry<f64>, n: f64, edit: impl Fn(&mut Geometry<f64>)) -> f64 {
    let mut g = *g;
    edit(&mut g);
    Reference.evaluate(&CAMERA, &g, n).unwrap().v2_mps
}

/// i0 = 180 deg: v2 = 0 exactly in physics, but 180 deg in radians is fl(pi), 1.2e-16
/// short of pi (f32: 8.7e-8 past it). Each float backend gives the v2 of the angle it
/// was given, sin(i0) x v2(i0 = 90 deg), not 0; `FIXED` gives exactly 0: its input is
/// within 2^-41 rad of pi, so |a/c0| < 1e-15 rad/s, which rounds to 0 in I7F25
/// (LSB 2^-35 rad/s). The reference's own noise (~5e-17 |v_P|) swamps the 1e-20 m/s.
#[test]
fn retrograde_equatorial_orbit() {
    let to90 = |g: &mut Geometry<f64>| g.inclination_rad = core::f64::consts::FRAC_PI_2;
    for g0 in [0.0, 40.0, 233.0] {
        for (roll, n) in [(0.0, 0.0), (25.0, 12_000.0)] {
            let g = geo(roll, 180.0, g0);
            let all = check_all(&CAMERA, &g, n);
            let sp = all.reference.speed_mps();
            assert!(all.reference.v2_mps.abs() <= 1e-15 * sp);
            assert_eq!(all.fixed.v2_mps, 0.0, "FIXED");

            let expect64 = libm::sin(g.inclination_rad) * ref_v2_at(&g, n, to90);
            assert!(expect64 != 0.0);
            assert!(
                (all.f64.v2_mps - expect64).abs() <= 1e-12 * expect64.abs(),
                "CLOSED_F64 v2 {:e} vs sin(fl(pi)) v2(90 deg) = {expect64:e}",
                all.f64.v2_mps
            );

            let gx = g.to::<f32>().to_f64();
            let expect32 = libm::sin(gx.inclination_rad) * ref_v2_at(&gx, n, to90);
            let f32_v2 = f64::from(all.f32.v2_mps);
            assert!(
                (f32_v2 - expect32).abs() <= 1e-5 * expect32.abs(),
                "CLOSED_F32 v2 {f32_v2:e} vs sin(fl32(pi)) v2(90 deg) = {expect32:e}"
            );
            let naive_v2 = f64::from(all.naive.unwrap().v2_mps);
            assert!(
                (naive_v2 - expect32).abs() <= 1e-4 * expect32.abs(),
                "NaiveF32 v2 {naive_v2:e} vs {expect32:e}"
            );
        }
    }
}

/// gamma0 = 90 and 270 deg: a = w sin i0 cos g0 = 0 in physics (v2 = 0), and
/// c = w sin i0 sin g0 is at its extreme (the largest Earth-rotation term in v1). As for
/// i0 = 180 deg, the float backends give cos(g0 as given) x v2(g0 = 0) (f64: 6e-17 and
/// -1.8e-16; f32: -4.4e-8 and 1.2e-8) and `FIXED` exactly 0.
#[test]
fn arg_latitude_90_and_270_deg() {
    let to0 = |g: &mut Geometry<f64>| g.arg_latitude_rad = 0.0;
    for g0 in [90.0, 270.0] {
        for (roll, n) in [(0.0, 0.0), (25.0, -20_000.0), (-30.0, 30_000.0)] {
            let g = geo(roll, I0_DEG, g0);
            let all = check_all(&CAMERA, &g, n);
            assert_eq!(all.fixed.v2_mps, 0.0, "FIXED");
            let sp = all.reference.speed_mps();

            let expect64 = libm::cos(g.arg_latitude_rad) * ref_v2_at(&g, n, to0);
            assert!(expect64 != 0.0);
            assert!(
                (all.f64.v2_mps - expect64).abs() <= 1e-12 * expect64.abs(),
                "CLOSED_F64 v2 {:e} vs {expect64:e}",
                all.f64.v2_mps
            );
            assert!((all.reference.v2_mps - expect64).abs() <= 1e-15 * sp);

            let gx = g.to::<f32>().to_f64();
            let expect32 = libm::cos(gx.arg_latitude_rad) * ref_v2_at(&gx, n, to0);
            let f32_v2 = f64::from(all.f32.v2_mps);
            assert!(
                (f32_v2 - expect32).abs() <= 1e-5 * expect32.abs(),
                "CLOSED_F32 v2 {f32_v2:e} vs {expect32:e}"
            );
            let naive_v2 = f64::from(all.naive.unwrap().v2_mps);
            assert!(
                (naive_v2 - expect32).abs() <= 1e-4 * expect32.abs(),
                "NaiveF32 v2 {naive_v2:e} vs {expect32:e}"
            );
        }
    }
}

/// The poles: i0 = 90 deg, gamma0 = 90 deg (north) and 270 deg (south), so the
/// sub-satellite point is on the spin axis, where the Earth's surface does not move:
/// at nadir v1 = -f Omega R / H (plus the f w cos(fl(pi/2)) R / H ~ 1e-20 of the
/// rounded input) and v2 = 0 (to the cos(g0) of the rounded input). Off nadir the
/// ground point moves with the Earth; every backend against the reference.
#[test]
fn the_poles() {
    for g0 in [90.0, 270.0] {
        let g = geo(0.0, 90.0, g0);
        let r = Reference.evaluate(&CAMERA, &g, 0.0).unwrap();
        let p = nadir_physics(&g, &CAMERA);
        assert_close("Reference vs pole physics", &r, &p, 1e-13, 1e-15, &g);
        let pole_v1 = -CAMERA.focal_m * g.orbit_rate_rad_s * R / H;
        assert!((r.v1_mps - pole_v1).abs() <= 1e-13 * pole_v1.abs());
        for roll in [-45.0, -30.0, 0.0, 30.0, 45.0] {
            let g = geo(roll, 90.0, g0);
            for n in [-20_000.0, 0.0, 20_000.0] {
                if Reference.evaluate(&CAMERA, &g, n).is_err() {
                    // Roll 45 deg + field 31.6 deg: beyond the limb (65.2 deg).
                    assert_all_refuse(&CAMERA, &g, n, ModelError::LineOfSightMissesEarth);
                    continue;
                }
                let all = check_all(&CAMERA, &g, n);
                let sp = all.reference.speed_mps();
                assert_eq!(all.fixed.v2_mps, 0.0, "FIXED");
                // |cos(g0)| of the rounded inputs: 1.8e-16 (f64), 4.4e-8 (f32).
                assert!(all.f64.v2_mps.abs() <= 2e-15 * sp);
                assert!(f64::from(all.f32.v2_mps).abs() <= 5e-8 * sp);
                assert!(f64::from(all.naive.unwrap().v2_mps).abs() <= 5e-8 * sp);
            }
        }
    }
}

// ---------------------------------------------------------------------------------
// The edges of the envelope and of the domain.

/// Field angles of +/-40 deg (the fixed backend's and the surveys' limit) for every
/// backend. The domain's own limit |tan alpha| = `domain::MAX_TAN_FIELD` (89.994 deg,
/// the roll turning the ray back toward the Earth) for the float backends:
/// - ray at the nadir (roll = -alpha): the exact pinhole motion (`nadir_physics_sec`);
/// - rays 0.3 rad off the nadir: against the reference. Here the reference is the less
///   accurate of the two: its depth C3 = rho cos(alpha) is a difference of two terms
///   ~1e4 times larger, so it carries ~tan(alpha) u of error (2e-12 and more), for which
///   the f64 comparison allows 1e-14 tan(alpha);
/// - `FIXED` refuses the pixel (`OutOfDomain(PixelOffset)`); `NaiveF32`, outside the
///   envelope its bound covers, has only to stay finite (its error there is a few
///   percent, same cancellation in f32);
/// - one step beyond the limit, every backend refuses the pixel.
#[test]
fn extreme_field_angles() {
    for roll in [-20.0, 0.0, 20.0] {
        let g = geo(roll, I0_DEG, G0_DEG);
        for field in [-40.0, 40.0] {
            check_all(&CAMERA, &g, pixel_at_field_deg(&CAMERA, field));
        }
    }
    let n_max = domain::MAX_TAN_FIELD * CAMERA.focal_m / CAMERA.pixel_m;
    for side in [1.0, -1.0] {
        let n = side * n_max * (1.0 - 1e-12);
        let t = n * CAMERA.pixel_m / CAMERA.focal_m;
        let alpha = libm::atan(t);
        for eta in [0.0, 0.3, -0.3] {
            let g = Geometry::circular(eta - alpha, I0_DEG.to_radians(), G0_DEG.to_radians(), H, R);
            let r = Reference.evaluate(&CAMERA, &g, n).unwrap();
            let m = CLOSED_F64.evaluate(&CAMERA, &g, n).unwrap();
            let tol_ref = 1e-14 * t.abs();
            let tol = f64_rel_tolerance(&CAMERA, &g, n).unwrap().max(tol_ref);
            assert_close("CLOSED_F64", &m, &r, tol, tol, &(eta, n));
            if eta == 0.0 {
                let p = nadir_physics_sec(&g, &CAMERA, libm::sqrt(1.0 + t * t));
                assert_close("CLOSED_F64 vs pinhole", &m, &p, 1e-13, 1e-13, &n);
                assert_close("Reference vs pinhole", &r, &p, tol_ref, tol_ref, &n);
            }
            // v2 (f sec^2 alpha) is here 500 times v1: F32_V2_TOLERANCE, measured where v2
            // is a few percent of |v_P|, does not apply; v2 is held to the |v_P| bound.
            check_closed_f32_v2(&CAMERA, &g, n, F32_REL_TOLERANCE);
            let gq = geometry_from_f64(&g).unwrap();
            assert_eq!(
                FIXED.evaluate(&CAMERA, &gq, n),
                Err(ModelError::OutOfDomain(Param::PixelOffset))
            );
            let m = NaiveF32.evaluate(&CAMERA, &g.to(), n).unwrap();
            assert!(m.v1_mps.is_finite() && m.v2_mps.is_finite());
        }
        let g = geo(0.0, I0_DEG, G0_DEG);
        assert_all_refuse(
            &CAMERA,
            &g,
            side * n_max * (1.0 + 1e-12),
            ModelError::OutOfDomain(Param::PixelOffset),
        );
    }
}

/// Altitudes at the ends of the fixed envelope (200 and 2 000 km): every backend, nadir
/// and rolled. At the ends of the model's domain (H = 1e-9 R, 6 mm, and H = 16 R,
/// beyond GEO): the float backends at nadir against the exact nadir motion (the
/// reference's law-of-sines route is itself ill-conditioned off nadir at 6 mm), rolled
/// ones against the reference at 16 R; `FIXED` refuses both (`OutOfDomain(Altitude)`).
/// Just beyond either end: `OutOfDomain(Altitude)` from every backend.
#[test]
fn altitudes_at_both_ends() {
    for h in [200e3, 2_000e3] {
        for roll in [-30.0f64, 0.0, 30.0] {
            let g = Geometry::circular(roll.to_radians(), 1.7, 0.3, h, R);
            for field in [-30.0, 0.0, 30.0] {
                let n = pixel_at_field_deg(&CAMERA, field);
                if Reference.evaluate(&CAMERA, &g, n).is_ok() {
                    check_all(&CAMERA, &g, n);
                } else {
                    assert_all_refuse(&CAMERA, &g, n, ModelError::LineOfSightMissesEarth);
                }
            }
        }
    }
    let lo = domain::MIN_ALTITUDE_OVER_RADIUS * R;
    let hi = domain::MAX_ALTITUDE_OVER_RADIUS * R;
    for h in [lo * (1.0 + 1e-6), hi * (1.0 - 1e-6)] {
        let g = Geometry::circular(0.0, 1.7, 0.3, h, R);
        let p = nadir_physics(&g, &CAMERA);
        let r = Reference.evaluate(&CAMERA, &g, 0.0).unwrap();
        // The reference translates by R and back by -(R + H): H comes back with the
        // rounding of R + H, ulp(R + H) / H = 1.5e-7 relative at 6 mm.
        let ulp = f64::from_bits((R + h).to_bits() + 1) - (R + h);
        let tol = 1e-12 + 2.0 * ulp / h;
        assert_close("Reference at nadir", &r, &p, tol, tol, &h);
        let m = CLOSED_F64.evaluate(&CAMERA, &g, 0.0).unwrap();
        assert_close("CLOSED_F64 at nadir", &m, &p, 1e-12, 1e-12, &h);
        let g32 = g.to::<f32>();
        let m = CLOSED_F32.evaluate(&CAMERA, &g32, 0.0).unwrap();
        let p32 = nadir_physics(&g32.to_f64(), &CAMERA);
        assert_close(
            "CLOSED_F32 at nadir",
            &widen(&m),
            &p32,
            F32_REL_TOLERANCE,
            // Outside the grid F32_V2_TOLERANCE was measured on (200-2 000 km) v2 is not
            // small against v1 (at 16 R it is the larger): the |v_P| bound applies to it.
            F32_REL_TOLERANCE,
            &h,
        );
        let gq = geometry_from_f64(&g);
        assert_eq!(
            gq.and_then(|gq| FIXED.update(&gq)).map(|_| ()),
            Err(ModelError::OutOfDomain(Param::Altitude))
        );
    }
    // At 16 R the Earth subtends +/-3.4 deg. The orbit rate (1.8e-5 rad/s) is below the
    // Earth's, and v2 is larger than v1: held to the |v_P| bound (see the f32 check above).
    let g = Geometry::circular(2f64.to_radians(), 1.7, 0.3, hi * (1.0 - 1e-6), R);
    for field in [-1.0, 0.0, 1.0] {
        let n = pixel_at_field_deg(&CAMERA, field);
        check_closed_f64(&CAMERA, &g, n);
        check_closed_f32_v2(&CAMERA, &g, n, F32_REL_TOLERANCE);
    }
    for h in [lo * (1.0 - 1e-6), hi * (1.0 + 1e-6)] {
        let g = Geometry::circular(0.0, 1.7, 0.3, h, R);
        assert_all_refuse(&CAMERA, &g, 0.0, ModelError::OutOfDomain(Param::Altitude));
    }
}

/// Roll +/-45 deg (the fixed envelope's limit) at both altitude ends and 645 km, field
/// -40 to 40 deg: every backend against the reference where the ray meets the Earth,
/// `LineOfSightMissesEarth` from all where it does not (roll + field beyond the limb).
/// Beyond 45 deg the float backends carry on (their domain is any roll), `FIXED`
/// refuses (`OutOfDomain(Roll)`; its exact bound is in `fixed_point_saturation_corners`).
#[test]
fn roll_of_plus_minus_45_deg() {
    let mut met = 0;
    for h in [200e3, 645e3, 2_000e3] {
        for roll in [-45.0f64, 45.0] {
            let g = Geometry::circular(roll.to_radians(), 1.7, 0.3, h, R);
            for field in (-4..=4).map(|k| 10.0 * k as f64) {
                let n = pixel_at_field_deg(&CAMERA, field);
                if Reference.evaluate(&CAMERA, &g, n).is_ok() {
                    check_all(&CAMERA, &g, n);
                    met += 1;
                } else {
                    assert_all_refuse(&CAMERA, &g, n, ModelError::LineOfSightMissesEarth);
                }
            }
        }
    }
    assert!(met >= 30, "{met}");
    let g = geo(46.0, I0_DEG, G0_DEG);
    check_floats(&CAMERA, &g, 0.0);
    assert_eq!(
        FIXED.update(&geometry_from_f64(&g).unwrap()),
        Err(ModelError::OutOfDomain(Param::Roll))
    );
}

// ---------------------------------------------------------------------------------
// The fixed-point format.

/// The corners of the fixed backend's format. `corners_of_the_envelope`
/// (tests/fixed_point.rs) evaluates the 1 944 envelope corners (altitude 200/2 000 km,
/// R, roll -45/0/45 deg, field -40/0/40 deg, i0, g0, the rates at their bounds, which
/// include the tightest containers, b/c0 and the v1 bracket) against the reference, and
/// `outside_the_envelope_is_refused` a value some way outside each bound. Here, to the
/// bit: every bound of `fixed_point::envelope` taken exactly (evaluated, within
/// tolerance of the reference or refused as beyond the limb by both) and one I24F40 LSB
/// beyond (`OutOfDomain` of that input, never a wrapped value); I24F40::MIN and MAX in
/// every field; the conversion at +/-2^23; the field-angle and focal-length bounds; and
/// the saturated cosines (roll 0, field 0) at both altitude ends. In the dev profile
/// (`cargo test`) every overflow in `update` and `motion` would panic.
#[test]
fn fixed_point_saturation_corners() {
    type Fx = FixedReal;
    let lsb = Fx::DELTA;
    let base = geometry_from_f64(&Geometry::circular(0.3, 1.7, 0.5, 645e3, 6_371e3)).unwrap();
    let (h_lo, h_hi) = envelope::ALTITUDE_M;
    let (r_lo, r_hi) = envelope::EARTH_RADIUS_M;
    let roll = envelope::MAX_ROLL_RAD;
    let ang = envelope::MAX_ANGLE_RAD;
    let w = envelope::MAX_EARTH_RATE_RAD_S;
    let om = envelope::MAX_ORBIT_RATE_RAD_S;
    type Set = fn(&mut Geometry<Fx>, Fx);
    let fields: [(Param, Set, Fx, Fx); 7] = [
        (Param::Roll, |g, x| g.roll_rad = x, -roll, roll),
        (Param::Inclination, |g, x| g.inclination_rad = x, -ang, ang),
        (Param::ArgLatitude, |g, x| g.arg_latitude_rad = x, -ang, ang),
        (Param::Altitude, |g, x| g.altitude_m = x, h_lo, h_hi),
        (Param::EarthRadius, |g, x| g.earth_radius_m = x, r_lo, r_hi),
        (Param::EarthRate, |g, x| g.earth_rate_rad_s = x, -w, w),
        (Param::OrbitRate, |g, x| g.orbit_rate_rad_s = x, -om, om),
    ];
    let pixels = [-40.0, 0.0, 40.0].map(|d| pixel_at_field_deg(&CAMERA, d));
    let mut evaluated = 0;
    for (param, set, lo, hi) in fields {
        for (edge, beyond) in [(lo, lo - lsb), (hi, hi + lsb)] {
            let mut g = base;
            set(&mut g, edge);
            for n in pixels {
                let fixed = FIXED.evaluate(&CAMERA, &g, n).map(|m| motion_to_f64(&m));
                match (fixed, Reference.evaluate(&CAMERA, &g.to_f64(), n)) {
                    (Ok(m), Ok(r)) => {
                        let tol = FIXED_REL_TOLERANCE;
                        assert_close("FIXED at its bound", &m, &r, tol, tol, &(param, edge, n));
                        evaluated += 1;
                    }
                    (Err(a), Err(b)) => {
                        assert_eq!(a, ModelError::LineOfSightMissesEarth, "{param:?} {edge}");
                        assert_eq!(b, ModelError::LineOfSightMissesEarth);
                    }
                    (a, b) => panic!("{param:?} = {edge}: FIXED {a:?}, reference {b:?}"),
                }
            }
            set(&mut g, beyond);
            assert_eq!(
                FIXED.update(&g),
                Err(ModelError::OutOfDomain(param)),
                "{param:?} = {beyond} (one LSB beyond {edge})"
            );
        }
        // The format's own extremes.
        for x in [Fx::MIN, Fx::MAX] {
            let mut g = base;
            set(&mut g, x);
            let expect = match (param, x < 0) {
                (Param::Altitude, true) => ModelError::NonPositiveAltitude,
                (Param::EarthRadius, true) => ModelError::NonPositiveEarthRadius,
                _ => ModelError::OutOfDomain(param),
            };
            assert_eq!(FIXED.update(&g), Err(expect), "{param:?} = {x}");
        }
    }
    assert!(evaluated >= 30, "{evaluated}");

    // f64 -> I24F40 at the format's range: 2^23 does not fit (refused, not wrapped to
    // -2^23), -2^23 is I24F40::MIN itself.
    let g = Geometry::circular(0.3, 1.7, 0.5, 645e3, 6_371e3);
    type SetF = fn(&mut Geometry<f64>, f64);
    let conv: [(Param, SetF, ModelError); 3] = [
        (
            Param::Roll,
            |g, x| g.roll_rad = x,
            ModelError::OutOfDomain(Param::Roll),
        ),
        (
            Param::Altitude,
            |g, x| g.altitude_m = x,
            ModelError::NonPositiveAltitude,
        ),
        (
            Param::OrbitRate,
            |g, x| g.orbit_rate_rad_s = x,
            ModelError::OutOfDomain(Param::OrbitRate),
        ),
    ];
    for (param, set, at_min) in conv {
        let two23 = 8_388_608.0;
        let mut gg = g;
        set(&mut gg, two23);
        assert_eq!(geometry_from_f64(&gg), Err(ModelError::OutOfDomain(param)));
        set(&mut gg, -two23);
        let gq = geometry_from_f64(&gg).unwrap();
        assert_eq!(FIXED.update(&gq), Err(at_min), "{param:?} = -2^23");
    }

    // The field-angle bound (at boot, in f64) and the smallest focal length.
    let n_at = |alpha: f64| libm::tan(alpha) * CAMERA.focal_m / CAMERA.pixel_m;
    for side in [1.0, -1.0] {
        assert!(FIXED
            .pixel(&CAMERA, side * n_at(envelope::MAX_FIELD_RAD - 1e-12))
            .is_ok());
        assert_eq!(
            FIXED.pixel(&CAMERA, side * n_at(envelope::MAX_FIELD_RAD + 1e-12)),
            Err(ModelError::OutOfDomain(Param::PixelOffset))
        );
    }
    let small = |focal_m: f64| Camera {
        focal_m,
        pixel_m: 1e-6,
    };
    assert!(FIXED.pixel(&small(envelope::MIN_FOCAL_M), 100.0).is_ok());
    assert_eq!(
        FIXED.pixel(&small(envelope::MIN_FOCAL_M * (1.0 - 1e-15)), 100.0),
        Err(ModelError::OutOfDomain(Param::FocalLength))
    );

    // cos(roll) and cos(alpha) of exactly 1 saturate to 1 - 2^-31 (documented cost
    // 2^-31): nadir at both altitude ends, against the reference.
    for h in [200e3, 2_000e3] {
        check_fixed(&CAMERA, &Geometry::circular(0.0, 1.7, 0.3, h, R), 0.0);
    }
}

// ---------------------------------------------------------------------------------
// The tick counter.

/// Expected tick count of the exact product x = num / 2^k (round half up, by integer
/// arithmetic), if it fits the u32 counter and is at least 1.
fn ticks_of(num: u128, k: u32) -> Option<u32> {
    let t = (2 * num + (1u128 << k)) >> (k + 1);
    u32::try_from(t).ok().filter(|&t| t >= 1)
}

/// The counter holds 1 to u32::MAX ticks; `line_period_ticks` rounds period x clock to
/// the nearest tick (halves up) and refuses anything outside (`LinePeriodOutOfRange`).
/// With a 2^24 Hz clock every period below is exact, and so is period x clock, so the
/// expected count (and the rounding error) comes from integers: the largest count, the
/// last product that still rounds to it, the first that rounds past it, one tick
/// beyond; the smallest count, the half tick that rounds up to it, the largest product
/// below half a tick (0 ticks), and for f32 the largest count it can represent (2^32 -
/// 256) and an odd count above 2^23 (where x + 0.5 is not representable).
#[test]
fn tick_counter_largest_and_smallest_periods() {
    const K: u32 = 24; // clock 2^24 Hz; x = num / 2^K ticks.
    let clock = (1u64 << K) as f64;
    let x = |ticks_num: u128, frac_num: u128, frac_k: u32| -> (u128, u32) {
        // ticks_num + frac_num / 2^frac_k, as one numerator over 2^frac_k.
        ((ticks_num << frac_k) + frac_num, frac_k)
    };
    let max = u128::from(u32::MAX);
    let cases64: [(u128, u32); 9] = [
        x(max, 0, 0),              // u32::MAX ticks exactly
        x(max, (1 << 20) - 1, 21), // u32::MAX + 1/2 - 2^-21: still u32::MAX
        x(max, 1, 1),              // u32::MAX + 1/2: rounds to 2^32, refused
        x(max + 1, 0, 0),          // 2^32: one beyond
        x(1, 0, 0),                // one tick
        x(0, 1, 1),                // half a tick: rounds up to 1
        x(0, (1 << 53) - 1, 54),   // largest f64 below 1/2: 0 ticks
        x(0, 1, 2),                // a quarter tick
        x((1 << 23) + 1, 0, 0),    // an odd count above 2^23
    ];
    for (num, k) in cases64 {
        let period = num as f64 / 2f64.powi((k + K) as i32);
        assert_eq!(period * clock * 2f64.powi(k as i32), num as f64, "exact");
        let got = line_period_ticks(period, clock);
        match ticks_of(num, k) {
            Some(t) => {
                let got = got.unwrap_or_else(|e| panic!("{num}/2^{k}: {e:?}"));
                assert_eq!(got.ticks, t, "{num}/2^{k}");
                let err = ((u128::from(t) << k) as f64 - num as f64) / 2f64.powi(k as i32) / clock;
                assert_eq!(got.rounding_error_s, err, "{num}/2^{k}");
            }
            None => assert_eq!(got, Err(ModelError::LinePeriodOutOfRange), "{num}/2^{k}"),
        }
    }
    // f32: 24-bit significands. 2^32 - 256 is the largest count below 2^32 it can hold.
    let clock32 = clock as f32;
    let cases32: [(u128, u32); 7] = [
        x((1 << 32) - 256, 0, 0),
        x(1 << 32, 0, 0),
        x(1, 0, 0),
        x(0, 1, 1),
        x(0, (1 << 24) - 1, 25), // largest f32 below 1/2
        x((1 << 23) + 1, 0, 0),
        x((1 << 23) - 1, 1, 1), // 2^23 - 1/2: rounds up to 2^23
    ];
    for (num, k) in cases32 {
        let period = (num as f64 / 2f64.powi((k + K) as i32)) as f32;
        assert_eq!(
            f64::from(period) * clock * 2f64.powi(k as i32),
            num as f64,
            "exact in f32"
        );
        let got = line_period_ticks(period, clock32);
        match ticks_of(num, k) {
            Some(t) => {
                let got = got.unwrap_or_else(|e| panic!("f32 {num}/2^{k}: {e:?}"));
                assert_eq!(got.ticks, t, "f32 {num}/2^{k}");
                let err = ((u128::from(t) << k) as f64 - num as f64) / 2f64.powi(k as i32) / clock;
                assert_eq!(f64::from(got.rounding_error_s), err, "f32 {num}/2^{k}");
            }
            None => assert_eq!(
                got,
                Err(ModelError::LinePeriodOutOfRange),
                "f32 {num}/2^{k}"
            ),
        }
    }
}

// ---------------------------------------------------------------------------------

#[test]
fn invalid_inputs_get_their_own_errors() {
    let g = geo(25.0, 97.98, 30.0);
    let bad_cam = Camera {
        focal_m: 0.0,
        ..CAMERA
    };
    assert_eq!(
        CLOSED_F64.evaluate(&bad_cam, &g, 0.0),
        Err(ModelError::NonPositiveFocalLength)
    );
    let bad_cam = Camera {
        pixel_m: -1.0,
        ..CAMERA
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
        CLOSED_F64.evaluate(&CAMERA, &low, 0.0),
        Err(ModelError::NonPositiveAltitude)
    );
    assert_eq!(
        Reference.evaluate(&CAMERA, &low, 0.0),
        Err(ModelError::NonPositiveAltitude)
    );
    let nan = Geometry {
        roll_rad: f64::NAN,
        ..g
    };
    assert_eq!(
        CLOSED_F32.evaluate(&CAMERA, &nan.to(), 0.0),
        Err(ModelError::NonFinite(Param::Roll))
    );
    assert_eq!(
        CLOSED_F64.evaluate(&CAMERA, &g, f64::INFINITY),
        Err(ModelError::NonFinite(Param::PixelOffset))
    );
    let far = Geometry {
        altitude_m: 1e9,
        ..g
    };
    assert_eq!(
        CLOSED_F64.evaluate(&CAMERA, &far, 0.0),
        Err(ModelError::OutOfDomain(Param::Altitude))
    );
}

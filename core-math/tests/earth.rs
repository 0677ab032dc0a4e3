//! The real-Earth model: the general form (f64, f32) against the construction on dual
//! numbers (`EarthReference`) over the envelope, its reduction to the round-Earth closed
//! form, and the typed errors of `shared/EARTH-MODEL.md` on every backend.

use core_math::accuracy::{
    earth_kappa, EARTH_F32_KAPPA_C, EARTH_F32_KAPPA_LIMIT, EARTH_F32_NEAR_LIMB_TOLERANCE,
    EARTH_F32_REL_TOLERANCE, EARTH_F64_REL_TOLERANCE,
};
use core_math::earth::{limb_margin_rad, Attitude, EarthCamera, EarthGeometry};
use core_math::sample::{EarthCase, SplitMix64};
use core_math::sphere::accuracy::f64_rel_tolerance;
use core_math::sphere::CLOSED_F64;
use core_math::{
    Backend, Camera, Earth, EarthReference, Ellipsoid, ImageMotion, ModelError, Param, StateVector,
    GENERAL_F32, GENERAL_F64,
};

/// Draws of the envelope per test (about 0.1 s of evaluation each).
const DRAWS: usize = 50_000;
const U32: f64 = f32::EPSILON as f64 / 2.0;

/// |dv| / |v|: hypot of the component differences over the reference's |v_P|.
fn rel(m: &ImageMotion<f64>, r: &ImageMotion<f64>) -> f64 {
    libm::hypot(m.v1_mps - r.v1_mps, m.v2_mps - r.v2_mps) / libm::hypot(r.v1_mps, r.v2_mps)
}

fn f32_eval(c: &EarthCase) -> Result<ImageMotion<f64>, ModelError> {
    GENERAL_F32
        .evaluate(&c.camera, &c.geometry.to::<f32>(), c.n_px)
        .map(|m| ImageMotion {
            v1_mps: m.v1_mps as f64,
            v2_mps: m.v2_mps as f64,
        })
}

fn margin_deg(c: &EarthCase) -> f64 {
    limb_margin_rad(&c.geometry, &c.camera, c.n_px)
        .unwrap()
        .to_degrees()
}

/// Within this margin of the limb (deg) a backend may report a hit or a miss
/// (EARTH-MODEL.md).
const EITHER_DEG: f64 = 1e-4;

/// Every draw: the three backends agree on hit or miss (beyond 1e-4 deg from the limb),
/// and where they hit, the general f64 form is within 1e-12 of the reference. The draws
/// cover the whole envelope (`SplitMix64::earth_case`), 0.001 deg to the limb included.
#[test]
fn general_f64_matches_the_reference() {
    let mut rng = SplitMix64(0x0EA7_2026_1124_0064);
    let (mut hits, mut misses, mut worst) = (0, 0, 0f64);
    for _ in 0..DRAWS {
        let Some(c) = rng.earth_case() else { continue };
        let m = margin_deg(&c);
        let r = EarthReference.evaluate(&c.camera, &c.geometry, c.n_px);
        let g = GENERAL_F64.evaluate(&c.camera, &c.geometry, c.n_px);
        let s = f32_eval(&c);
        match (r, g) {
            (Ok(r), Ok(g)) => {
                let e = rel(&g, &r);
                assert!(e <= EARTH_F64_REL_TOLERANCE, "{e:e} at {c:?}");
                assert!(s.is_ok() || m.abs() < EITHER_DEG, "f32 {s:?} at {c:?}");
                worst = worst.max(e);
                hits += 1;
            }
            (Err(ModelError::LineOfSightMissesEarth), Err(ModelError::LineOfSightMissesEarth)) => {
                assert!(
                    s == Err(ModelError::LineOfSightMissesEarth) || m.abs() < EITHER_DEG,
                    "f32 {s:?} at {c:?}"
                );
                assert!(m < EITHER_DEG, "a miss {m} deg inside the limb: {c:?}");
                misses += 1;
            }
            (r, g) => {
                assert!(m.abs() < EITHER_DEG, "{r:?} / {g:?} at {m} deg: {c:?}")
            }
        }
    }
    println!("general f64 vs reference: {hits} hits, {misses} misses, worst {worst:.2e}");
    assert!(hits > 30_000 && misses > 1_000);
}

/// The f32 form against the reference at the inputs as given (the attitude's rounding to
/// f32 counts): err <= C kappa u32 at least 0.01 deg inside the limb, kappa the problem's
/// condition number; and where kappa <= 30, within 2e-6 from 1 deg inside the limb and
/// 2e-5 from 0.01 deg (see `core_math::accuracy`).
#[test]
fn general_f32_matches_the_reference() {
    let mut rng = SplitMix64(0x0EA7_2026_1124_0032);
    let (mut far, mut near, mut ratio) = (0f64, 0f64, 0f64);
    let (mut n_far, mut n_near, mut n_stiff) = (0, 0, 0);
    for _ in 0..20_000 {
        let Some(c) = rng.earth_case() else { continue };
        let m = margin_deg(&c);
        let (Ok(r), Ok(s)) = (
            EarthReference.evaluate(&c.camera, &c.geometry, c.n_px),
            f32_eval(&c),
        ) else {
            continue;
        };
        if m < 0.01 {
            continue;
        }
        let e = rel(&s, &r);
        let kappa = earth_kappa(&c.camera, &c.geometry, c.n_px).unwrap();
        assert!(
            e <= EARTH_F32_KAPPA_C * kappa * U32,
            "{e:e}, kappa {kappa}: {c:?}"
        );
        ratio = ratio.max(e / (kappa * U32));
        if kappa > EARTH_F32_KAPPA_LIMIT {
            n_stiff += 1;
        } else if m >= 1.0 {
            assert!(e <= EARTH_F32_REL_TOLERANCE, "{e:e}: {c:?}");
            far = far.max(e);
            n_far += 1;
        } else {
            assert!(e <= EARTH_F32_NEAR_LIMB_TOLERANCE, "{e:e}: {c:?}");
            near = near.max(e);
            n_near += 1;
        }
    }
    println!(
        "general f32 vs reference: kappa <= {EARTH_F32_KAPPA_LIMIT}: >= 1 deg {n_far} cases, \
         worst {far:.2e}; 0.01-1 deg {n_near}, worst {near:.2e}; kappa > \
         {EARTH_F32_KAPPA_LIMIT}: {n_stiff} cases; worst err/(kappa u) {ratio:.2}"
    );
    assert!(n_far > 10_000 && n_near > 500 && n_stiff > 100);
    // The bounds are not vacuous: the errors reach a fair part of them.
    assert!(far > 0.3 * EARTH_F32_REL_TOLERANCE && ratio > 0.3 * EARTH_F32_KAPPA_C);
}

/// With flattening 0, height 0, a circular orbit and no pitch, yaw or rates, the general
/// form is the round-Earth closed form (to 1e-12 in f64) over the round-Earth envelope,
/// the near-limb draws included (down to 1e-5 deg from the limb).
#[test]
fn general_reduces_to_the_round_earth_closed_form() {
    let mut rng = SplitMix64(0x0EA7_2026_1124_5EC7);
    let camera = Camera {
        focal_m: 0.555,
        pixel_m: 13e-6,
    };
    let earth_camera = EarthCamera {
        focal_m: camera.focal_m,
        pixel_m: camera.pixel_m,
        p1_m: 0.0,
    };
    let (mut n, mut worst, mut widened) = (0, 0f64, 0);
    for _ in 0..20_000 {
        // The sampler rounds every field to f32; the orbit rate must be the circular one
        // of the rounded altitude for the two models to describe the same orbit.
        let r = rng.envelope_geometry();
        let g = core_math::sphere::Geometry {
            orbit_rate_rad_s: core_math::sphere::orbital_rate_rad_s(r.earth_radius_m, r.altitude_m),
            ..r
        };
        let Some(n_px) = rng.envelope_pixel(&g, &camera) else {
            continue;
        };
        let sphere = CLOSED_F64.evaluate(&camera, &g, n_px);
        let general = GENERAL_F64.evaluate(&earth_camera, &g.to_earth(), n_px);
        match (sphere, general) {
            (Ok(s), Ok(e)) => {
                let d = rel(&e, &s);
                // 1e-12, widened within ~0.01 deg of the limb by the conditioning of the
                // ray/sphere intersection there (the tolerance the round-Earth forms
                // already meet against their reference, `core_math::accuracy`).
                let tol = f64_rel_tolerance(&camera, &g, n_px).unwrap();
                assert!(d <= tol, "{d:e} > {tol:e}: {g:?} {n_px}");
                if tol > 1e-12 {
                    widened += 1;
                }
                worst = worst.max(d);
                n += 1;
            }
            // The sampler can put a ray past the limb; both must then refuse it alike.
            (Err(s), Err(e)) if s == e => {}
            (s, e) => panic!("{s:?} / {e:?}: {g:?} {n_px}"),
        }
    }
    println!(
        "general vs round-Earth closed form: {n} cases ({widened} with the near-limb \
         widening), worst {worst:.2e}"
    );
    assert!(n > 15_000);
}

/// The reference puts the ground point back onto the pixel it was found from.
#[test]
fn reference_projects_the_ground_point_onto_its_pixel() {
    let mut rng = SplitMix64(0x0EA7_2026_1124_0001);
    let mut n = 0;
    for _ in 0..5_000 {
        let Some(c) = rng.earth_case() else { continue };
        let p = EarthReference.pixel(&c.camera, c.n_px).unwrap();
        let Ok(chain) = EarthReference::chain(&c.geometry, &p) else {
            continue;
        };
        let tol = 1e-11 * c.camera.focal_m;
        assert!((chain.p_m[0] - p.p1_m).abs() < tol && (chain.p_m[1] - p.p2_m).abs() < tol);
        n += 1;
    }
    assert!(n > 3_000);
}

fn default_case() -> (EarthCamera, EarthGeometry<f64>) {
    let camera = EarthCamera {
        focal_m: 0.555,
        pixel_m: 13e-6,
        p1_m: 0.0,
    };
    let geometry = EarthGeometry {
        state: core_math::earth::circular_state(7_016e3, 97.98f64.to_radians(), 0.6),
        attitude: Attitude {
            roll_rad: 0.3,
            pitch_rad: -0.2,
            yaw_rad: 0.1,
            roll_rate_rad_s: 0.01,
            pitch_rate_rad_s: -0.01,
            yaw_rate_rad_s: 0.001,
        },
        ground_h_m: 1_000.0,
        ellipsoid: Ellipsoid::WGS84,
        earth_rate_rad_s: core_math::EARTH_RATE_RAD_S,
    };
    (camera, geometry)
}

/// Each row of EARTH-MODEL.md's error table gives its error on every backend.
#[test]
fn every_bad_input_gives_its_typed_error_on_every_backend() {
    let (cam, geo) = default_case();
    let all = |cam: &EarthCamera, g: &EarthGeometry<f64>, n: f64| {
        [
            EarthReference.evaluate(cam, g, n).err(),
            GENERAL_F64.evaluate(cam, g, n).err(),
            GENERAL_F32.evaluate(cam, &g.to::<f32>(), n).err(),
        ]
    };
    let expect = |cam: &EarthCamera, g: &EarthGeometry<f64>, n: f64, e: ModelError| {
        for got in all(cam, g, n) {
            assert_eq!(got, Some(e), "{cam:?} {g:?} {n}");
        }
    };
    // The good case first: no error anywhere.
    assert_eq!(all(&cam, &geo, 1234.5), [None; 3]);

    let mut g = geo;
    g.state.position_m[1] = f64::NAN;
    expect(&cam, &g, 0.0, ModelError::NonFinite(Param::Position));
    let mut g = geo;
    g.attitude.yaw_rate_rad_s = f64::INFINITY;
    expect(&cam, &g, 0.0, ModelError::NonFinite(Param::YawRate));
    expect(
        &cam,
        &geo,
        f64::NAN,
        ModelError::NonFinite(Param::PixelOffset),
    );
    let mut g = geo;
    g.ground_h_m = f64::NAN;
    expect(&cam, &g, 0.0, ModelError::NonFinite(Param::GroundHeight));

    for (f, p) in [(0.0, Param::FocalLength), (-1.0, Param::FocalLength)] {
        expect(
            &EarthCamera { focal_m: f, ..cam },
            &geo,
            0.0,
            ModelError::InvalidInput(p),
        );
    }
    let no_pixel = EarthCamera {
        pixel_m: 0.0,
        ..cam
    };
    expect(
        &no_pixel,
        &geo,
        0.0,
        ModelError::InvalidInput(Param::PixelPitch),
    );
    for (a, fl, h, p) in [
        (0.0, 0.0, 0.0, Param::SemiMajorAxis),
        (-6e6, 0.0, 0.0, Param::SemiMajorAxis),
        (6.4e6, 1.0, 0.0, Param::Flattening),
        (6.4e6, -1e-3, 0.0, Param::Flattening),
        (6.4e6, 0.1, -5.76e6, Param::GroundHeight),
    ] {
        let mut g = geo;
        g.ellipsoid = Ellipsoid {
            a_m: a,
            flattening: fl,
        };
        g.ground_h_m = h;
        expect(&cam, &g, 0.0, ModelError::InvalidInput(p));
    }
    // F6 (docs/fuzzing.md): a subnormal pixel pitch rounded to 0 in f32 gave a zero
    // line period; below 1 nm it is out of the domain on every backend.
    let tiny_pixel = EarthCamera {
        pixel_m: 3.035_577_859_16e-312,
        ..cam
    };
    expect(
        &tiny_pixel,
        &geo,
        0.0,
        ModelError::OutOfDomain(Param::PixelPitch),
    );
    let mut g = geo;
    g.state.position_m = [0.0; 3];
    expect(&cam, &g, 0.0, ModelError::DegenerateState);
    let mut g = geo;
    g.state.velocity_mps = g.state.position_m.map(|x| x * 1e-3);
    expect(&cam, &g, 0.0, ModelError::DegenerateState);
    // Inside the ground ellipsoid: under a 9 km mountain at 5 km altitude.
    let mut g = geo;
    g.state = core_math::earth::circular_state(6_383e3, 0.2, 0.0);
    g.ground_h_m = 9_000.0;
    expect(&cam, &g, 0.0, ModelError::SatelliteNotAboveGround);
    // Looking at the sky.
    let mut g = geo;
    g.attitude.roll_rad = 2.0;
    expect(&cam, &g, 0.0, ModelError::LineOfSightMissesEarth);
    // Beyond the domain.
    let mut g = geo;
    g.attitude.roll_rate_rad_s = 2.0;
    expect(&cam, &g, 0.0, ModelError::OutOfDomain(Param::RollRate));
    let mut g = geo;
    g.state.position_m = [2e9, 0.0, 0.0];
    expect(&cam, &g, 0.0, ModelError::OutOfDomain(Param::Position));
}

/// v1 = 0: a pitch rate that exactly cancels the along-track image motion at the array
/// centre (found by bisection on the reference) leaves no line period.
#[test]
fn no_along_track_motion_is_refused() {
    let (cam, mut g) = default_case();
    g.attitude = Attitude::default();
    let v1 = |rate: f64| {
        let mut g = g;
        g.attitude.pitch_rate_rad_s = rate;
        EarthReference::chain(&g, &EarthReference.pixel(&cam, 0.0).unwrap())
            .unwrap()
            .motion
            .v1_mps
    };
    let (mut lo, mut hi) = (-0.1, 0.1);
    assert!(v1(lo).signum() != v1(hi).signum());
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if v1(mid).signum() == v1(lo).signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // At the exact zero both neighbours straddle it; the reference, fed the rate that
    // gives v1 = 0 to the last bit, refuses.
    let mut g0 = g;
    g0.attitude.pitch_rate_rad_s = if v1(lo) == 0.0 { lo } else { hi };
    if v1(g0.attitude.pitch_rate_rad_s) == 0.0 {
        assert_eq!(
            EarthReference.evaluate(&cam, &g0, 0.0),
            Err(ModelError::NoAlongTrackMotion)
        );
    }
    // The pitch rate that stops the image is the orbit rate seen from the ground point:
    // about -v/H, a large and physically meaningful number, not a rounding artefact.
    assert!(lo.abs() > 5e-3, "{lo}");
    // On either side the period is finite and large.
    let mut g1 = g;
    g1.attitude.pitch_rate_rad_s = lo;
    let m = GENERAL_F64.evaluate(&cam, &g1, 0.0).unwrap();
    assert!(m.v1_mps.abs() < 1e-9);
}

/// Every backend's refusal of a state vector with no angular momentum, whatever its
/// scalar, is the typed one (f32 included, where r x v may round to zero on its own).
#[test]
fn state_vectors_with_no_orbit_plane_are_refused() {
    let (cam, mut g) = default_case();
    g.state = StateVector {
        position_m: [7e6, 0.0, 0.0],
        velocity_mps: [7e3, 0.0, 0.0],
    };
    assert_eq!(
        GENERAL_F32.evaluate(&cam, &g.to::<f32>(), 0.0),
        Err(ModelError::DegenerateState)
    );
    // The model marker is what picks the interface.
    fn takes_earth<B: Backend<Earth>>(_: &B) {}
    takes_earth(&GENERAL_F32);
}

/// Finding F9 (docs/fuzzing.md): a satellite nearly at rest. Its orbital frame is still
/// defined (r x v != 0) and constant, so the image moves by the attitude rates and the
/// Earth's turn alone. With the Earth still and a pitch rate q at the nadir pixel the
/// image of the ground point moves along P1 at f q (exactly, to the velocity's 1e-92);
/// with the Earth turning, the reference agrees with the general form, an independent
/// closed form. Before the fix the reference's frame turned at ~1e77 rad/s here (the
/// rounding of r x a divided by |r x v|) and gave |v| ~ 1e78 m/s.
#[test]
fn a_satellite_nearly_at_rest_moves_the_image_by_the_attitude_and_the_earth_alone() {
    let (cam, mut g) = default_case();
    g.attitude = Attitude {
        pitch_rate_rad_s: -4.5e-4,
        ..Attitude::default()
    };
    for speed_mps in [1e-92, 1e-40, 1e-12, 1e-3] {
        // A direction whose two-body acceleration has a rounding across r (the axes'
        // directions would give r x a = 0 exactly).
        g.state = StateVector {
            position_m: [4.1e6, -3.7e6, 4.6e6],
            velocity_mps: [0.3 * speed_mps, 0.8 * speed_mps, 0.1 * speed_mps],
        };
        g.earth_rate_rad_s = 0.0;
        let r = EarthReference.evaluate(&cam, &g, 0.0).unwrap();
        // The satellite's own motion adds about f |v| / range: 4e-22 m/s at 1e-12 m/s.
        let want = cam.focal_m * 4.5e-4;
        let tol = 1e-12 * want + cam.focal_m * speed_mps / 600e3;
        assert!(
            (r.v1_mps.abs() - want).abs() <= tol && r.v2_mps.abs() <= tol,
            "{speed_mps:e} m/s, Earth still: {r:?}, |v1| should be {want:e}"
        );
        g.earth_rate_rad_s = core_math::EARTH_RATE_RAD_S;
        let r = EarthReference.evaluate(&cam, &g, 0.0).unwrap();
        let m = GENERAL_F64.evaluate(&cam, &g, 0.0).unwrap();
        assert!(
            rel(&m, &r) <= EARTH_F64_REL_TOLERANCE,
            "{speed_mps:e} m/s, Earth turning: reference {r:?}, general {m:?}"
        );
    }
}

/// One general case against 50-digit values of the literal construction computed with
/// mpmath by `tools/derivation/general.py` (an independent route: no Rust, dual numbers
/// in 60-digit arithmetic, the textbook root), its inputs the binary64 roundings of:
/// r = (-2 100 000, 4 800 000, 4 600 000) m, v = (3 198, -3 995, 5 689) m/s (e = 0.0247,
/// i = 97.5 deg), roll 20.5, pitch -7.25, yaw 3.5 deg, rates 0.05, -0.025, 0.0125 deg/s,
/// ground 1 500 m, f 0.75 m, pixel 2^-16 m, n_px 12 000, p1 2^-9 m, WGS 84.
#[test]
// The golden digits are kept as the script printed them; f64 reads the nearest value.
#[allow(clippy::excessive_precision)]
fn a_general_case_against_fifty_digits() {
    let rad = f64::to_radians;
    let camera = EarthCamera {
        focal_m: 0.75,
        pixel_m: 1.0 / 65_536.0,
        p1_m: 1.0 / 512.0,
    };
    let geometry = EarthGeometry {
        state: StateVector {
            position_m: [-2_100_000.0, 4_800_000.0, 4_600_000.0],
            velocity_mps: [3_198.0, -3_995.0, 5_689.0],
        },
        attitude: Attitude {
            roll_rad: rad(20.5),
            pitch_rad: rad(-7.25),
            yaw_rad: rad(3.5),
            roll_rate_rad_s: rad(0.05),
            pitch_rate_rad_s: rad(-0.025),
            yaw_rate_rad_s: rad(0.0125),
        },
        ground_h_m: 1_500.0,
        ellipsoid: Ellipsoid::WGS84,
        earth_rate_rad_s: 7.292_115_9e-5,
    };
    let golden = ImageMotion {
        v1_mps: -0.007_525_801_788_036_971_655_592_857_871_333_662_575_986_491_042_137_6,
        v2_mps: -0.000_256_250_906_440_766_936_231_590_627_015_827_919_704_291_544_252_33,
    };
    let r = EarthReference
        .evaluate(&camera, &geometry, 12_000.0)
        .unwrap();
    let g = GENERAL_F64.evaluate(&camera, &geometry, 12_000.0).unwrap();
    let s = GENERAL_F32
        .evaluate(&camera, &geometry.to::<f32>(), 12_000.0)
        .unwrap();
    let s = ImageMotion {
        v1_mps: f64::from(s.v1_mps),
        v2_mps: f64::from(s.v2_mps),
    };
    assert!(rel(&r, &golden) < 1e-14, "reference {:e}", rel(&r, &golden));
    assert!(
        rel(&g, &golden) < 1e-14,
        "general f64 {:e}",
        rel(&g, &golden)
    );
    assert!(
        rel(&s, &golden) < 1e-6,
        "general f32 {:e}",
        rel(&s, &golden)
    );
}

/// Turning the camera about its boresight by `delta` (`GeneralUpdate::yawed`, and
/// `General::motion_yawed`, the yaw steering request's residual drift) is the update at
/// yaw + delta: both routes checked against the reference evaluated at the turned
/// attitude, over the envelope.
#[test]
fn a_yawed_update_is_the_update_at_the_turned_yaw() {
    let mut rng = SplitMix64(0x7A3D_2026_1124_0001);
    let (mut compared, mut worst64, mut worst32) = (0, 0f64, 0f64);
    for _ in 0..5_000 {
        let Some(c) = rng.earth_case() else { continue };
        let delta = rng.uniform(-0.2, 0.2);
        let mut turned = c.geometry;
        turned.attitude.yaw_rad += delta;
        // Turning the frame moves the pixel's ground point: near the limb it may fall
        // off; only cases at least 0.01 deg inside the limb both ways compare.
        let inside = |g: &EarthGeometry<f64>| {
            limb_margin_rad(g, &c.camera, c.n_px).is_ok_and(|m| m >= 0.01f64.to_radians())
        };
        if !inside(&c.geometry) || !inside(&turned) {
            continue;
        }
        let r = EarthReference.evaluate(&c.camera, &turned, c.n_px).unwrap();
        let (s, co) = libm::sincos(delta);
        let u64_ = GENERAL_F64.update(&c.geometry).unwrap().yawed(s, co);
        let p64 = GENERAL_F64.pixel(&c.camera, c.n_px).unwrap();
        let g = GENERAL_F64.motion(&u64_, &p64).unwrap();
        worst64 = worst64.max(rel(&g, &r));
        let g32 = c.geometry.to::<f32>();
        let u32_ = GENERAL_F32.update(&g32).unwrap().yawed(s as f32, co as f32);
        let p32 = GENERAL_F32.pixel(&c.camera, c.n_px).unwrap();
        let m32 = GENERAL_F32.motion(&u32_, &p32).unwrap();
        let m32 = ImageMotion {
            v1_mps: m32.v1_mps as f64,
            v2_mps: m32.v2_mps as f64,
        };
        // The controller's route: the unturned update, the pixel turned back
        // (`General::motion_yawed`); the same quantity, rounded differently.
        let y64 = GENERAL_F64
            .motion_yawed(&GENERAL_F64.update(&c.geometry).unwrap(), &p64, s, co)
            .unwrap();
        worst64 = worst64.max(rel(&y64, &r));
        let y32 = GENERAL_F32
            .motion_yawed(
                &GENERAL_F32.update(&g32).unwrap(),
                &p32,
                s as f32,
                co as f32,
            )
            .unwrap();
        let y32 = ImageMotion {
            v1_mps: y32.v1_mps as f64,
            v2_mps: y32.v2_mps as f64,
        };
        let kappa = earth_kappa(&c.camera, &turned, c.n_px).unwrap_or(f64::INFINITY);
        for (route, m) in [("yawed", &m32), ("motion_yawed", &y32)] {
            let e32 = rel(m, &r);
            // The f32 route's bound of the turned problem (as in the f32 test), with one
            // more rounding of each turned component.
            assert!(
                e32 <= EARTH_F32_KAPPA_C * (kappa + 4.0) * U32
                    || e32 <= EARTH_F32_NEAR_LIMB_TOLERANCE,
                "f32 {route} {e32:e} (kappa {kappa:.1}) at {c:?}, delta {delta}"
            );
            worst32 = worst32.max(e32);
        }
        compared += 1;
    }
    assert!(compared > 3_000, "only {compared} cases compared");
    assert!(
        worst64 <= 10.0 * EARTH_F64_REL_TOLERANCE,
        "f64 yawed vs reference: {worst64:e}"
    );
    println!("yawed update: {compared} cases, f64 {worst64:.2e}, f32 {worst32:.2e}");
}

/// The row form (`General::row_motion`, the controller's per-sample route): on the
/// pixel's row it is `motion` expanded in p2. Over the envelope, f64 within 1e-12 of the
/// reference; f32 within the same condition-number bound as `motion`'s f32 route; hit,
/// miss and refusal as `motion` (beyond 1e-4 deg of the limb).
#[test]
fn the_row_form_is_the_motion_on_the_row() {
    let mut rng = SplitMix64(0x0EA7_2026_1124_0A0E);
    let (mut compared, mut worst64, mut ratio32, mut far32) = (0, 0f64, 0f64, 0f64);
    let (mut facing_checked, mut facing_refused) = (0, 0);
    for _ in 0..20_000 {
        let Some(c) = rng.earth_case() else { continue };
        let m = margin_deg(&c);
        let p2_m = c.n_px * c.camera.pixel_m;
        let u64_ = GENERAL_F64.update(&c.geometry);
        let g32 = c.geometry.to::<f32>();
        let u32_ = GENERAL_F32.update(&g32);
        let (Ok(u64_), Ok(u32_)) = (u64_, u32_) else {
            continue;
        };
        let row64 = GENERAL_F64
            .row_motion(&u64_, &GENERAL_F64.row(&c.camera).unwrap())
            .motion_at(p2_m);
        let rows32 = GENERAL_F32.row_motion(&u32_, &GENERAL_F32.row(&c.camera).unwrap());
        let row32 = rows32.motion_at(p2_m as f32);
        // The one-check route, wherever the pixel faces the ground: the same bits and the
        // same errors, right to the limb.
        let p2 = p2_m as f32;
        if rows32.faces_ground_over(p2, p2) {
            let facing = rows32.motion_at_facing(p2);
            assert_eq!(
                facing.map(|m| (m.v1_mps.to_bits(), m.v2_mps.to_bits())),
                row32.map(|m| (m.v1_mps.to_bits(), m.v2_mps.to_bits())),
                "{c:?}"
            );
            facing_checked += 1;
            facing_refused += usize::from(facing.is_err());
        } else {
            assert_eq!(row32.map(|_| ()), Err(ModelError::LineOfSightMissesEarth));
        }
        // Facing the ground at both ends of an interval: at every pixel between.
        let (a, b) = (p2.min(-p2), p2.max(-p2));
        if rows32.faces_ground_over(a, b) {
            for k in 0..=16 {
                let q = a + (b - a) * k as f32 / 16.0;
                assert!(rows32.beta[0] + rows32.beta[1] * q < 0.0, "{q} {c:?}");
            }
        }
        let direct64 = GENERAL_F64.motion(&u64_, &GENERAL_F64.pixel(&c.camera, c.n_px).unwrap());
        let direct32 = GENERAL_F32.motion(&u32_, &GENERAL_F32.pixel(&c.camera, c.n_px).unwrap());
        if m.abs() < EITHER_DEG {
            continue;
        }
        assert_eq!(
            row64.is_ok(),
            direct64.is_ok(),
            "f64 {row64:?} / {direct64:?} at {c:?}"
        );
        assert_eq!(
            row32.map(|_| ()),
            direct32.map(|_| ()),
            "f32 at {m} deg: {c:?}"
        );
        let (Ok(row64), Ok(row32)) = (row64, row32) else {
            continue;
        };
        if m < 0.01 {
            continue;
        }
        let r = EarthReference
            .evaluate(&c.camera, &c.geometry, c.n_px)
            .unwrap();
        worst64 = worst64.max(rel(&row64, &r));
        let e32 = rel(
            &ImageMotion {
                v1_mps: row32.v1_mps as f64,
                v2_mps: row32.v2_mps as f64,
            },
            &r,
        );
        let kappa = earth_kappa(&c.camera, &c.geometry, c.n_px).unwrap();
        assert!(
            e32 <= EARTH_F32_KAPPA_C * kappa * U32,
            "f32 row {e32:e}, kappa {kappa}: {c:?}"
        );
        if kappa <= EARTH_F32_KAPPA_LIMIT && m >= 1.0 {
            assert!(e32 <= EARTH_F32_REL_TOLERANCE, "f32 row {e32:e}: {c:?}");
            far32 = far32.max(e32);
        }
        ratio32 = ratio32.max(e32 / (kappa * U32));
        compared += 1;
    }
    assert!(compared > 10_000, "only {compared} cases compared");
    assert!(facing_checked > 10_000, "only {facing_checked} facing");
    assert!(facing_refused > 0, "no refusal on the one-check route");
    assert!(
        worst64 <= EARTH_F64_REL_TOLERANCE,
        "f64 row vs reference: {worst64:e}"
    );
    println!(
        "row form: {compared} cases, f64 {worst64:.2e}, f32 {far32:.2e} (kappa <= \
         {EARTH_F32_KAPPA_LIMIT}, >= 1 deg from the limb), f32 err/(kappa u) {ratio32:.2}; \
         one-check route {facing_checked} pixels ({facing_refused} refused) as motion_at"
    );
}

//! Part II of `shared/EARTH-MODEL.md` without a DEM: the attitude given by the camera's
//! axes in I and its angular velocity ([`InertialAttitude`]) on every backend.
//!
//! - Part I's attitudes re-expressed as axes and angular velocity give Part I's motion
//!   (reference, general f64 and f32);
//! - the typed refusals.
//!
//! `cargo test --release -p core-math --test part2 -- --nocapture` prints the measured
//! maxima.

use core_math::accuracy::{
    earth_kappa, EARTH_F32_KAPPA_LIMIT, EARTH_F32_REL_TOLERANCE, EARTH_F64_REL_TOLERANCE,
};
use core_math::dual::Dual;
use core_math::earth::frames::Mat3;
use core_math::earth::reference::{EarthRefPixel, ReferenceGeometry};
use core_math::earth::{limb_margin_rad, InertialAttitude, InertialGeometry, MAX_AXES_ERROR};
use core_math::sample::SplitMix64;
use core_math::{
    Backend, EarthCamera, EarthReference, Ellipsoid, ImageMotion, ModelError, Param, StateVector,
    EARTH_RATE_RAD_S, GENERAL_F32, GENERAL_F64,
};

fn rel(m: &ImageMotion<f64>, r: &ImageMotion<f64>) -> f64 {
    libm::hypot(m.v1_mps - r.v1_mps, m.v2_mps - r.v2_mps) / libm::hypot(r.v1_mps, r.v2_mps)
}

fn widen(m: ImageMotion<f32>) -> ImageMotion<f64> {
    ImageMotion {
        v1_mps: m.v1_mps as f64,
        v2_mps: m.v2_mps as f64,
    }
}

/// The reference, general f64 and general f32 motions of an inertial geometry.
fn eval_all(
    camera: &EarthCamera,
    g: &InertialGeometry<f64>,
    n_px: f64,
) -> [Result<ImageMotion<f64>, ModelError>; 3] {
    let reference = (|| {
        let (p1_m, p2_m) = camera.focal_plane_m(n_px)?;
        let px = EarthRefPixel {
            p1_m,
            p2_m,
            focal_m: camera.focal_m,
        };
        EarthReference::motion_of(g, &px)
    })();
    let f64_form = (|| {
        let up = GENERAL_F64.update_inertial(g)?;
        GENERAL_F64.motion(&up, &GENERAL_F64.pixel(camera, n_px)?)
    })();
    let f32_form = (|| {
        let up = GENERAL_F32.update_inertial(&g.to::<f32>())?;
        GENERAL_F32
            .motion(&up, &GENERAL_F32.pixel(camera, n_px)?)
            .map(widen)
    })();
    [reference, f64_form, f32_form]
}

/// B0 and Omega of a geometry's camera at t = 0 from the reference's axes on dual
/// numbers: B0 = M(0), [Omega]x = B0^T dM/dt.
fn inertial_of<G: ReferenceGeometry>(g: &G) -> InertialAttitude<f64> {
    let m = g.axes(Dual::new(0.0, 1.0));
    let b0: Mat3 = m.map(|row| row.map(|x| x.re));
    let db: Mat3 = m.map(|row| row.map(|x| x.du));
    let k = |i: usize, j: usize| (0..3).map(|l| b0[l][i] * db[l][j]).sum::<f64>();
    InertialAttitude {
        camera_to_inertial: b0,
        omega_rad_s: [k(2, 1), k(0, 2), k(1, 0)],
    }
}

/// Part I's cases with the attitude handed over as the camera's axes in I and their
/// angular velocity: every backend gives Part I's motion (reference to 1e-12, general
/// f64 to Part I's 1e-12, general f32 to Part I's 2e-6 where kappa <= 30 and 1 deg
/// inside the limb), and the same refusals.
#[test]
fn part_one_attitudes_as_axes_give_part_one_motion() {
    let mut rng = SplitMix64(0x0EA7_2026_1126_0023);
    let (mut n, mut worst_ref, mut worst_f64, mut worst_f32, mut n_f32) = (0, 0f64, 0f64, 0f64, 0);
    for _ in 0..5_000 {
        let Some(c) = rng.earth_case() else { continue };
        let margin = limb_margin_rad(&c.geometry, &c.camera, c.n_px)
            .unwrap()
            .to_degrees();
        if margin < 1e-3 {
            continue;
        }
        let part1 = EarthReference.evaluate(&c.camera, &c.geometry, c.n_px);
        let g = InertialGeometry {
            state: c.geometry.state,
            attitude: inertial_of(&c.geometry),
            ground_h_m: c.geometry.ground_h_m,
            ellipsoid: c.geometry.ellipsoid,
            earth_rate_rad_s: c.geometry.earth_rate_rad_s,
        };
        let [r, g64, g32] = eval_all(&c.camera, &g, c.n_px);
        let Ok(part1) = part1 else {
            assert_eq!(r, part1.map(|_| unreachable!()), "{c:?}");
            assert_eq!(g64.err(), part1.err(), "{c:?}");
            continue;
        };
        let (r, g64) = (r.unwrap(), g64.unwrap());
        let (e_ref, e_64) = (rel(&r, &part1), rel(&g64, &r));
        assert!(e_ref <= 1e-12, "{e_ref:e}: {c:?}");
        assert!(e_64 <= EARTH_F64_REL_TOLERANCE, "{e_64:e}: {c:?}");
        worst_ref = worst_ref.max(e_ref);
        worst_f64 = worst_f64.max(e_64);
        n += 1;
        let kappa = earth_kappa(&c.camera, &c.geometry, c.n_px).unwrap();
        if margin >= 1.0 && kappa <= EARTH_F32_KAPPA_LIMIT {
            let e_32 = rel(&g32.unwrap(), &r);
            assert!(e_32 <= EARTH_F32_REL_TOLERANCE, "{e_32:e}: {c:?}");
            worst_f32 = worst_f32.max(e_32);
            n_f32 += 1;
        }
    }
    println!(
        "Part I attitudes as axes: {n} hits; reference (axes) vs reference (angles) \
         {worst_ref:.2e}; general f64 vs reference {worst_f64:.2e}; general f32 vs \
         reference {worst_f32:.2e} ({n_f32} cases, kappa <= {EARTH_F32_KAPPA_LIMIT}, \
         >= 1 deg inside the limb)"
    );
    assert!(n > 3_000 && n_f32 > 1_000);
}

/// The attitude's own checks, on every backend: non-finite axes or rates, axes that are
/// not a rotation, rates beyond the domain.
#[test]
fn bad_inertial_attitudes_give_their_typed_errors() {
    // On +x, flying +y; x_B along the flight, z_B the zenith: boresight nadir.
    let good = InertialGeometry {
        state: StateVector {
            position_m: [7.0e6, 0.0, 0.0],
            velocity_mps: [0.0, 7.5e3, 0.0],
        },
        attitude: InertialAttitude {
            camera_to_inertial: [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            omega_rad_s: [0.0; 3],
        },
        ground_h_m: 0.0,
        ellipsoid: Ellipsoid::WGS84,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    };
    let camera = EarthCamera {
        focal_m: 1.0,
        pixel_m: 1e-5,
        p1_m: 0.0,
    };
    for r in eval_all(&camera, &good, 100.0) {
        assert!(r.is_ok(), "{r:?}");
    }
    let with = |f: &dyn Fn(&mut InertialAttitude<f64>)| {
        let mut g = good;
        f(&mut g.attitude);
        g
    };
    let cases: [(InertialGeometry<f64>, ModelError); 6] = [
        (
            with(&|a| a.camera_to_inertial[1][2] = f64::NAN),
            ModelError::NonFinite(Param::CameraAxes),
        ),
        (
            with(&|a| a.omega_rad_s[0] = f64::INFINITY),
            ModelError::NonFinite(Param::AngularVelocity),
        ),
        (
            with(&|a| a.omega_rad_s[2] = 1.0e3),
            ModelError::OutOfDomain(Param::AngularVelocity),
        ),
        (
            with(&|a| a.camera_to_inertial[0][2] *= 1.0 + 3.0 * MAX_AXES_ERROR),
            ModelError::InvalidInput(Param::CameraAxes),
        ),
        (
            // A reflection: orthonormal, left-handed.
            with(&|a| {
                a.camera_to_inertial
                    .iter_mut()
                    .for_each(|row| row[2] = -row[2])
            }),
            ModelError::InvalidInput(Param::CameraAxes),
        ),
        (
            with(&|a| a.camera_to_inertial = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
            // Looking up: the satellite on +x, boresight -z.
            ModelError::LineOfSightMissesEarth,
        ),
    ];
    for (g, want) in cases {
        for (k, r) in eval_all(&camera, &g, 100.0).into_iter().enumerate() {
            assert_eq!(r, Err(want), "backend {k}: {g:?}");
        }
    }
}

//! Part II of `shared/EARTH-MODEL.md` without a DEM: the attitude given by the camera's
//! axes in I and its angular velocity ([`InertialAttitude`]), and the conversion of the
//! bus's data ([`core_math::earth::bus`]: state frames, quaternion, body rates, camera
//! mounting) on every backend.
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
use core_math::earth::bus::{
    bus_geometry, dps_to_rad_s, needs_c2t, quaternion_matrix, AttitudeFrame, BusAttitude, BusState,
    BusTime, StateFrame, IDENTITY_QUATERNION,
};
use core_math::earth::frames::{Mat3, TimeScales};
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

fn default_bus() -> (BusState, BusAttitude, BusTime) {
    (
        BusState {
            frame: StateFrame::Itrf,
            position_m: [7.0e6, 0.0, 0.0],
            velocity_mps: [0.0, 7.5e3, 0.0],
        },
        BusAttitude {
            // x_B along +y (the flight), z_B along +x (the zenith): boresight nadir when
            // the quaternion is relative to the ITRF.
            q: [0.5, 0.5, 0.5, 0.5],
            frame: AttitudeFrame::Gcrf,
            body_rate_rad_s: [0.0; 3],
            camera_q: IDENTITY_QUATERNION,
        },
        BusTime {
            gps_s: Some(1.4e9),
            scales: TimeScales::DEFAULT,
        },
    )
}

fn geometry(
    s: &BusState,
    a: &BusAttitude,
    t: &BusTime,
) -> Result<InertialGeometry<f64>, ModelError> {
    bus_geometry(s, a, t, 0.0, Ellipsoid::WGS84, 7.292_115_9e-5)
}

#[test]
fn bad_bus_inputs_give_their_typed_errors() {
    let (s, a, t) = default_bus();
    assert!(geometry(&s, &a, &t).is_ok());
    let q_err = ModelError::InvalidQuaternion(Param::Quaternion);
    assert_eq!(q_err.name(), "invalid_quaternion");
    for (q, want) in [
        ([1.0011, 0.0, 0.0, 0.0], Err(q_err)),
        ([0.0, 0.0, 0.0, 0.998], Err(q_err)),
        ([0.0; 4], Err(q_err)),
        ([0.6, 0.6, 0.6, 0.6], Err(q_err)),
        ([1.0009, 0.0, 0.0, 0.0], Ok(())),
        ([0.0, 0.0, 0.0, -0.9991], Ok(())),
        (
            [f64::NAN, 0.0, 0.0, 1.0],
            Err(ModelError::NonFinite(Param::Quaternion)),
        ),
        (
            [1.0, f64::INFINITY, 0.0, 0.0],
            Err(ModelError::NonFinite(Param::Quaternion)),
        ),
    ] {
        let got = geometry(&s, &BusAttitude { q, ..a }, &t).map(|_| ());
        assert_eq!(got, want, "{q:?}");
        let cam = geometry(&s, &BusAttitude { camera_q: q, ..a }, &t).map(|_| ());
        let want_cam = want.map_err(|e| match e {
            ModelError::InvalidQuaternion(_) => {
                ModelError::InvalidQuaternion(Param::CameraQuaternion)
            }
            _ => ModelError::NonFinite(Param::CameraQuaternion),
        });
        assert_eq!(cam, want_cam, "cam {q:?}");
    }
    // Normalised before use: a quaternion off by 9e-4 gives the unit one's matrix.
    let m = quaternion_matrix([0.0, 0.0, 1.0009, 0.0], Param::Quaternion).unwrap();
    assert_eq!(m, [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]);
    // Non-finite state and rates.
    let nan3 = [f64::NAN, 0.0, 0.0];
    let bad_r = BusState {
        position_m: nan3,
        ..s
    };
    assert_eq!(
        geometry(&bad_r, &a, &t),
        Err(ModelError::NonFinite(Param::Position))
    );
    let bad_v = BusState {
        velocity_mps: nan3,
        ..s
    };
    assert_eq!(
        geometry(&bad_v, &a, &t),
        Err(ModelError::NonFinite(Param::Velocity))
    );
    let bad_w = BusAttitude {
        body_rate_rad_s: nan3,
        ..a
    };
    assert_eq!(
        geometry(&s, &bad_w, &t),
        Err(ModelError::NonFinite(Param::BodyRate))
    );
    // GPS time: needed by a GCRF state or quaternion, not otherwise.
    let no_time = BusTime { gps_s: None, ..t };
    let missing = Err(ModelError::InvalidInput(Param::GpsTime));
    assert_eq!(geometry(&s, &a, &no_time), missing);
    let a_itrf = BusAttitude {
        frame: AttitudeFrame::Itrf,
        ..a
    };
    assert!(geometry(&s, &a_itrf, &no_time).is_ok());
    let s_gcrf = BusState {
        frame: StateFrame::Gcrf,
        ..s
    };
    assert_eq!(geometry(&s_gcrf, &a_itrf, &no_time), missing);
    let s_inertial = BusState {
        frame: StateFrame::Inertial,
        ..s
    };
    assert!(geometry(&s_inertial, &a_itrf, &no_time).is_ok());
    let nan_time = BusTime {
        gps_s: Some(f64::NAN),
        ..t
    };
    assert_eq!(
        geometry(&s, &a, &nan_time),
        Err(ModelError::NonFinite(Param::GpsTime))
    );
    let bad_scales = BusTime {
        scales: TimeScales {
            dut1_s: 1.0,
            ..t.scales
        },
        ..t
    };
    assert_eq!(
        geometry(&s, &a, &bad_scales),
        Err(ModelError::InvalidInput(Param::Dut1))
    );
    // A bad quaternion is named even when the time is missing too.
    let bad_q = BusAttitude {
        q: [2.0, 0.0, 0.0, 0.0],
        ..a
    };
    assert_eq!(geometry(&s, &bad_q, &no_time), Err(q_err));
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

/// The conversion itself, by hand: ITRF velocity plus w x r, GCRF by C2T, the mounting
/// and the body rates, which inputs need C2T.
#[test]
fn bus_conversion_follows_the_frames() {
    let (s, a, t) = default_bus();
    let w_e = 7.292_115_9e-5;
    let a_itrf = BusAttitude {
        frame: AttitudeFrame::Itrf,
        // Mounted turned by 90 deg about z_body: x_cam = y_body.
        camera_q: [libm::sqrt(0.5), 0.0, 0.0, libm::sqrt(0.5)],
        body_rate_rad_s: dps_to_rad_s([1.0, 0.0, 0.0]),
        ..a
    };
    assert!(!needs_c2t(&s, &a_itrf) && needs_c2t(&s, &a));
    let g = geometry(&s, &a_itrf, &t).unwrap();
    assert_eq!(g.state.position_m, s.position_m);
    assert_eq!(g.state.velocity_mps, [0.0, 7.5e3 + w_e * 7.0e6, 0.0]);
    // Omega = R(cam)^T w = (0, -1, 0) deg/s; B = R(q) R(cam): x_B = y_body = +z (I).
    let om = g.attitude.omega_rad_s;
    let want = dps_to_rad_s([0.0, -1.0, 0.0]);
    assert!((0..3).all(|i| (om[i] - want[i]).abs() < 1e-16), "{om:?}");
    let b = g.attitude.camera_to_inertial;
    let x_b = [b[0][0], b[1][0], b[2][0]];
    assert!(
        (x_b[2] - 1.0).abs() < 1e-15 && x_b[0].abs() < 1e-15,
        "{b:?}"
    );
    // GCRF: r_I = C2T r, v_I = C2T v, B = C2T R(q) R(cam).
    let c2t = core_math::earth::frames::c2t(t.gps_s.unwrap(), &t.scales).unwrap();
    let s_gcrf = BusState {
        frame: StateFrame::Gcrf,
        ..s
    };
    let a_gcrf = BusAttitude {
        frame: AttitudeFrame::Gcrf,
        ..a_itrf
    };
    let g2 = geometry(&s_gcrf, &a_gcrf, &t).unwrap();
    let mv = |x: [f64; 3]| -> [f64; 3] {
        core::array::from_fn(|i| (0..3).map(|j| c2t[i][j] * x[j]).sum::<f64>())
    };
    assert_eq!(g2.state.position_m, mv(s.position_m));
    assert_eq!(g2.state.velocity_mps, mv(s.velocity_mps));
    for j in 0..3 {
        let col = mv([b[0][j], b[1][j], b[2][j]]);
        let got = g2.attitude.camera_to_inertial;
        assert!((0..3).all(|i| (got[i][j] - col[i]).abs() < 1e-15));
    }
    assert_eq!(g2.attitude.omega_rad_s, g.attitude.omega_rad_s);
}

//! Part II of `shared/EARTH-MODEL.md` without a DEM: the attitude given by the camera's
//! axes in I and its angular velocity ([`InertialAttitude`]), and the conversion of the
//! bus's data ([`core_math::earth::bus`]: state frames, quaternion, body rates, camera
//! mounting) on every backend.
//!
//! - Part I's attitudes re-expressed as axes and angular velocity give Part I's motion
//!   (reference, general f64 and f32);
//! - the independent goldens of `tools/goldens/part2_motion.py`
//!   (`tests/data/part2_motion.csv`: mpmath, its own quaternions and intersection, ERFA's
//!   C2T) against the reference and the general forms, first with ERFA's C2T from the
//!   row, then with the crate's own C2T within the effect of its documented error;
//! - the typed refusals.
//!
//! `cargo test --release -p core-math --test part2 -- --nocapture` prints the measured
//! maxima quoted in `docs/earth-model.md`, "Part II: bus inputs".

use core_math::accuracy::{
    earth_kappa, EARTH_F32_KAPPA_LIMIT, EARTH_F32_REL_TOLERANCE, EARTH_F64_REL_TOLERANCE,
};
use core_math::dual::Dual;
use core_math::earth::bus::{
    bus_geometry, bus_geometry_with_c2t, dps_to_rad_s, needs_c2t, quaternion_matrix, AttitudeFrame,
    BusAttitude, BusState, BusTime, StateFrame, IDENTITY_QUATERNION,
};
use core_math::earth::frames::{Mat3, TimeScales, C2T_TOLERANCE_RAD};
use core_math::earth::reference::{EarthRefPixel, ReferenceGeometry};
use core_math::earth::{limb_margin_rad, InertialAttitude, InertialGeometry, MAX_AXES_ERROR};
use core_math::sample::SplitMix64;
use core_math::{
    Backend, EarthCamera, EarthReference, Ellipsoid, ImageMotion, ModelError, Param, StateVector,
    EARTH_RATE_RAD_S, GENERAL_F32, GENERAL_F64,
};

const CSV: &str = include_str!("data/part2_motion.csv");

/// Tolerances of the golden comparison (relative, |dv| / |v|): the reference and the
/// general f64 form against the independent evaluation, and the f32 form (its update
/// computed in f32 from the f64 axes rounded).
const GOLDEN_F64_REL: f64 = 1.0e-9;
const GOLDEN_F32_REL: f64 = 2.0e-6;

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

/// `EarthGeometry::to_inertial` (plain f64: the orbital frame and A, Omega from the
/// general form's W_B and n_B) against the reference's axes on dual numbers (B0 = M(0),
/// [Omega]x = B0^T dM/dt), over Part I's seeded cases.
#[test]
fn part_one_to_inertial_matches_the_dual_number_axes() {
    let mut rng = SplitMix64(0x0EA7_2026_1126_0024);
    let (mut n, mut worst_axes, mut worst_omega) = (0, 0f64, 0f64);
    for _ in 0..2_000 {
        let Some(c) = rng.earth_case() else { continue };
        let mine = c.geometry.to_inertial().unwrap().attitude;
        let dual = inertial_of(&c.geometry);
        for i in 0..3 {
            for j in 0..3 {
                let d = (mine.camera_to_inertial[i][j] - dual.camera_to_inertial[i][j]).abs();
                worst_axes = worst_axes.max(d);
            }
        }
        let wn = dual
            .omega_rad_s
            .iter()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt()
            .max(1e-6);
        for k in 0..3 {
            worst_omega = worst_omega.max((mine.omega_rad_s[k] - dual.omega_rad_s[k]).abs() / wn);
        }
        n += 1;
    }
    assert!(n > 1_000, "{n} cases");
    assert!(
        worst_axes <= 1e-14 && worst_omega <= 1e-12,
        "{worst_axes:e} {worst_omega:e}"
    );
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

/// One golden row.
struct Golden {
    case: u32,
    state: BusState,
    attitude: BusAttitude,
    time: BusTime,
    ground_h_m: f64,
    ellipsoid: Ellipsoid,
    earth_rate_rad_s: f64,
    camera: EarthCamera,
    n_px: f64,
    c2t_erfa: Option<Mat3>,
    motion: ImageMotion<f64>,
}

fn goldens() -> Vec<Golden> {
    let mut lines = CSV.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            let s = |name: &str| fields[head.iter().position(|h| *h == name).expect(name)];
            let f = |name: &str| s(name).parse::<f64>().expect(name);
            let opt = |name: &str| (!s(name).is_empty()).then(|| f(name));
            let v3 = |a: &str, b: &str, c: &str| [f(a), f(b), f(c)];
            let q4 = |p: &str| {
                [
                    f(&format!("{p}qw")),
                    f(&format!("{p}qx")),
                    f(&format!("{p}qy")),
                    f(&format!("{p}qz")),
                ]
            };
            let c2t_erfa = opt("c2t_00").map(|_| {
                core::array::from_fn(|i| core::array::from_fn(|j| f(&format!("c2t_{i}{j}"))))
            });
            Golden {
                case: f("case") as u32,
                state: BusState {
                    frame: match s("frame") {
                        "inertial" => StateFrame::Inertial,
                        "itrf" => StateFrame::Itrf,
                        "gcrf" => StateFrame::Gcrf,
                        x => panic!("frame {x}"),
                    },
                    position_m: v3("x_m", "y_m", "z_m"),
                    velocity_mps: v3("vx_mps", "vy_mps", "vz_mps"),
                },
                attitude: BusAttitude {
                    q: q4(""),
                    frame: match s("attitude_frame") {
                        "gcrf" => AttitudeFrame::Gcrf,
                        "itrf" => AttitudeFrame::Itrf,
                        x => panic!("attitude_frame {x}"),
                    },
                    body_rate_rad_s: dps_to_rad_s(v3("wx_dps", "wy_dps", "wz_dps")),
                    camera_q: q4("cam_"),
                },
                time: BusTime {
                    gps_s: opt("gps_s"),
                    scales: TimeScales {
                        gps_utc_s: f("gps_utc_s"),
                        dut1_s: f("dut1_s"),
                    },
                },
                ground_h_m: f("ground_h_m"),
                ellipsoid: Ellipsoid {
                    a_m: f("a_m"),
                    flattening: f("flattening"),
                },
                earth_rate_rad_s: f("earth_rate_rad_s"),
                camera: EarthCamera {
                    focal_m: f("f_m"),
                    pixel_m: f("pixel_m"),
                    p1_m: f("p1_m"),
                },
                n_px: f("n_px"),
                c2t_erfa,
                motion: ImageMotion {
                    v1_mps: f("v1_mps"),
                    v2_mps: f("v2_mps"),
                },
            }
        })
        .collect()
}

impl Golden {
    fn geometry_with(&self, c2t: Option<&Mat3>) -> Result<InertialGeometry<f64>, ModelError> {
        bus_geometry_with_c2t(
            &self.state,
            &self.attitude,
            c2t,
            self.ground_h_m,
            self.ellipsoid,
            self.earth_rate_rad_s,
        )
    }
}

/// R(angle about axis k) C: C2T turned by `angle` about I's axis k.
fn turned(c2t: &Mat3, k: usize, angle: f64) -> Mat3 {
    let (s, c) = libm::sincos(angle);
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let mut out = *c2t;
    for col in 0..3 {
        out[i][col] = c * c2t[i][col] - s * c2t[j][col];
        out[j][col] = s * c2t[i][col] + c * c2t[j][col];
    }
    out
}

/// The independent goldens: with ERFA's C2T from the row, the reference and the general
/// f64 form within 1e-9 and the f32 form within 2e-6 of the mpmath evaluation; with the
/// crate's own C2T ([`core_math::earth::frames::c2t`]), the reference within 1e-9 plus
/// the effect of C2T's documented error [`C2T_TOLERANCE_RAD`] on that row (the largest
/// change of the reference's motion when ERFA's C2T is turned by that angle about
/// either sense of each axis of I).
#[test]
fn the_independent_goldens() {
    let rows = goldens();
    assert!(rows.len() >= 300);
    let mut worst = [0f64; 3];
    let (mut worst_own, mut worst_allowance, mut worst_own_excess, mut n_c2t) =
        (0f64, 0f64, 0f64, 0);
    for row in &rows {
        assert_eq!(needs_c2t(&row.state, &row.attitude), row.c2t_erfa.is_some());
        let g = row.geometry_with(row.c2t_erfa.as_ref()).unwrap();
        let results = eval_all(&row.camera, &g, row.n_px);
        for (k, (res, tol)) in results
            .iter()
            .zip([GOLDEN_F64_REL, GOLDEN_F64_REL, GOLDEN_F32_REL])
            .enumerate()
        {
            let m = res.unwrap_or_else(|e| panic!("case {}: backend {k}: {e}", row.case));
            let e = rel(&m, &row.motion);
            assert!(e <= tol, "case {}: backend {k}: {e:e}", row.case);
            worst[k] = worst[k].max(e);
        }

        // The whole bus path, C2T the crate's own.
        let own = bus_geometry(
            &row.state,
            &row.attitude,
            &row.time,
            row.ground_h_m,
            row.ellipsoid,
            row.earth_rate_rad_s,
        )
        .unwrap();
        let [r_own, g_own, _] = eval_all(&row.camera, &own, row.n_px);
        let (r_own, g_own) = (r_own.unwrap(), g_own.unwrap());
        let e_own = rel(&r_own, &row.motion);
        let allowance = match &row.c2t_erfa {
            None => 0.0,
            Some(c2t) => {
                n_c2t += 1;
                let mut a = 0f64;
                for k in 0..3 {
                    for sign in [-1.0, 1.0] {
                        let g = row.geometry_with(Some(&turned(c2t, k, sign * C2T_TOLERANCE_RAD)));
                        let [r, _, _] = eval_all(&row.camera, &g.unwrap(), row.n_px);
                        a = a.max(rel(&r.unwrap(), &results[0].unwrap()));
                    }
                }
                a
            }
        };
        assert!(
            e_own <= GOLDEN_F64_REL + allowance,
            "case {}: own C2T {e_own:e}, allowance {allowance:e}",
            row.case
        );
        assert!(rel(&g_own, &r_own) <= EARTH_F64_REL_TOLERANCE);
        worst_own = worst_own.max(e_own);
        worst_allowance = worst_allowance.max(allowance);
        worst_own_excess = worst_own_excess.max(e_own - GOLDEN_F64_REL);
    }
    println!(
        "Part II goldens ({} rows, {n_c2t} with C2T), ERFA's C2T: reference {:.2e}, \
         general f64 {:.2e}, general f32 {:.2e}",
        rows.len(),
        worst[0],
        worst[1],
        worst[2]
    );
    println!(
        "Part II goldens, the crate's C2T: reference {worst_own:.2e} (allowance for C2T's \
         {C2T_TOLERANCE_RAD:.0e} rad: up to {worst_allowance:.2e})"
    );
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

/// `matrix_quaternion` inverts `quaternion_matrix` up to the sign, on every one of
/// Shepperd's four branches (each component the largest in turn), to 1e-15.
#[test]
fn matrix_quaternion_inverts_quaternion_matrix() {
    let mut rng = core_math::sample::SplitMix64(0x0DD5_4A7E_2026);
    let mut worst = 0.0f64;
    for k in 0..20_000 {
        let mut q: [f64; 4] = core::array::from_fn(|_| rng.uniform(-1.0, 1.0));
        // Every fourth case makes component k % 4 the largest by far.
        if k % 2 == 0 {
            q[k % 4] *= 8.0;
        }
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        let q = q.map(|c| c / n);
        let m = quaternion_matrix(q, Param::Quaternion).unwrap();
        let back = core_math::earth::bus::matrix_quaternion(&m);
        let (plus, minus) = (0..4).fold((0.0f64, 0.0f64), |(p, n), i| {
            (p.max((back[i] - q[i]).abs()), n.max((back[i] + q[i]).abs()))
        });
        worst = worst.max(plus.min(minus));
    }
    assert!(worst <= 1e-15, "{worst:e}");
}

//! The bus's data carried to an update instant (Part II of `shared/EARTH-MODEL.md`):
//! the last GNSS fix on the two-body orbit, the last attitude at its body rates, both
//! turned into the general form's inputs in the frame I of the update instant (the ITRF
//! frozen at it).
//!
//! What is done once per frame, in f64: the GNSS state in I at its time of fix
//! (r, v + w x r); the camera's axes in I at the attitude's time of validity,
//! B = C2T R(q) R(cam_q), with C2T from a [`CelestialPole`] that is recomputed only when
//! it is older than [`POLE_MAX_AGE_S`] (the precession-nutation series at most once a
//! minute at a steady stream of frames) and the Earth rotation angle of the instant.
//!
//! What is done per update, in f32: the orbit's Taylor series ([`Propagator`]) to the
//! update instant, the attitude turned by its body rates over the time since its
//! validity (B exp([Omega]x dt), a series in the rotation vector), and both frames
//! turned to the ITRF of the update instant: I at t is I at t0 turned about z by the
//! Earth's rotation in t - t0 (R3(w (t - t0)); over 2 s this angle is 1.5e-4 rad, and
//! ERA's own rate differs from `w` by 1e-8 of it, 1.5e-12 rad). No trigonometry.

use core_math::earth::bus::quaternion_matrix;
use core_math::earth::frames::{mat_mul, CelestialPole, TimeScales, POLE_MAX_AGE_S};
use core_math::earth::{GeneralInstant, InertialAttitude};
use core_math::{ModelError, Param, StateVector, GENERAL_F32};

use crate::bus::{gps_s, Gnss, StarAttitude};
use crate::config::EARTH_RATE_RAD_S;
use crate::fault::Fault;
use crate::nav::Propagator;

/// The last accepted GNSS fix, as the state in I at its time of fix, ready to
/// propagate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssState {
    pub fix_us: u64,
    pub propagator: Propagator,
}

impl GnssState {
    /// The fix's state in I at the time of fix: r_I = r, v_I = v + w x r.
    pub fn inertial(g: &Gnss) -> StateVector {
        let (r, v, w) = (g.position_m, g.velocity_mps, EARTH_RATE_RAD_S);
        StateVector {
            position_m: r,
            velocity_mps: [v[0] - w * r[1], v[1] + w * r[0], v[2]],
        }
    }

    pub fn new(g: &Gnss) -> GnssState {
        GnssState {
            fix_us: g.fix_us,
            propagator: Propagator::new(&GnssState::inertial(g)),
        }
    }
}

/// The last accepted attitude: as received (to derive it again when the mounting or
/// the time scales change), and the camera's axes in I at its time of validity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeState {
    pub received: StarAttitude,
    /// B at the time of validity, row-major (x_I = B x_camera), rounded to f32.
    pub camera_to_inertial: [[f32; 3]; 3],
    /// Omega = R(cam_q)^T w_body (rad/s): the camera's angular velocity in its own axes.
    pub omega_rad_s: [f32; 3],
}

/// The pole to use at `t_us`: `pole` when it is within [`POLE_MAX_AGE_S`] of it, else
/// a new one (kept by the caller once the frame is accepted). Refusals: a time outside
/// C2T's domain (`fix_time`).
// Out of line: the ATTITUDE check and the re-derivation after a new pole each
// inlined it (docs/target.md, flash).
#[inline(never)]
pub fn pole_for(
    pole: Option<&CelestialPole>,
    t_us: u64,
    scales: &TimeScales,
) -> Result<CelestialPole, Fault> {
    let t_s = gps_s(t_us);
    match pole {
        Some(p) if libm::fabs(t_s - p.gps_s) <= POLE_MAX_AGE_S => Ok(*p),
        _ => CelestialPole::at(t_s, scales).map_err(|_| Fault::FixTime),
    }
}

impl AttitudeState {
    /// The attitude in I: B = C2T R(q) R(cam_q), Omega = R(cam_q)^T w. Refusals: a
    /// quaternion (the attitude's or the mounting's) whose norm is off by more than
    /// 1e-3 (`bad_quaternion`), a time outside C2T's domain (`fix_time`).
    pub fn derive(
        a: &StarAttitude,
        mounting_q: &[f32; 4],
        pole: &CelestialPole,
        scales: &TimeScales,
    ) -> Result<AttitudeState, Fault> {
        let quaternion = |q: &[f32; 4], p: Param| {
            quaternion_matrix(q.map(f64::from), p).map_err(|e| match e {
                ModelError::NonFinite(_) => Fault::NonFinite,
                _ => Fault::BadQuaternion,
            })
        };
        let body = quaternion(&a.q, Param::Quaternion)?;
        let mount = quaternion(mounting_q, Param::CameraQuaternion)?;
        let c2t = pole
            .c2t(gps_s(a.valid_us), scales)
            .map_err(|_| Fault::FixTime)?;
        let b = mat_mul(&c2t, &mat_mul(&body, &mount));
        let w = a.body_rate_rad_s.map(f64::from);
        let omega: [f64; 3] =
            core::array::from_fn(|j| mount[0][j] * w[0] + mount[1][j] * w[1] + mount[2][j] * w[2]);
        Ok(AttitudeState {
            received: *a,
            camera_to_inertial: b.map(|row| row.map(|x| x as f32)),
            omega_rad_s: omega.map(|x| x as f32),
        })
    }
}

/// (sin, cos) of the Earth's rotation in `dt_s`: an angle below 1e-3 rad for any
/// propagation the controller makes, where the series' next terms are below f32's
/// rounding.
#[inline(always)]
fn earth_turn(dt_s: f32) -> (f32, f32) {
    let a = EARTH_RATE_RAD_S as f32 * dt_s;
    (a, 1.0 - 0.5 * a * a)
}

/// x in I at t from x in I at t0, the Earth having turned by (sin, cos) in between:
/// R3(angle) x.
#[inline(always)]
fn to_later_itrf(x: [f32; 3], (s, c): (f32, f32)) -> [f32; 3] {
    [c * x[0] + s * x[1], c * x[1] - s * x[0], x[2]]
}

/// B exp([Omega]x dt): the camera's axes after turning at Omega for dt. With
/// a = Omega dt, th^2 = |a|^2: exp([a]x) = 1 + s [a]x + c [a]x^2, s = sin(th)/th,
/// c = (1 - cos th)/th^2, by their series to th^6 (the next terms, th^8/9! and
/// th^8/10!, are below 3e-9 up to th = 0.35 rad: the envelope's largest rate on every
/// axis for a second).
#[inline(always)]
fn turned(b: &[[f32; 3]; 3], omega: [f32; 3], dt_s: f32) -> [[f32; 3]; 3] {
    let a = omega.map(|w| w * dt_s);
    let t2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    let s = 1.0 - t2 * (1.0 / 6.0 - t2 * (1.0 / 120.0 - t2 * (1.0 / 5040.0)));
    let c = 0.5 - t2 * (1.0 / 24.0 - t2 * (1.0 / 720.0 - t2 * (1.0 / 40320.0)));
    // [a]x and [a]x^2 = a a^T - th^2 1.
    let k = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
    let e: [[f32; 3]; 3] = core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            let id = if i == j { 1.0 } else { 0.0 };
            let k2 = a[i] * a[j] - if i == j { t2 } else { 0.0 };
            id + s * k[i][j] + c * k2
        })
    });
    core::array::from_fn(|i| {
        core::array::from_fn(|j| b[i][0] * e[0][j] + b[i][1] * e[1][j] + b[i][2] * e[2][j])
    })
}

/// The satellite and the camera's axes in the ITRF of an update instant: what the DEM's
/// ground needs besides the general form's constants (a line of sight r + s B u).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ItrfFrame {
    /// r (m).
    pub position_m: [f32; 3],
    /// B, row-major: x_ITRF = B x_camera.
    pub camera_to_itrf: [[f32; 3]; 3],
}

/// The general form's per-instant constants at the update instant from the GNSS state
/// `dt_fix_s` after its fix and the attitude `dt_att_s` after its validity.
pub fn instant(
    gnss: &GnssState,
    attitude: &AttitudeState,
    dt_fix_s: f32,
    dt_att_s: f32,
) -> Result<GeneralInstant<f32>, ModelError> {
    instant_in_itrf(gnss, attitude, dt_fix_s, dt_att_s).map(|(i, _)| i)
}

/// [`instant`] with the satellite and the camera's axes in the ITRF of the instant.
#[inline(always)]
pub fn instant_in_itrf(
    gnss: &GnssState,
    attitude: &AttitudeState,
    dt_fix_s: f32,
    dt_att_s: f32,
) -> Result<(GeneralInstant<f32>, ItrfFrame), ModelError> {
    let state = gnss.propagator.parts_at(dt_fix_s);
    let turn = earth_turn(dt_fix_s);
    let b = turned(&attitude.camera_to_inertial, attitude.omega_rad_s, dt_att_s);
    let (s, c) = earth_turn(dt_att_s);
    // The columns of B (camera axes in I at the attitude's time) into I at t.
    let b_t: [[f32; 3]; 3] = [
        core::array::from_fn(|j| c * b[0][j] + s * b[1][j]),
        core::array::from_fn(|j| c * b[1][j] - s * b[0][j]),
        b[2],
    ];
    let position_m = to_later_itrf(state.position_m, turn);
    let instant = GENERAL_F32.instant_inertial_parts(
        position_m,
        to_later_itrf(state.velocity_mps, turn),
        // A turn about z changes no length.
        state.r2_minus_a2_m2,
        &InertialAttitude {
            camera_to_inertial: b_t,
            omega_rad_s: attitude.omega_rad_s,
        },
        EARTH_RATE_RAD_S as f32,
    )?;
    Ok((
        instant,
        ItrfFrame {
            position_m,
            camera_to_itrf: b_t,
        },
    ))
}

//! The satellite bus's data as the model's inputs (`shared/EARTH-MODEL.md`, Part II,
//! "Frames" and "Attitude from a quaternion and body rates"): a state vector in the
//! inertial frame of Part I, the ITRF or the GCRF; an attitude quaternion relative to
//! the GCRF or the ITRF with gyro body rates and the camera's mounting; all turned into
//! an [`InertialGeometry`]`<f64>`.
//! f64 and `libm` only, host and target alike.
//!
//! The inertial frame I is the ITRF frozen at `gps_s`, so:
//! - state `Inertial`: r_I = r, v_I = v; `Itrf`: r_I = r, v_I = v + w x r,
//!   w = (0, 0, earth_rate); `Gcrf`: r_I = C2T r, v_I = C2T v;
//! - camera axes B = C2T R(q) R(cam_q) (quaternion relative to the GCRF) or
//!   B = R(q) R(cam_q) (ITRF);
//! - Omega = R(cam_q)^T w_body (the camera's angular velocity relative to I in camera
//!   coordinates; the ITRF's own turning relative to inertial space is the Earth's rate
//!   that the model adds back through the Earth-fixed ground point).
//!
//! C2T is [`frames::c2t()`] (IAU 2006/2000B, within [`frames::C2T_TOLERANCE_RAD`] of
//! SOFA's `iauC2t06a`).

use crate::earth::frames::{self, Mat3, TimeScales};
use crate::earth::{Ellipsoid, InertialAttitude, InertialGeometry};
use crate::error::{ModelError, Param};
use crate::orbit::StateVector;
use crate::vector::{cross, scale};

/// Largest accepted | |q| - 1 | of a quaternion before it is normalised.
pub const MAX_QUATERNION_NORM_ERROR: f64 = 1.0e-3;

/// The identity quaternion (scalar first): the default camera mounting.
pub const IDENTITY_QUATERNION: [f64; 4] = [1.0, 0.0, 0.0, 0.0];

/// The frame a bus state vector is given in (the CSV's `frame`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StateFrame {
    /// Part I's inertial frame I (no conversion, no time needed).
    #[default]
    Inertial,
    /// The ITRF (GNSS receivers); needs no time either.
    Itrf,
    /// The GCRF; needs `gps_s` for C2T.
    Gcrf,
}

/// The frame an attitude quaternion is relative to (the CSV's `attitude_frame`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AttitudeFrame {
    /// The GCRF (star trackers; the contract's default); needs `gps_s` for C2T.
    #[default]
    Gcrf,
    /// The ITRF.
    Itrf,
}

/// A position and velocity as the bus gives them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BusState {
    pub frame: StateFrame,
    /// Position (m) and velocity (m/s) in `frame`.
    pub position_m: [f64; 3],
    pub velocity_mps: [f64; 3],
}

/// An attitude as the bus gives it: a quaternion, gyro rates, the camera's mounting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BusAttitude {
    /// `qw, qx, qy, qz`: scalar first, Hamilton; x_frame = R(q) x_body. Norm within
    /// [`MAX_QUATERNION_NORM_ERROR`] of 1; normalised before use.
    pub q: [f64; 4],
    pub frame: AttitudeFrame,
    /// The body's angular velocity relative to inertial space, in body coordinates
    /// (rad/s; the CSV's `wx_dps, wy_dps, wz_dps` are deg/s).
    pub body_rate_rad_s: [f64; 3],
    /// `cam_qw, cam_qx, cam_qy, cam_qz`: x_body = R(cam_q) x_camera
    /// ([`IDENTITY_QUATERNION`] by default); the same norm rule as `q`.
    pub camera_q: [f64; 4],
}

/// The time of the bus data: `gps_s` (seconds since 1980-01-06T00:00:00 GPS) where the
/// inputs need C2T, and the leap seconds and DUT1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BusTime {
    /// `None` when the bus gave no time: then a GCRF state or a GCRF quaternion is
    /// refused with [`ModelError::InvalidInput`]`(GpsTime)`.
    pub gps_s: Option<f64>,
    pub scales: TimeScales,
}

/// The rotation matrix of a unit quaternion q = (w, x, y, z), scalar first, Hamilton
/// convention (i j = k), active: v' = q v q* = R(q) v, i.e. R(q) maps the coordinates
/// of a vector in the rotated frame (body) to the reference frame:
///
/// ```text
/// R = [1 - 2(y^2 + z^2)   2(xy - wz)          2(xz + wy)
///      2(xy + wz)         1 - 2(x^2 + z^2)    2(yz - wx)
///      2(xz - wy)         2(yz + wx)          1 - 2(x^2 + y^2)]
/// ```
///
/// The quaternion is first checked (finite: [`ModelError::NonFinite`]`(param)`; norm
/// within [`MAX_QUATERNION_NORM_ERROR`] of 1: [`ModelError::InvalidQuaternion`]`(param)`)
/// and normalised, so the result is orthonormal to rounding. `param` names the input in
/// the refusal ([`Param::Quaternion`] or [`Param::CameraQuaternion`]). q and -q give the
/// same matrix.
pub fn quaternion_matrix(q: [f64; 4], param: Param) -> Result<Mat3, ModelError> {
    if !q.iter().all(|x| x.is_finite()) {
        return Err(ModelError::NonFinite(param));
    }
    let n = libm::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if !(libm::fabs(n - 1.0) <= MAX_QUATERNION_NORM_ERROR) {
        return Err(ModelError::InvalidQuaternion(param));
    }
    let [w, x, y, z] = q.map(|c| c / n);
    Ok([
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ])
}

/// The unit quaternion (w, x, y, z, scalar first) of a rotation matrix, the inverse of
/// [`quaternion_matrix`] up to the sign: Shepperd's choice of the largest of 4w^2,
/// 4x^2, 4y^2, 4z^2 (1 + trace, 1 + m00 - m11 - m22, ...), so that no division is by a
/// small number. For test generators and host tools; `m` orthonormal.
pub fn matrix_quaternion(m: &Mat3) -> [f64; 4] {
    let d = [m[0][0], m[1][1], m[2][2]];
    let t = [
        1.0 + d[0] + d[1] + d[2],
        1.0 + d[0] - d[1] - d[2],
        1.0 - d[0] + d[1] - d[2],
        1.0 - d[0] - d[1] + d[2],
    ];
    let k = (0..4).fold(0, |b, i| if t[i] > t[b] { i } else { b });
    let s = 0.5 / libm::sqrt(t[k]);
    let (x, y, z) = (m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]);
    let (xy, xz, yz) = (m[0][1] + m[1][0], m[0][2] + m[2][0], m[1][2] + m[2][1]);
    let q = match k {
        0 => [t[0], x, y, z],
        1 => [x, t[1], xy, xz],
        2 => [y, xy, t[2], yz],
        _ => [z, xz, yz, t[3]],
    };
    q.map(|c| c * s)
}

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    core::array::from_fn(|i| {
        core::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
    })
}

fn mat_vec(a: &Mat3, x: [f64; 3]) -> [f64; 3] {
    core::array::from_fn(|i| a[i][0] * x[0] + a[i][1] * x[1] + a[i][2] * x[2])
}

fn mat_t_vec(a: &Mat3, x: [f64; 3]) -> [f64; 3] {
    core::array::from_fn(|j| a[0][j] * x[0] + a[1][j] * x[1] + a[2][j] * x[2])
}

/// C2T at the bus time, refused without a time ([`ModelError::InvalidInput`]`(GpsTime)`).
fn c2t_at(time: &BusTime) -> Result<Mat3, ModelError> {
    match time.gps_s {
        Some(gps_s) => frames::c2t(gps_s, &time.scales),
        None => Err(ModelError::InvalidInput(Param::GpsTime)),
    }
}

/// The state vector in I from the bus's, given C2T where the frame is the GCRF.
fn state_with(
    s: &BusState,
    earth_rate_rad_s: f64,
    c2t: Option<&Mat3>,
) -> Result<StateVector, ModelError> {
    let (r, v) = (s.position_m, s.velocity_mps);
    if !r.iter().all(|x| x.is_finite()) {
        return Err(ModelError::NonFinite(Param::Position));
    }
    if !v.iter().all(|x| x.is_finite()) {
        return Err(ModelError::NonFinite(Param::Velocity));
    }
    let (position_m, velocity_mps) = match (s.frame, c2t) {
        (StateFrame::Inertial, _) => (r, v),
        (StateFrame::Itrf, _) => {
            let wxr = cross([0.0, 0.0, earth_rate_rad_s], r);
            (r, [v[0] + wxr[0], v[1] + wxr[1], v[2] + wxr[2]])
        }
        (StateFrame::Gcrf, Some(m)) => (mat_vec(m, r), mat_vec(m, v)),
        (StateFrame::Gcrf, None) => return Err(ModelError::InvalidInput(Param::GpsTime)),
    };
    Ok(StateVector {
        position_m,
        velocity_mps,
    })
}

/// The camera's attitude in I from the bus's, given C2T where the quaternion is
/// relative to the GCRF.
fn attitude_with(a: &BusAttitude, c2t: Option<&Mat3>) -> Result<InertialAttitude<f64>, ModelError> {
    let body = quaternion_matrix(a.q, Param::Quaternion)?;
    let mount = quaternion_matrix(a.camera_q, Param::CameraQuaternion)?;
    if !a.body_rate_rad_s.iter().all(|x| x.is_finite()) {
        return Err(ModelError::NonFinite(Param::BodyRate));
    }
    let camera_in_frame = mat_mul(&body, &mount);
    let camera_to_inertial = match (a.frame, c2t) {
        (AttitudeFrame::Itrf, _) => camera_in_frame,
        (AttitudeFrame::Gcrf, Some(m)) => mat_mul(m, &camera_in_frame),
        (AttitudeFrame::Gcrf, None) => return Err(ModelError::InvalidInput(Param::GpsTime)),
    };
    Ok(InertialAttitude {
        camera_to_inertial,
        omega_rad_s: mat_t_vec(&mount, a.body_rate_rad_s),
    })
}

/// The state vector in I (Part II, "Frames"). Refusals: a non-finite position or
/// velocity; a GCRF state without `gps_s` ([`ModelError::InvalidInput`]`(GpsTime)`);
/// those of [`frames::c2t()`].
pub fn inertial_state(
    state: &BusState,
    time: &BusTime,
    earth_rate_rad_s: f64,
) -> Result<StateVector, ModelError> {
    let c2t = match state.frame {
        StateFrame::Gcrf => Some(c2t_at(time)?),
        _ => None,
    };
    state_with(state, earth_rate_rad_s, c2t.as_ref())
}

/// The camera's axes in I and its angular velocity (Part II, "Attitude from a
/// quaternion and body rates"). Refusals: a non-finite or badly normed quaternion
/// ([`quaternion_matrix`]), non-finite body rates, a GCRF quaternion without `gps_s`,
/// those of [`frames::c2t()`].
pub fn inertial_attitude(
    attitude: &BusAttitude,
    time: &BusTime,
) -> Result<InertialAttitude<f64>, ModelError> {
    let c2t = match attitude.frame {
        AttitudeFrame::Gcrf => Some(c2t_at(time)?),
        AttitudeFrame::Itrf => None,
    };
    attitude_with(attitude, c2t.as_ref())
}

/// Whether the bus's data need C2T (a GCRF state or a GCRF quaternion), hence `gps_s`.
pub fn needs_c2t(state: &BusState, attitude: &BusAttitude) -> bool {
    state.frame == StateFrame::Gcrf || attitude.frame == AttitudeFrame::Gcrf
}

/// The whole geometry from the bus's data (C2T computed once, only if
/// [`needs_c2t`]), for the backends' Part II entry points. The result is then checked by
/// the backends as any geometry is (`check_inputs`, `validate`). Refusals: the
/// quaternions' ([`quaternion_matrix`]) first, then a missing `gps_s` where C2T is needed
/// ([`ModelError::InvalidInput`]`(GpsTime)`), those of [`frames::c2t()`], non-finite state
/// or body rates.
pub fn bus_geometry(
    state: &BusState,
    attitude: &BusAttitude,
    time: &BusTime,
    ground_h_m: f64,
    ellipsoid: Ellipsoid,
    earth_rate_rad_s: f64,
) -> Result<InertialGeometry<f64>, ModelError> {
    // The quaternions' checks come before the time's, so that a bad quaternion is
    // reported as such whatever else is missing.
    quaternion_matrix(attitude.q, Param::Quaternion)?;
    quaternion_matrix(attitude.camera_q, Param::CameraQuaternion)?;
    let c2t = if needs_c2t(state, attitude) {
        Some(c2t_at(time)?)
    } else {
        None
    };
    bus_geometry_with_c2t(
        state,
        attitude,
        c2t.as_ref(),
        ground_h_m,
        ellipsoid,
        earth_rate_rad_s,
    )
}

/// [`bus_geometry`] with C2T given (`None` where the data need none): for a caller that
/// has C2T already (one per update for several uses) and for tests against another C2T
/// (ERFA's). A GCRF input with `c2t` `None` is refused as missing time
/// ([`ModelError::InvalidInput`]`(GpsTime)`).
pub fn bus_geometry_with_c2t(
    state: &BusState,
    attitude: &BusAttitude,
    c2t: Option<&Mat3>,
    ground_h_m: f64,
    ellipsoid: Ellipsoid,
    earth_rate_rad_s: f64,
) -> Result<InertialGeometry<f64>, ModelError> {
    let attitude = attitude_with(attitude, c2t)?;
    Ok(InertialGeometry {
        state: state_with(state, earth_rate_rad_s, c2t)?,
        attitude,
        ground_h_m,
        ellipsoid,
        earth_rate_rad_s,
    })
}

/// Degrees per second to radians per second (for the CSV's `wx_dps, wy_dps, wz_dps`).
pub fn dps_to_rad_s(w_dps: [f64; 3]) -> [f64; 3] {
    scale(core::f64::consts::PI / 180.0, w_dps)
}

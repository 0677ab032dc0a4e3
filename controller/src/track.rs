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
//! The star tracker's quaternion is first blended with the attitude the gyros carried
//! from the last one ([`AttitudeBlend`]), and the attitude keeps, besides its rates, the
//! angular acceleration that constant roll, pitch and yaw rates relative to the orbital
//! frame imply ([`euler_accel`]): in a slew with yaw steering the camera's rates in its
//! own axes turn by 4e-5 rad/s^2, which a constant rate would carry as a period error
//! of up to 6e-4 by the end of an attitude period (docs/controller.md, "The attitude
//! between frames").
//!
//! What is done per update, in f32: the orbit's Taylor series ([`Propagator`]) to the
//! update instant, the attitude turned by its body rates and acceleration over the time
//! since its validity (B exp([Omega dt + dOmega/dt dt^2 / 2]x), a series in the rotation
//! vector; the next term of the rotation, Omega x dOmega/dt dt^3 / 12, is below 1e-10 rad
//! in an attitude period), and both frames
//! turned to the ITRF of the update instant: I at t is I at t0 turned about z by the
//! Earth's rotation in t - t0 (R3(w (t - t0)); over 2 s this angle is 1.5e-4 rad, and
//! ERA's own rate differs from `w` by 1e-8 of it, 1.5e-12 rad). No trigonometry.

use core_math::earth::bus::quaternion_matrix;
use core_math::earth::frames::{
    mat_mul, row_times as row_times_f64, CelestialPole, TimeScales, POLE_MAX_AGE_S,
};
use core_math::earth::{GeneralInstant, InertialAttitude};
use core_math::vector::dot;
use core_math::{ModelError, Param, StateVector, GENERAL_F32};

use crate::bus::{gps_s, Gnss, StarAttitude};
use crate::config::{AttitudeBlend, EARTH_RATE_RAD_S};
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
    /// dOmega/dt (rad/s^2, camera axes) if the roll, pitch and yaw relative to the
    /// orbital frame keep their rates ([`euler_accel`]); zero before the first fix.
    pub omega_accel_rad_s2: [f32; 3],
    /// The same in body axes, R(cam_q) dOmega/dt (rad/s^2): for the blend.
    pub body_accel_rad_s2: [f32; 3],
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

/// The quaternion's own check, before any blend: its norm within 1e-3 of one
/// (`bad_quaternion`), finite (`non_finite`).
pub fn check_quaternion(a: &StarAttitude) -> Result<(), Fault> {
    rotation(&a.q, Param::Quaternion).map(|_| ())
}

/// R(q) of an f32 quaternion (`param` the attitude's or the mounting's), with the
/// frame's refusals: `non_finite`, `bad_quaternion` for a norm off by more than 1e-3.
// Out of line: the check and the derivation's two held a copy each (docs/target.md,
// flash).
#[inline(never)]
fn rotation(q: &[f32; 4], param: Param) -> Result<[[f64; 3]; 3], Fault> {
    quaternion_matrix(q.map(f64::from), param).map_err(|e| match e {
        ModelError::NonFinite(_) => Fault::NonFinite,
        _ => Fault::BadQuaternion,
    })
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
        orbit: Option<&GnssState>,
    ) -> Result<AttitudeState, Fault> {
        let body = rotation(&a.q, Param::Quaternion)?;
        let mount = rotation(mounting_q, Param::CameraQuaternion)?;
        let c2t = pole
            .c2t(gps_s(a.valid_us), scales)
            .map_err(|_| Fault::FixTime)?;
        let b = mat_mul(&c2t, &mat_mul(&body, &mount));
        let w = a.body_rate_rad_s.map(f64::from);
        let omega = row_times_f64(&w, &mount);
        let (b, omega) = (rounded(&b), omega.map(|x| x as f32));
        // The orbit's state in I at the time of validity: the fix's carried over the
        // fix's age dt (at most `gnss_stale_after`, 2 s) by r + v dt - mu r dt^2 / (2 r^3),
        // v - mu r dt / r^3 (the next terms move the orbital frame's axes by below 1e-8
        // rad), its frame turned by the Earth's rotation since. The orbital frame's own
        // turn over a second (1.1e-3 rad) would otherwise move the acceleration's axes,
        // which in the default pass's roll slew is a 3e-6 period error.
        let accel = orbit.map_or([0.0; 3], |g| {
            let dt_s = ((a.valid_us as f64 - g.fix_us as f64) * 1e-6) as f32;
            let st = &g.propagator.state;
            let (r, v) = (
                st.position_m.map(|x| x as f32),
                st.velocity_mps.map(|x| x as f32),
            );
            let r2 = dot(r, r);
            let k = -(core_math::GM_M3_S2 as f32) / (r2 * core_math::sqrt_f32(r2));
            let carried: [(f32, f32); 3] = core::array::from_fn(|i| carry(r[i], v[i], k, dt_s));
            let r_t = carried.map(|c| c.0);
            let v_t = carried.map(|c| c.1);
            let s = EARTH_RATE_RAD_S as f32 * dt_s;
            let turn = |x: [f32; 3]| [x[0] + s * x[1], x[1] - s * x[0], x[2]];
            euler_accel(&b, omega, turn(r_t), turn(v_t))
        });
        let m = rounded(&mount);
        Ok(AttitudeState {
            received: *a,
            camera_to_inertial: b,
            omega_rad_s: omega,
            omega_accel_rad_s2: accel,
            body_accel_rad_s2: core::array::from_fn(|i| {
                m[i][0] * accel[0] + m[i][1] * accel[1] + m[i][2] * accel[2]
            }),
        })
    }
}

impl AttitudeBlend {
    /// Taken as it is: for a bus whose attitude is already filtered.
    pub const NONE: AttitudeBlend = AttitudeBlend {
        gain: 1.0,
        gate_rad: 0.0,
        max_gap_us: 0,
    };

    /// `new` blended with `last` carried to its time of validity at its body rates and
    /// their change `accel_rad_s2` (body axes) (in f32: the quaternions' rounding, 6e-8,
    /// is a thirtieth of the blended estimate's noise at a 4-arcsecond star tracker).
    /// `new` is later than `last` (the intake's checks).
    pub fn blend(
        &self,
        last: &StarAttitude,
        accel_rad_s2: [f32; 3],
        new: &StarAttitude,
    ) -> StarAttitude {
        let gap_us = new.valid_us.saturating_sub(last.valid_us);
        if !(self.gain < 1.0 && gap_us <= self.max_gap_us) {
            return *new;
        }
        let dt_s = gap_us as f32 * 1e-6;
        let (w, accel) = (last.body_rate_rad_s, accel_rad_s2);
        let turn: [f32; 3] = core::array::from_fn(|i| (w[i] + 0.5 * accel[i] * dt_s) * dt_s);
        let predicted = q_unit(q_mul(last.q, q_exp(turn)));
        let inverse = [predicted[0], -predicted[1], -predicted[2], -predicted[3]];
        let mut d = q_mul(inverse, q_unit(new.q));
        if d[0] < 0.0 {
            d = d.map(|x| -x);
        }
        let e = [2.0 * d[1], 2.0 * d[2], 2.0 * d[3]];
        if dot(e, e) > self.gate_rad * self.gate_rad {
            return *new;
        }
        StarAttitude {
            q: q_unit(q_mul(predicted, q_exp(e.map(|x| self.gain * x)))),
            ..*new
        }
    }
}

/// A matrix rounded to f32.
// Out of line: the derivation rounded two, each inlined.
#[inline(never)]
fn rounded(m: &[[f64; 3]; 3]) -> [[f32; 3]; 3] {
    m.map(|row| row.map(|x| x as f32))
}

/// One axis of the fix carried by `dt_s` in [`AttitudeState::derive`]: (r + v dt + k r
/// dt^2 / 2, v + k r dt). Out of line: the derivation unrolled it over the three axes
/// (docs/target.md, `m3-flash3`).
#[inline(never)]
fn carry(r: f32, v: f32, k: f32, dt_s: f32) -> (f32, f32) {
    (r + v * dt_s + 0.5 * k * r * dt_s * dt_s, v + k * r * dt_s)
}

/// Hamilton product.
fn q_mul(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

// Out of line on the M3, where each product is a software call: inlined, the
// frame's acceleration and blend held a copy at each use (docs/target.md, flash).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
fn q_unit(q: [f32; 4]) -> [f32; 4] {
    let n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    let inv = 1.0 / core_math::sqrt_f32(n2);
    q.map(|x| x * inv)
}

/// exp of the rotation vector `v` as a unit quaternion, cos(th/2) and sin(th/2)/th by
/// their series to th^4: the blend turns by at most the envelope's rate over
/// `max_gap_us` (0.35 rad/s over 0.5 s: th <= 0.18), where the next terms are below
/// 3e-9.
fn q_exp(v: [f32; 3]) -> [f32; 4] {
    let t2 = dot(v, v);
    let c = 1.0 - t2 / 8.0 * (1.0 - t2 / 48.0);
    let s = 0.5 * (1.0 - t2 / 24.0 * (1.0 - t2 / 80.0));
    [c, s * v[0], s * v[1], s * v[2]]
}

// Out of line on the M3, where each product is a software call: inlined, the
// frame's acceleration and blend held a copy at each use (docs/target.md, flash).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    core_math::vector::cross(a, b)
}

/// dOmega/dt (rad/s^2, camera axes) of a camera whose roll, pitch and yaw relative to
/// the orbital frame (Part I: A = Rx(roll) Ry(pitch) Rz(yaw), the frame's z along r, y
/// along r x v) keep their rates, from its axes `b` in I (x_I = b x_camera), its
/// angular velocity `omega` relative to I in its own axes and the orbit's r, v in I.
///
/// The orbital frame turns at W = r x v / |r|^2. Relative to it the camera turns at
/// Omega - W_c = w1 + w2 + w3 about the roll axis (the frame's x, fixed in it), the
/// pitch axis (z_c x x_c / cos(pitch)) and the yaw axis (the camera's z): a rate about
/// an axis that the later rotations carry turns with them, so in camera axes
/// d(w1)/dt = -(w2 + w3) x w1, d(w2)/dt = -w3 x w2; and W_c = b^T W turns at -Omega
/// while W itself changes with |r| (dW/dt = -2 (r.v) W / |r|^2 on the two-body orbit):
/// dOmega/dt = -(w2 + w3) x w1 - w3 x w2 - Omega x W_c + b^T dW/dt. Zero where the
/// pitch is within 0.6 deg of +-90 deg (the axes are then degenerate).
pub fn euler_accel(b: &[[f32; 3]; 3], omega: [f32; 3], r: [f32; 3], v: [f32; 3]) -> [f32; 3] {
    // b^T x: x^T b, the same products (each commutes exactly) summed in the same order;
    // on the M3 one out-of-line copy for both uses.
    let to_camera = |x: [f32; 3]| -> [f32; 3] { row_times(&x, b) };
    let h = cross(r, v);
    let (r2, h2) = (dot(r, r), dot(h, h));
    if !(r2 > 0.0 && h2 > 0.0) {
        return [0.0; 3];
    }
    let w_orbit = to_camera(h.map(|x| x / r2));
    // x of the orbital frame: (r x v) x r / (|r x v| |r|).
    let x_frame = to_camera(cross(h, r).map(|x| x / core_math::sqrt_f32(h2 * r2)));
    let z = [0.0, 0.0, 1.0];
    let pitch_axis = cross(z, x_frame);
    let relative: [f32; 3] = core::array::from_fn(|i| omega[i] - w_orbit[i]);
    // relative = a x_frame + p pitch_axis + y z, by Cramer's rule; the determinant is
    // cos(pitch)^2.
    let det = dot(x_frame, cross(pitch_axis, z));
    if libm::fabsf(det) < 1e-4 {
        return [0.0; 3];
    }
    let a = dot(relative, cross(pitch_axis, z)) / det;
    let p = dot(x_frame, cross(relative, z)) / det;
    let y = dot(x_frame, cross(pitch_axis, relative)) / det;
    let w1 = x_frame.map(|x| a * x);
    let w2 = pitch_axis.map(|x| p * x);
    let w3 = [0.0, 0.0, y];
    let t1 = cross([w2[0], w2[1], w2[2] + y], w1);
    let t2 = cross(w3, w2);
    let t3 = cross(omega, w_orbit);
    let shrink = -2.0 * dot(r, v) / r2;
    core::array::from_fn(|i| -t1[i] - t2[i] - t3[i] + shrink * w_orbit[i])
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

/// B exp([a]x): the camera's axes after turning at Omega + dOmega/dt t for dt. With
/// a = Omega dt + dOmega/dt dt^2 / 2, th^2 = |a|^2: exp([a]x) = 1 + s [a]x + c [a]x^2, s = sin(th)/th,
/// c = (1 - cos th)/th^2, by their series to th^6 (the next terms, th^8/9! and
/// th^8/10!, are below 3e-9 up to th = 0.35 rad: the envelope's largest rate on every
/// axis for a second).
#[inline(always)]
fn turned(b: &[[f32; 3]; 3], omega: [f32; 3], accel: [f32; 3], dt_s: f32) -> [[f32; 3]; 3] {
    let half_dt2 = 0.5 * dt_s * dt_s;
    let a: [f32; 3] = core::array::from_fn(|i| omega[i] * dt_s + accel[i] * half_dt2);
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
    core::array::from_fn(|i| row_times(&b[i], &e))
}

/// The row `r` times the matrix `e`.
// Out of line on the M3, where each product is a software call: the update's turn of
// the camera's axes inlined it for each row (docs/target.md, flash).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
#[cfg_attr(
    not(all(target_arch = "arm", not(target_abi = "eabihf"))),
    inline(always)
)]
fn row_times(r: &[f32; 3], e: &[[f32; 3]; 3]) -> [f32; 3] {
    core::array::from_fn(|j| r[0] * e[0][j] + r[1] * e[1][j] + r[2] * e[2][j])
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
    let b = turned(
        &attitude.camera_to_inertial,
        attitude.omega_rad_s,
        attitude.omega_accel_rad_s2,
        dt_att_s,
    );
    let omega_rad_s: [f32; 3] = core::array::from_fn(|i| {
        attitude.omega_rad_s[i] + attitude.omega_accel_rad_s2[i] * dt_att_s
    });
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
            omega_rad_s,
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

//! What a satellite bus sends, for the tests of the bus frames: a Kepler orbit in I (the
//! ITRF frozen at T0) seen as GNSS fixes in the ITRF of each instant, and a camera whose
//! axes turn at constant body rates ([`Bus`]) or whose roll, pitch and yaw relative to
//! the orbital frame keep constant rates ([`EulerBus`], Part I's attitude), seen as
//! GCRF star-tracker quaternions and gyro rates.

use controller::bus::{encode_time_scales, Gnss, StarAttitude};
use controller::frame::kind;
use controller::Scene;
use core_math::earth::bus::matrix_quaternion;
use core_math::earth::frames::{self, Mat3, TimeScales};
use core_math::earth::kepler::Kepler;
use core_math::earth::{Attitude, EarthGeometry, InertialGeometry};
use core_math::{Ellipsoid, StateVector, EARTH_RATE_RAD_S, GM_M3_S2};

use super::frame;

/// 2026-12 in GPS time (us since 1980-01-06).
pub const T0_US: u64 = 1_480_000_000_000_000;
pub const SCALES: TimeScales = TimeScales {
    gps_utc_s: 18.0,
    dut1_s: 0.125,
};

pub fn secs(us: u64) -> f64 {
    us as f64 * 1e-6
}

pub fn mul(a: &Mat3, b: &Mat3) -> Mat3 {
    core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

pub fn transpose(a: &Mat3) -> Mat3 {
    core::array::from_fn(|i| core::array::from_fn(|j| a[j][i]))
}

pub struct Bus {
    pub kepler: Kepler,
    q0: [f64; 4],
    /// When the first attitude is valid.
    pub valid0_us: u64,
    body_rate_rad_s: [f64; 3],
    /// The state and the camera's axes in I at T0 (Part I's geometry).
    pub geometry: InertialGeometry<f64>,
}

impl Bus {
    /// The orbit and camera of `geometry` at T0; the body carries the camera turned by
    /// `mounting` (camera axes in body axes); the camera turns at `geometry`'s angular
    /// velocity plus `slew_rad_s` (camera axes), as constant body rates.
    pub fn new(
        geometry: InertialGeometry<f64>,
        mounting: &Mat3,
        slew_rad_s: [f64; 3],
        valid0_us: u64,
    ) -> Bus {
        let s = geometry.state;
        let kepler = Kepler::new(s.position_m, s.velocity_mps, GM_M3_S2).unwrap();
        // I at T0 to the GCRF: C2T(T0)^T; body = GCRF-from-camera R(mounting)^T.
        let c2t = frames::c2t(secs(T0_US), &SCALES).unwrap();
        let body = mul(
            &mul(&transpose(&c2t), &geometry.attitude.camera_to_inertial),
            &transpose(mounting),
        );
        let o = geometry.attitude.omega_rad_s;
        let omega: [f64; 3] = core::array::from_fn(|i| o[i] + slew_rad_s[i]);
        let w = core::array::from_fn(|i| (0..3).map(|k| mounting[i][k] * omega[k]).sum());
        Bus {
            kepler,
            q0: matrix_quaternion(&body),
            valid0_us,
            body_rate_rad_s: w,
            geometry,
        }
    }

    /// The GNSS fix at `fix_us`: the Kepler state turned into the ITRF of that instant
    /// (the Earth's turn since T0 about z; precession over seconds is below 1e-11).
    pub fn gnss(&self, fix_us: u64) -> Gnss {
        let dt = secs(fix_us) - secs(T0_US);
        let s = self.kepler.state_at(dt);
        let (r, v) = (s.position_m, s.velocity_mps);
        let a = EARTH_RATE_RAD_S * dt;
        let (s, c) = (a.sin(), a.cos());
        let rot = |x: [f64; 3]| [c * x[0] + s * x[1], c * x[1] - s * x[0], x[2]];
        let (r, v) = (rot(r), rot(v));
        let w = EARTH_RATE_RAD_S;
        Gnss {
            fix_us,
            position_m: r,
            velocity_mps: [v[0] + w * r[1], v[1] - w * r[0], v[2]],
        }
    }

    /// The attitude at `valid_us`: q0 turned at the body rates since its validity.
    pub fn attitude(&self, valid_us: u64) -> StarAttitude {
        let w = self.body_rate_rad_s;
        let rate = (w.iter().map(|x| x * x).sum::<f64>()).sqrt();
        let half = 0.5 * rate * (secs(valid_us) - secs(self.valid0_us));
        let e = [
            half.cos(),
            half.sin() * w[0] / rate,
            half.sin() * w[1] / rate,
            half.sin() * w[2] / rate,
        ];
        let q = self.q0;
        let p = [
            q[0] * e[0] - q[1] * e[1] - q[2] * e[2] - q[3] * e[3],
            q[0] * e[1] + q[1] * e[0] + q[2] * e[3] - q[3] * e[2],
            q[0] * e[2] - q[1] * e[3] + q[2] * e[0] + q[3] * e[1],
            q[0] * e[3] + q[1] * e[2] - q[2] * e[1] + q[3] * e[0],
        ];
        StarAttitude {
            valid_us,
            q: p.map(|x| x as f32),
            body_rate_rad_s: w.map(|x| x as f32),
        }
    }
}

pub fn gnss_frame(seq: u16, tag_us: u64, g: &Gnss) -> Vec<u8> {
    let mut p = [0u8; 64];
    let n = g.encode(&mut p).unwrap();
    frame(kind::GNSS, seq, tag_us, &p[..n])
}

pub fn attitude_frame(seq: u16, tag_us: u64, a: &StarAttitude) -> Vec<u8> {
    let mut p = [0u8; 64];
    let n = a.encode(&mut p).unwrap();
    frame(kind::ATTITUDE, seq, tag_us, &p[..n])
}

pub fn scales_frame(seq: u16, tag_us: u64, leap_s: i16, dut1_s: f32) -> Vec<u8> {
    let mut p = [0u8; 8];
    let n = encode_time_scales(leap_s, dut1_s, &mut p).unwrap();
    frame(kind::TIME_SCALES, seq, tag_us, &p[..n])
}

pub fn scene_frame(seq: u16, tag_us: u64, s: &Scene) -> Vec<u8> {
    let mut p = [0u8; 512];
    let n = s.encode(&mut p).unwrap();
    frame(kind::SCENE, seq, tag_us, &p[..n])
}

/// Hamilton product.
pub fn q_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The angle (rad) between two attitudes given as quaternions.
pub fn angle_between(a: [f64; 4], b: [f64; 4]) -> f64 {
    let d = q_mul([a[0], -a[1], -a[2], -a[3]], b);
    let v = (d[1] * d[1] + d[2] * d[2] + d[3] * d[3]).sqrt();
    2.0 * v.atan2(d[0].abs())
}

/// A camera whose roll, pitch and yaw relative to the orbital frame keep constant
/// rates from T0 (Part I's attitude, `EarthGeometry::to_inertial`, at every instant of
/// the Kepler orbit), carried by a body turned by `mounting`.
pub struct EulerBus {
    pub bus: Bus,
    pub attitude: Attitude<f64>,
    pub mounting_q: [f64; 4],
    mounting: Mat3,
    c2t0: Mat3,
}

impl EulerBus {
    pub fn new(state: StateVector, attitude: Attitude<f64>, mounting_q: [f64; 4]) -> EulerBus {
        let geometry = EulerBus::geometry_of(state, attitude);
        let mounting = core_math::earth::bus::quaternion_matrix(
            mounting_q,
            core_math::Param::CameraQuaternion,
        )
        .unwrap();
        EulerBus {
            bus: Bus::new(geometry, &mounting, [0.0; 3], T0_US),
            attitude,
            mounting_q,
            mounting,
            c2t0: frames::c2t(secs(T0_US), &SCALES).unwrap(),
        }
    }

    pub fn geometry_of(state: StateVector, attitude: Attitude<f64>) -> InertialGeometry<f64> {
        EarthGeometry {
            state,
            attitude,
            ground_h_m: 0.0,
            ellipsoid: Ellipsoid::WGS84,
            earth_rate_rad_s: EARTH_RATE_RAD_S,
        }
        .to_inertial()
        .unwrap()
    }

    /// The body's exact GCRF quaternion and body rates at `valid_us` (f64).
    pub fn exact(&self, valid_us: u64) -> ([f64; 4], [f64; 3]) {
        let dt = secs(valid_us) - secs(T0_US);
        let a = self.attitude;
        let at = Attitude {
            roll_rad: a.roll_rad + a.roll_rate_rad_s * dt,
            pitch_rad: a.pitch_rad + a.pitch_rate_rad_s * dt,
            yaw_rad: a.yaw_rad + a.yaw_rate_rad_s * dt,
            ..a
        };
        let g = EulerBus::geometry_of(self.bus.kepler.state_at(dt), at);
        let body = mul(
            &mul(&transpose(&self.c2t0), &g.attitude.camera_to_inertial),
            &transpose(&self.mounting),
        );
        let o = g.attitude.omega_rad_s;
        let m = &self.mounting;
        let w = core::array::from_fn(|i| (0..3).map(|k| m[i][k] * o[k]).sum());
        (matrix_quaternion(&body), w)
    }

    /// The star tracker's frame at `valid_us`: the exact attitude turned by `error_rad`
    /// (a rotation vector, body axes), rounded to f32.
    pub fn attitude(&self, valid_us: u64, error_rad: [f64; 3]) -> StarAttitude {
        let (q, w) = self.exact(valid_us);
        let e = error_rad;
        let q = q_mul(q, [1.0, 0.5 * e[0], 0.5 * e[1], 0.5 * e[2]]);
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        StarAttitude {
            valid_us,
            q: q.map(|x| (x / n) as f32),
            body_rate_rad_s: w.map(|x| x as f32),
        }
    }
}

//! A controller primed with one synthetic NAV frame, or with the bus's GNSS and
//! ATTITUDE frames of the same instant, for the binaries that run without a telemetry
//! link: the default-scene demo and the benchmark.
//!
//! The frame goes through the same encoder, decoder and `Controller::on_frame` as a
//! frame from the UART, so the demo exercises the flight path from the frame on.

use core::convert::Infallible;
use core::hint::black_box;

use controller::bus::{Gnss, StarAttitude};
use controller::frame::{encode, kind, Decoder, Event, MAX_FRAME};
use controller::nav::{Attitude, Nav};
use controller::{Controller, LinePeriodSink};
use core_math::earth::frames::{self, Mat3, TimeScales};
use core_math::earth::EarthGeometry;
use core_math::StateVector;

use crate::board;
use crate::FirmwareError;

/// Orbit of the synthetic frame: 645 km over the equatorial radius of WGS 84, circular,
/// i0 97.98 deg, argument of latitude 0.5 rad.
const ALTITUDE_M: f64 = 645e3;
const INCLINATION_DEG: f64 = 97.98;
const ARG_LATITUDE_RAD: f64 = 0.5;

/// Period registers that keep nothing (the periods stay readable in
/// `Controller::outputs`); `black_box` so that a benchmark cannot drop the writes.
pub struct NoRegisters;

impl LinePeriodSink for NoRegisters {
    type Error = Infallible;
    fn write_period(&mut self, _index: u8, ticks: u32) -> Result<(), Infallible> {
        black_box(ticks);
        Ok(())
    }
}

/// A controller for `scene` (with the plan the scene needs, or `exhaustive`: every
/// segment, the most samples) holding one accepted NAV frame at t = 1 s with
/// `attitude`.
pub fn controller_with_nav(
    scene: controller::Scene,
    exhaustive: bool,
    attitude: Attitude<f32>,
) -> Result<Controller, FirmwareError> {
    let config = board::controller_config();
    let c = if exhaustive {
        Controller::evaluate_everything(config, scene)
    } else {
        Controller::new(config, scene)
    };
    let mut c = c.map_err(|_| FirmwareError::Layout)?;
    let state = orbit();
    let mut payload = [0u8; 96];
    let n = Nav { state, attitude }
        .encode(&mut payload)
        .ok_or(FirmwareError::Layout)?;
    let mut frame = [0u8; MAX_FRAME];
    let len = encode(
        kind::NAV,
        1,
        1_000_000,
        payload.get(..n).ok_or(FirmwareError::Layout)?,
        &mut frame,
    )
    .ok_or(FirmwareError::Layout)?;
    feed(&mut c, frame.get(..len).ok_or(FirmwareError::Layout)?);
    if c.nav().is_none() {
        return Err(FirmwareError::Telemetry);
    }
    Ok(c)
}

/// The synthetic orbit's state at its epoch (ECI of date, or the ITRF frozen then).
pub fn orbit() -> StateVector {
    let r_m = controller::EARTH.a_m + ALTITUDE_M;
    let (i0, u) = (INCLINATION_DEG.to_radians(), ARG_LATITUDE_RAD);
    let speed = libm::sqrt(core_math::GM_M3_S2 / r_m);
    let (si, ci, su, cu) = (libm::sin(i0), libm::cos(i0), libm::sin(u), libm::cos(u));
    StateVector {
        position_m: [r_m * cu, r_m * su * ci, r_m * su * si],
        velocity_mps: [-speed * su, speed * cu * ci, speed * cu * si],
    }
}

fn feed(c: &mut Controller, bytes: &[u8]) {
    let mut decoder = Decoder::new();
    decoder.feed(bytes, |e| {
        if let Event::Frame(f) = e {
            c.on_frame(&f);
        }
    });
}

/// GPS time of the bus frames' instant (us since 1980-01-06): 2026-12.
pub const BUS_EPOCH_US: u64 = 1_480_000_000_000_000;

/// A controller for `scene` holding the bus's view of [`controller_with_nav`]'s
/// instant: a GNSS fix at [`BUS_EPOCH_US`] (the orbit taken as the ITRF frozen then),
/// and an attitude valid 50 ms later whose quaternion puts the camera at `attitude`
/// relative to the orbital frame, with the body rates of that attitude (the mounting
/// the scene's). The default time scales.
pub fn controller_with_bus(
    scene: controller::Scene,
    attitude: Attitude<f32>,
) -> Result<Controller, FirmwareError> {
    let mut c =
        Controller::new(board::controller_config(), scene).map_err(|_| FirmwareError::Layout)?;
    let state = orbit();
    let w = core_math::EARTH_RATE_RAD_S;
    let (r, v) = (state.position_m, state.velocity_mps);
    let gnss = Gnss {
        fix_us: BUS_EPOCH_US,
        position_m: r,
        velocity_mps: [v[0] + w * r[1], v[1] - w * r[0], v[2]],
    };
    let valid_us = BUS_EPOCH_US + 50_000;
    let inertial = EarthGeometry {
        state,
        attitude: attitude.to_f64(),
        ground_h_m: 0.0,
        ellipsoid: controller::EARTH,
        earth_rate_rad_s: w,
    }
    .to_inertial()
    .map_err(|_| FirmwareError::Layout)?;
    // The quaternion of the body in the GCRF: C2T^T B (mounting the identity; the
    // 50 ms between the fix and the attitude turn nothing that matters to a benchmark).
    let c2t = frames::c2t(controller::bus::gps_s(valid_us), &TimeScales::DEFAULT)
        .map_err(|_| FirmwareError::Layout)?;
    let b = inertial.attitude.camera_to_inertial;
    let body: Mat3 = core::array::from_fn(|i| {
        core::array::from_fn(|j| c2t[0][i] * b[0][j] + c2t[1][i] * b[1][j] + c2t[2][i] * b[2][j])
    });
    let star = StarAttitude {
        valid_us,
        q: quaternion_of(&body).map(|x| x as f32),
        body_rate_rad_s: inertial.attitude.omega_rad_s.map(|x| x as f32),
    };
    let mut payload = [0u8; 64];
    let mut frame = [0u8; MAX_FRAME];
    let n = gnss.encode(&mut payload).ok_or(FirmwareError::Layout)?;
    let tag = BUS_EPOCH_US + 60_000;
    let p = payload.get(..n).ok_or(FirmwareError::Layout)?;
    let len = encode(kind::GNSS, 1, tag, p, &mut frame).ok_or(FirmwareError::Layout)?;
    feed(&mut c, frame.get(..len).ok_or(FirmwareError::Layout)?);
    let n = star.encode(&mut payload).ok_or(FirmwareError::Layout)?;
    let p = payload.get(..n).ok_or(FirmwareError::Layout)?;
    let len = encode(kind::ATTITUDE, 2, tag + 1, p, &mut frame).ok_or(FirmwareError::Layout)?;
    feed(&mut c, frame.get(..len).ok_or(FirmwareError::Layout)?);
    if c.gnss().is_none() || c.bus_attitude().is_none() {
        return Err(FirmwareError::Telemetry);
    }
    Ok(c)
}

/// A rotation matrix's quaternion, scalar first (Shepperd: from its largest component).
fn quaternion_of(m: &Mat3) -> [f64; 4] {
    let tr = m[0][0] + m[1][1] + m[2][2];
    if tr > 0.0 {
        let s = 2.0 * libm::sqrt(1.0 + tr);
        [
            0.25 * s,
            (m[2][1] - m[1][2]) / s,
            (m[0][2] - m[2][0]) / s,
            (m[1][0] - m[0][1]) / s,
        ]
    } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
        let s = 2.0 * libm::sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]);
        [
            (m[2][1] - m[1][2]) / s,
            0.25 * s,
            (m[0][1] + m[1][0]) / s,
            (m[0][2] + m[2][0]) / s,
        ]
    } else if m[1][1] > m[2][2] {
        let s = 2.0 * libm::sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]);
        [
            (m[0][2] - m[2][0]) / s,
            (m[0][1] + m[1][0]) / s,
            0.25 * s,
            (m[1][2] + m[2][1]) / s,
        ]
    } else {
        let s = 2.0 * libm::sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]);
        [
            (m[1][0] - m[0][1]) / s,
            (m[0][2] + m[2][0]) / s,
            (m[1][2] + m[2][1]) / s,
            0.25 * s,
        ]
    }
}

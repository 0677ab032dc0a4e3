//! A controller primed with one synthetic NAV frame, for the binaries that run without
//! a telemetry link: the default-scene demo and the benchmark.
//!
//! The frame goes through the same encoder, decoder and `Controller::on_frame` as a
//! frame from the UART, so the demo exercises the flight path from the frame on.

use core::convert::Infallible;
use core::hint::black_box;

use controller::frame::{encode, kind, Decoder, Event, MAX_FRAME};
use controller::nav::{Attitude, Nav};
use controller::{Config, Controller, LinePeriodSink};
use core_math::StateVector;

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
    let config = Config::default();
    let c = if exhaustive {
        Controller::evaluate_everything(config, scene)
    } else {
        Controller::new(config, scene)
    };
    let mut c = c.map_err(|_| FirmwareError::Layout)?;
    let r_m = controller::EARTH.a_m + ALTITUDE_M;
    let (i0, u) = (INCLINATION_DEG.to_radians(), ARG_LATITUDE_RAD);
    let speed = libm::sqrt(core_math::GM_M3_S2 / r_m);
    let (si, ci, su, cu) = (libm::sin(i0), libm::cos(i0), libm::sin(u), libm::cos(u));
    let state = StateVector {
        position_m: [r_m * cu, r_m * su * ci, r_m * su * si],
        velocity_mps: [-speed * su, speed * cu * ci, speed * cu * si],
    };
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
    let mut decoder = Decoder::new();
    decoder.feed(frame.get(..len).ok_or(FirmwareError::Layout)?, |e| {
        if let Event::Frame(f) = e {
            c.on_frame(&f);
        }
    });
    if c.nav().is_none() {
        return Err(FirmwareError::Telemetry);
    }
    Ok(c)
}

//! Shared by the controller tests: frames built from a circular orbit.
#![allow(dead_code)]

use std::convert::Infallible;

pub mod bus;

use controller::frame::{encode, kind, Decoder, Event, MAX_FRAME};
use controller::nav::{Attitude, Nav};
use controller::report::{encode_periods, Periods};
use controller::{Controller, Fault};
use core_math::{StateVector, GM_M3_S2};

pub const R: f64 = 6_371_000.0;

/// ECI state on a circular orbit (node longitude 0.4 rad) at argument of latitude `u`.
pub fn state(i: f64, u: f64, h: f64) -> StateVector {
    let a = R + h;
    let speed = libm::sqrt(GM_M3_S2 / a);
    let (si, ci) = (libm::sin(i), libm::cos(i));
    let (su, cu) = (libm::sin(u), libm::cos(u));
    let (sn, cn) = (libm::sin(0.4), libm::cos(0.4));
    // In-plane unit vectors: node direction and 90 deg ahead.
    let p = [cn, sn, 0.0];
    let q = [-sn * ci, cn * ci, si];
    let r: [f64; 3] = core::array::from_fn(|k| a * (cu * p[k] + su * q[k]));
    let v: [f64; 3] = core::array::from_fn(|k| speed * (-su * p[k] + cu * q[k]));
    StateVector {
        position_m: r,
        velocity_mps: v,
    }
}

pub fn nav_frame(seq: u16, time_us: u64, sv: StateVector, attitude: Attitude<f32>) -> Vec<u8> {
    let mut payload = [0u8; 128];
    let n = Nav {
        state: sv,
        attitude,
    }
    .encode(&mut payload)
    .unwrap();
    let mut buf = [0u8; MAX_FRAME];
    let len = encode(kind::NAV, seq, time_us, &payload[..n], &mut buf).unwrap();
    buf[..len].to_vec()
}

pub fn roll(rad: f32) -> Attitude<f32> {
    Attitude {
        roll_rad: rad,
        ..Attitude::default()
    }
}

/// A period sink that takes every write.
pub struct Accept;

impl controller::LinePeriodSink for Accept {
    type Error = Infallible;
    fn write_period(&mut self, _index: u8, _ticks: u32) -> Result<(), Infallible> {
        Ok(())
    }
}

/// One frame of `kind`, as the ground would send it.
pub fn frame(kind: u8, seq: u16, time_us: u64, payload: &[u8]) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(kind, seq, time_us, payload, &mut buf).unwrap();
    buf[..n].to_vec()
}

/// The orbit the controller tests fly: inclination (deg) and altitude (m).
pub const I0: f64 = 97.98;
pub const H: f64 = 645e3;

/// Feeds bytes through a fresh decoder into the controller, counting rejections.
pub fn feed(c: &mut Controller, bytes: &[u8]) {
    let mut d = Decoder::new();
    d.feed(bytes, |e| match e {
        Event::Frame(f) => c.on_frame(&f),
        Event::Rejected(r) => c.reject(Fault::from(r)),
    });
}

/// A period sink that records every write (segment index, ticks).
#[derive(Default)]
pub struct Registers {
    pub writes: Vec<(u8, u32)>,
}

impl controller::LinePeriodSink for Registers {
    type Error = Infallible;
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), Infallible> {
        self.writes.push((index, ticks));
        Ok(())
    }
}

/// The PERIODS frame the controller would send now, decoded.
pub fn periods(c: &Controller) -> Periods {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_periods(c, &mut buf).unwrap();
    Periods::decode(&buf[..n]).unwrap()
}

//! The host side of the checks: the twin run (the same `controller` crate, same
//! `Session`, on the host), the downlink decoder, the reference periods.

use anyhow::{anyhow, Result};
use std::collections::BTreeMap;
use std::convert::Infallible;

use controller::frame::{kind, Decoder, Event};
use controller::golden::NavInput;
use controller::report::{Periods, Status};
use controller::session::Session;
use controller::{Config, Controller, LinePeriodSink, Scene};

/// What a run (firmware or twin) sent to the ground.
#[derive(Default)]
pub struct Downlink {
    /// PERIODS payloads by update instant (us), in arrival order.
    pub periods: Vec<(u64, Vec<u8>)>,
    /// STATUS frames: time tag and content.
    pub status: Vec<(u64, Status)>,
    /// Frames the host decoder refused, and frames of unknown kind or content.
    pub bad_frames: u32,
    /// Bytes between frames (none expected).
    pub skipped_bytes: u32,
}

impl Downlink {
    pub fn decode(bytes: &[u8]) -> Downlink {
        let mut d = Downlink::default();
        let mut decoder = Decoder::new();
        decoder.feed(bytes, |e| match e {
            Event::Frame(f) if f.kind == kind::PERIODS && Periods::decode(f.payload).is_some() => {
                d.periods.push((f.time_us, f.payload.to_vec()))
            }
            Event::Frame(f) if f.kind == kind::STATUS => match Status::decode(f.payload) {
                Some(s) => d.status.push((f.time_us, s)),
                None => d.bad_frames += 1,
            },
            _ => d.bad_frames += 1,
        });
        d.skipped_bytes = decoder.skipped_bytes;
        d
    }

    pub fn final_status(&self) -> Option<&Status> {
        self.status.last().map(|(_, s)| s)
    }

    /// The decoded PERIODS records, by update instant.
    pub fn decoded(&self) -> Vec<(u64, Periods)> {
        self.periods
            .iter()
            .filter_map(|(t, p)| Periods::decode(p).map(|p| (*t, p)))
            .collect()
    }
}

/// A sink that accepts everything (the twin has no registers).
pub struct Accept;

impl LinePeriodSink for Accept {
    type Error = Infallible;
    fn write_period(&mut self, _index: u8, _ticks: u32) -> Result<(), Infallible> {
        Ok(())
    }
}

/// The controller the firmware runs after power-on (same config, same boot scene, the
/// boot it notes for STATUS).
pub fn new_controller(config: Config) -> Result<Controller> {
    let mut c = Controller::new(config, Scene::paper_default())
        .map_err(|f| anyhow!("the default scene was refused: {}", f.name()))?;
    c.note_boot(controller::restart::ResetCause::PowerOn, 0);
    Ok(c)
}

/// What the controller had in force at one update: the NAV frame and the ground heights.
#[derive(Clone, Debug)]
pub struct InForce {
    pub nav: NavInput,
    pub heights_m: Vec<f32>,
}

/// A host run of `bytes` through a `Session`, as the firmware does, byte by byte.
/// Also returns the NAV frame and terrain in force at each update (the inputs of the
/// reference check).
pub fn twin(bytes: &[u8], config: Config) -> Result<(Downlink, BTreeMap<u64, InForce>)> {
    let mut session = Session::new(new_controller(config)?);
    let mut out = Vec::new();
    let mut inputs = BTreeMap::new();
    for &b in bytes {
        let mut periods_sent = false;
        let ended = session.feed(&[b], &mut Accept, |frame| {
            periods_sent |= frame.get(3) == Some(&kind::PERIODS);
            out.extend_from_slice(frame);
        });
        if periods_sent {
            let c = &session.controller;
            if let (Some(nav), Some(t)) = (c.nav(), c.last_update_us()) {
                inputs.insert(
                    t,
                    InForce {
                        nav: NavInput {
                            state: nav.propagator.state,
                            attitude: nav.attitude,
                            time_us: nav.time_us,
                        },
                        heights_m: c.heights_m().to_vec(),
                    },
                );
            }
        }
        if ended {
            break;
        }
    }
    Ok((Downlink::decode(&out), inputs))
}

/// Relative tolerance of the f32 general form against the reference (the rounding to
/// whole ticks, 0.5 / ticks, comes on top): core_math::accuracy's
/// EARTH_F32_REL_TOLERANCE is 2e-6 of |v1| at the envelope's worst conditioning; the
/// issue's 1e-6 holds for the pass's conditions, and is what is checked.
pub const F32_REL_TOLERANCE: f64 = 1e-6;

/// What the fixed-point pixels (the mps2-an385's) add to it: the real-Earth fixed-point
/// backend's target from 1 deg of the limb outward, which its error bound and survey
/// meet (docs/fixed-point.md, "The error bound").
pub const EARTH_FIXED_REL_TOLERANCE: f64 = 2e-6;

//! The host side of the checks: the twin run (the same `controller` crate, same
//! `Session`, on the host), the downlink decoder, the reference periods.

use std::collections::BTreeMap;

use controller::control::NavState;
use controller::frame::{kind, Decoder, Event};
use controller::report::{Periods, Status};
use controller::session::Session;
use controller::{Config, Controller, LinePeriodSink, Scene};
use core_math::{Backend, Geometry, Reference, EARTH_RATE_RAD_S};

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
struct Accept;

impl LinePeriodSink for Accept {
    type Error = ();
    fn write_period(&mut self, _index: u8, _ticks: u32) -> Result<(), ()> {
        Ok(())
    }
}

/// The controller the firmware runs (same config, same boot scene).
pub fn new_controller() -> Result<Controller, String> {
    Controller::new(Config::default(), Scene::paper_default())
        .map_err(|f| format!("the default scene was refused: {}", f.name()))
}

/// A host run of `bytes` through a `Session`, as the firmware does, byte by byte.
/// Also returns the NAV state in force at each update (for the reference check of a
/// user's telemetry).
pub fn twin(bytes: &[u8]) -> Result<(Downlink, BTreeMap<u64, NavState>), String> {
    let mut session = Session::new(new_controller()?);
    let mut out = Vec::new();
    let mut navs = BTreeMap::new();
    for &b in bytes {
        let mut periods_sent = false;
        let ended = session.feed(&[b], &mut Accept, |frame| {
            periods_sent |= frame.get(3) == Some(&kind::PERIODS);
            out.extend_from_slice(frame);
        });
        if periods_sent {
            if let Some(nav) = session.controller.nav() {
                let now = session.controller.now_us();
                let t = now - now % session.controller.config.update_period_us.max(1);
                navs.insert(t, *nav);
            }
        }
        if ended {
            break;
        }
    }
    Ok((Downlink::decode(&out), navs))
}

/// The f64 geometry of the controller's own propagation of `nav` to `t_us`.
pub fn propagated(nav: &NavState, t_us: u64, earth_radius_m: f64) -> Geometry<f64> {
    let dt = (t_us as f64 - nav.time_us as f64) * 1e-6;
    let o = nav.orbit;
    Geometry {
        roll_rad: f64::from(nav.attitude.roll_rad) + f64::from(nav.attitude.roll_rate_rad_s) * dt,
        inclination_rad: o.inclination_rad,
        arg_latitude_rad: o.arg_latitude_rad + o.orbit_rate_rad_s * dt,
        altitude_m: o.altitude_m,
        earth_radius_m,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
        orbit_rate_rad_s: o.orbit_rate_rad_s,
    }
}

/// Reference periods for the plan of the default scene: per segment (by index) the
/// pixel offsets the plan samples, each with its f64 reference pixel constants.
pub struct ReferencePlan {
    segments: Vec<(u8, Vec<<Reference as Backend>::Pixel>)>,
    camera: core_math::Camera,
    line_clock_hz: f64,
}

impl ReferencePlan {
    pub fn new(controller: &Controller) -> Result<ReferencePlan, String> {
        let scene = controller.scene();
        let mut segments = Vec::new();
        for seg in controller.plan().active() {
            let px = &seg.sample_px[..usize::from(seg.n_samples)];
            let pixels = px
                .iter()
                .map(|&n| Reference.pixel(&scene.camera, f64::from(n)))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| format!("reference pixel: {}", e.name()))?;
            segments.push((seg.index, pixels));
        }
        Ok(ReferencePlan {
            segments,
            camera: scene.camera,
            line_clock_hz: scene.line_clock_hz,
        })
    }

    /// The exact (unrounded) period in ticks of every segment at `g`: |v| at the plan's
    /// samples from the f64 reference, period A (1/v_min + 1/v_max) / 2.
    pub fn ticks(&self, g: &Geometry<f64>) -> Result<BTreeMap<u8, f64>, String> {
        let update = Reference
            .update(g)
            .map_err(|e| format!("reference update: {}", e.name()))?;
        let mut out = BTreeMap::new();
        for (index, pixels) in &self.segments {
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            for p in pixels {
                let v = Reference
                    .motion(&update, p)
                    .map_err(|e| format!("reference motion: {}", e.name()))?
                    .speed_mps();
                lo = lo.min(v);
                hi = hi.max(v);
            }
            let a = self.camera.pixel_m;
            out.insert(*index, 0.5 * (a / lo + a / hi) * self.line_clock_hz);
        }
        Ok(out)
    }
}

/// Relative tolerance of the f32 closed form against the reference (the rounding to
/// whole ticks, 0.5 / ticks, comes on top).
pub const F32_REL_TOLERANCE: f64 = 1e-6;

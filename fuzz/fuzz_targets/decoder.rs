//! The telemetry link end to end: a byte stream built from arbitrary operations (raw
//! noise, well-formed frames of any kind and payload, NAV frames from raw or plausible
//! orbits, SCENE uploads, corrupted frames), fed to `controller::frame::Decoder` in
//! arbitrary chunkings, every event handed to a `controller::Controller`, then
//! `advance(now)` with a sink that checks every period written.
//!
//! Oracles:
//! - no panic anywhere (decoder, controller, session);
//! - every written period is within `period_bounds_s()` x `scene().line_clock_hz`
//!   (allowing one tick and f32 rounding), and the segment index is an active segment;
//! - the decoder's events do not depend on the chunking (chunked vs one byte at a time);
//! - `controller::session::Session` fed the same bytes writes the same periods as the
//!   direct loop (it runs the same per-frame sequence), and never fails to encode a
//!   downlink frame (`encode_failures == 0`, "never expected").
#![no_main]

use std::convert::Infallible;

use arbitrary::{Arbitrary, Unstructured};
use controller::frame::{encode, kind, Decoder, Event, FrameError, MAX_FRAME};
use controller::nav::{Attitude, Nav};
use controller::scene::{SegmentSpec, MAX_SEGMENTS};
use controller::session::Session;
use controller::{Config, Controller, Fault, LinePeriodSink, Scene};
use core_math::{Camera, StateVector, GM_M3_S2};
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug)]
enum Op {
    /// Line noise.
    Raw(Vec<u8>),
    /// A well-formed frame of any kind and payload.
    Frame {
        kind: u8,
        dt_us: u32,
        payload: Vec<u8>,
    },
    /// A TIME frame `dt_us` after the last time tag.
    Time { dt_us: u32 },
    /// A TIME frame at an absolute time tag (backwards, huge, ...).
    TimeAt { time_us: u64 },
    /// A NAV frame with raw floats.
    NavRaw {
        dt_us: u32,
        pos: [f64; 3],
        vel: [f64; 3],
        att: [f32; 6],
    },
    /// A NAV frame on a circular orbit: mostly inside the controller's envelope.
    NavOrbit {
        dt_us: u32,
        incl: u16,
        node: u16,
        arg_lat: u16,
        alt: u16,
        speed_scale: i8,
        roll: i16,
        pitch: i8,
        yaw: i8,
        roll_rate: i8,
    },
    /// A SCENE upload from the paper's scene with arbitrary changes.
    Scene(SceneOp),
    /// The previous operation's bytes with one byte changed (a damaged frame).
    Corrupt { at: u16, xor: u8 },
    /// The previous operation's bytes cut short (a truncated frame).
    Cut { keep: u16 },
}

#[derive(Arbitrary, Debug)]
struct SceneOp {
    dt_us: u32,
    focal_m: Option<f64>,
    pixel_m: Option<f64>,
    line_clock_hz: Option<f64>,
    mtf_floor: Option<f32>,
    max_roll_rad: Option<f32>,
    max_pitch_rad: Option<f32>,
    max_rate_rad_s: Option<f32>,
    max_stages: Option<u16>,
    count: Option<u8>,
    /// (index, first px, last px, stages, active, ground height m, p1 m)
    segments: Vec<(u8, i32, i32, u16, bool, f32, f32)>,
}

#[derive(Debug)]
struct Input {
    /// Chunk sizes for the decoder (cycled; 0 means 1).
    chunks: Vec<u8>,
    ops: Vec<Op>,
}

impl<'a> Arbitrary<'a> for Input {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let n = u.int_in_range(0..=8)?;
        let mut chunks = Vec::with_capacity(n);
        for _ in 0..n {
            chunks.push(u.arbitrary()?);
        }
        let ops = u.arbitrary_iter()?.collect::<Result<Vec<Op>, _>>()?;
        Ok(Input { chunks, ops })
    }
}

const R: f64 = 6_371_000.0;

fn frame(kind: u8, seq: u16, time_us: u64, payload: &[u8]) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    match encode(kind, seq, time_us, payload, &mut buf) {
        Some(n) => buf[..n].to_vec(),
        None => Vec::new(),
    }
}

fn nav_payload(state: StateVector, attitude: Attitude<f32>) -> Vec<u8> {
    let mut p = [0u8; 128];
    let n = Nav { state, attitude }.encode(&mut p).unwrap();
    p[..n].to_vec()
}

/// The uplink byte stream of the operations.
fn build(ops: &[Op]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut last: Vec<u8> = Vec::new();
    let mut t: u64 = 0;
    let mut seq: u16 = 0;
    let next_t = |t: &mut u64, dt: u32| {
        *t = t.saturating_add(u64::from(dt));
        *t
    };
    for op in ops {
        seq = seq.wrapping_add(1);
        let bytes = match op {
            Op::Raw(b) => b.clone(),
            Op::Frame {
                kind,
                dt_us,
                payload,
            } => frame(*kind, seq, next_t(&mut t, *dt_us), payload),
            Op::Time { dt_us } => frame(kind::TIME, seq, next_t(&mut t, *dt_us), &[]),
            Op::TimeAt { time_us } => {
                t = *time_us;
                frame(kind::TIME, seq, t, &[])
            }
            Op::NavRaw {
                dt_us,
                pos,
                vel,
                att,
            } => {
                let a = Attitude {
                    roll_rad: att[0],
                    pitch_rad: att[1],
                    yaw_rad: att[2],
                    roll_rate_rad_s: att[3],
                    pitch_rate_rad_s: att[4],
                    yaw_rate_rad_s: att[5],
                };
                let sv = StateVector {
                    position_m: *pos,
                    velocity_mps: *vel,
                };
                frame(kind::NAV, seq, next_t(&mut t, *dt_us), &nav_payload(sv, a))
            }
            Op::NavOrbit {
                dt_us,
                incl,
                node,
                arg_lat,
                alt,
                speed_scale,
                roll,
                pitch,
                yaw,
                roll_rate,
            } => {
                let frac = |x: u16| f64::from(x) / f64::from(u16::MAX);
                let i = core::f64::consts::PI * frac(*incl);
                let o = core::f64::consts::TAU * frac(*node);
                let uu = core::f64::consts::TAU * frac(*arg_lat);
                // 450 to 850 km: around the default 500-800 km band.
                let h = 450e3 + 400e3 * frac(*alt);
                let a = R + h;
                let speed = libm::sqrt(GM_M3_S2 / a) * (1.0 + f64::from(*speed_scale) * 1e-3);
                let (si, ci) = (libm::sin(i), libm::cos(i));
                let (su, cu) = (libm::sin(uu), libm::cos(uu));
                let (sn, cn) = (libm::sin(o), libm::cos(o));
                let p = [cn, sn, 0.0];
                let q = [-sn * ci, cn * ci, si];
                let r: [f64; 3] = core::array::from_fn(|k| a * (cu * p[k] + su * q[k]));
                let v: [f64; 3] = core::array::from_fn(|k| speed * (-su * p[k] + cu * q[k]));
                let att = Attitude {
                    // +/- 0.5 rad, past the default scene's 25 deg.
                    roll_rad: f32::from(*roll) / 32767.0 * 0.5,
                    pitch_rad: f32::from(*pitch) * 1e-4,
                    yaw_rad: f32::from(*yaw) * 1e-4,
                    roll_rate_rad_s: f32::from(*roll_rate) * 1e-3,
                    pitch_rate_rad_s: 0.0,
                    yaw_rate_rad_s: 0.0,
                };
                let sv = StateVector {
                    position_m: r,
                    velocity_mps: v,
                };
                frame(
                    kind::NAV,
                    seq,
                    next_t(&mut t, *dt_us),
                    &nav_payload(sv, att),
                )
            }
            Op::Scene(s) => {
                let mut sc = Scene::paper_default();
                if let Some(x) = s.focal_m {
                    sc.camera = Camera {
                        focal_m: x,
                        ..sc.camera
                    };
                }
                if let Some(x) = s.pixel_m {
                    sc.camera = Camera {
                        pixel_m: x,
                        ..sc.camera
                    };
                }
                if let Some(x) = s.line_clock_hz {
                    sc.line_clock_hz = x;
                }
                if let Some(x) = s.mtf_floor {
                    sc.mtf_floor = x;
                }
                if let Some(x) = s.max_roll_rad {
                    sc.envelope.max_roll_rad = x;
                }
                if let Some(x) = s.max_pitch_rad {
                    sc.envelope.max_pitch_rad = x;
                }
                if let Some(x) = s.max_rate_rad_s {
                    sc.envelope.max_rate_rad_s = x;
                }
                if let Some(x) = s.max_stages {
                    sc.max_stages = x;
                }
                for &(idx, first_px, last_px, tdi_stages, active, ground_h_m, p1_m) in &s.segments {
                    sc.segments[usize::from(idx) % MAX_SEGMENTS] = SegmentSpec {
                        first_px,
                        last_px,
                        tdi_stages,
                        active,
                        ground_h_m,
                        p1_m,
                    };
                }
                if let Some(c) = s.count {
                    sc.count = c % (MAX_SEGMENTS as u8 + 1);
                }
                let mut p = [0u8; 512];
                let n = sc.encode(&mut p).unwrap_or(0);
                frame(kind::SCENE, seq, next_t(&mut t, s.dt_us), &p[..n])
            }
            Op::Corrupt { at, xor } => {
                let mut b = last.clone();
                if !b.is_empty() {
                    let k = usize::from(*at) % b.len();
                    b[k] ^= *xor;
                }
                b
            }
            Op::Cut { keep } => {
                let mut b = last.clone();
                b.truncate(usize::from(*keep) % (b.len() + 1));
                b
            }
        };
        out.extend_from_slice(&bytes);
        last = bytes;
        if out.len() > 64 * 1024 {
            break;
        }
    }
    out
}

/// An owned copy of a decoder event.
#[derive(Debug, PartialEq, Eq, Clone)]
enum Ev {
    Frame {
        kind: u8,
        sequence: u16,
        time_us: u64,
        payload: Vec<u8>,
    },
    Rejected(FrameError),
}

impl Ev {
    fn of(e: &Event<'_>) -> Ev {
        match e {
            Event::Frame(f) => Ev::Frame {
                kind: f.kind,
                sequence: f.sequence,
                time_us: f.time_us,
                payload: f.payload.to_vec(),
            },
            Event::Rejected(e) => Ev::Rejected(*e),
        }
    }
}

/// Records every write and checks it against the bounds in force.
struct CheckedSink {
    /// (lo, hi) in ticks, allowing a tick and f32 rounding.
    bounds_ticks: (f64, f64),
    active: [bool; MAX_SEGMENTS],
    writes: Vec<(u8, u32)>,
}

impl CheckedSink {
    fn arm(&mut self, c: &Controller) {
        let (lo, hi) = c.period_bounds_s();
        let clk = c.scene().line_clock_hz;
        let lo_t = f64::from(lo) * clk;
        let hi_t = f64::from(hi) * clk;
        // The controller rounds period_s (f32) x clock (as f32) to the nearest tick.
        self.bounds_ticks = (lo_t * (1.0 - 1e-6) - 1.0, hi_t * (1.0 + 1e-6) + 1.0);
        self.active = [false; MAX_SEGMENTS];
        for (i, _) in c.scene().active() {
            self.active[i] = true;
        }
    }
}

impl LinePeriodSink for CheckedSink {
    type Error = Infallible;
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), Infallible> {
        let (lo, hi) = self.bounds_ticks;
        let t = f64::from(ticks);
        assert!(
            t >= lo && t <= hi,
            "period register {index} written {ticks} ticks, outside [{lo}, {hi}]"
        );
        assert!(
            self.active
                .get(usize::from(index))
                .copied()
                .unwrap_or(false),
            "period written to segment {index}, not an active segment"
        );
        self.writes.push((index, ticks));
        Ok(())
    }
}

/// Records the writes of the session (bounds are checked by the direct loop).
struct Record(Vec<(u8, u32)>);

impl LinePeriodSink for Record {
    type Error = Infallible;
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), Infallible> {
        self.0.push((index, ticks));
        Ok(())
    }
}

fn new_controller() -> Controller {
    Controller::new(Config::default(), Scene::paper_default()).expect("default scene")
}

fuzz_target!(|input: Input| {
    let bytes = build(&input.ops);

    // 1. Chunked decode, every event straight to the controller.
    let mut dec = Decoder::new();
    let mut c = new_controller();
    let mut sink = CheckedSink {
        bounds_ticks: (0.0, 0.0),
        active: [false; MAX_SEGMENTS],
        writes: Vec::new(),
    };
    let mut events = Vec::new();
    let mut ended = false;
    let mut pos = 0;
    let mut k = 0;
    while pos < bytes.len() {
        let n = input
            .chunks
            .get(k % input.chunks.len().max(1))
            .map_or(1, |&n| usize::from(n).max(1));
        k += 1;
        let chunk = &bytes[pos..(pos + n).min(bytes.len())];
        pos += chunk.len();
        dec.feed(chunk, |e| {
            events.push(Ev::of(&e));
            if ended {
                return;
            }
            match e {
                Event::Rejected(err) => c.reject(Fault::from(err)),
                // As the session does: END stops the pass, it never reaches the controller.
                Event::Frame(f) if f.kind == kind::END => {
                    if f.payload.is_empty() {
                        ended = true;
                    } else {
                        c.reject(Fault::BadLength);
                    }
                }
                Event::Frame(f) => {
                    // As the session does: only an accepted frame moves the clock, so
                    // only it can make an update due.
                    let before = c.frames_accepted;
                    c.on_frame(&f);
                    if c.frames_accepted != before {
                        sink.arm(&c);
                        let now = c.now_us();
                        c.advance(now, &mut sink);
                    }
                }
            }
        });
    }

    // 2. The same bytes one at a time: the same events.
    let mut dec1 = Decoder::new();
    let mut events1 = Vec::new();
    for b in &bytes {
        dec1.feed(core::slice::from_ref(b), |e| events1.push(Ev::of(&e)));
    }
    assert_eq!(events, events1, "decoder events depend on the chunking");
    assert_eq!(dec.skipped_bytes, dec1.skipped_bytes);

    // 3. The session on the same bytes: the same periods, no encode failure.
    let mut s = Session::new(new_controller());
    let mut rec = Record(Vec::new());
    let mut downlink = 0usize;
    s.feed(&bytes, &mut rec, |f| {
        assert!(f.len() <= MAX_FRAME);
        downlink += 1;
    });
    assert_eq!(
        s.encode_failures, 0,
        "session failed to encode a downlink frame"
    );
    assert_eq!(
        rec.0, sink.writes,
        "session and direct loop wrote different periods"
    );
    assert_eq!(s.is_ended(), ended);

    // 4. A final tick far ahead (stale) must not write anything out of bounds either.
    sink.arm(&c);
    let later = c.now_us().saturating_add(5_000_000);
    c.advance(later, &mut sink);

    if std::env::var_os("FUZZ_DEBUG").is_some() {
        eprintln!(
            "bytes {} events {} writes {} updates {} accepted {} faults {:?}",
            bytes.len(),
            events.len(),
            sink.writes.len(),
            c.updates,
            c.frames_accepted,
            c.counters.as_array()
        );
    }
});

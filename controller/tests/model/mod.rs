//! A small reference model of the link's documented behaviour (docs/telemetry.md:
//! frames, faults, time window, counters) and a harness that drives a real `Session`
//! with random actions and checks it against the model after every action.
//!
//! Shared by the stateful property test (`tests/session_model.rs`, proptest) and the
//! `session` fuzz target (`fuzz/fuzz_targets/session.rs`, libFuzzer): both turn their
//! random input into [`Action`]s with [`Action::decode`] and run [`Harness::step`],
//! which panics on the first divergence.
#![allow(dead_code)]

use std::convert::Infallible;

use controller::bus::{encode_time_scales, Gnss, StarAttitude};
use controller::config::MAX_TIME_TAG_US;
use controller::frame::{
    encode, kind, Decoder, Event, FrameError, HEADER_LEN, MAX_FRAME, MAX_PAYLOAD, SYNC, VERSION,
};
use controller::nav::{Attitude, Nav};
use controller::report::{Periods, Status};
use controller::scene::{
    Terrain, MAX_GROUND_H_M, MAX_SEGMENTS, MIN_GROUND_H_M, SCENE_HEADER_LEN, SEGMENT_LEN,
};
use controller::session::Session;
use controller::{Config, Controller, Fault, LinePeriodSink, Mode, Scene, SegmentOutput};
use core_math::earth::frames::TimeScales;
use core_math::sample::SplitMix64;
use core_math::{StateVector, GM_M3_S2};

const R_M: f64 = 6_371_000.0;

/// One thing the ground (or the link) does.
#[derive(Clone, Debug)]
pub enum Action {
    /// A valid NAV frame `dt_us` after the clock.
    Nav {
        dt_us: u64,
        u_rad: f64,
        h_m: f64,
        i_rad: f64,
        roll_rad: f32,
    },
    /// A NAV frame, in the window, whose content is refused with `fault`.
    BadNav { dt_us: u64, what: u8 },
    /// A TIME frame `dt_us` after the clock.
    Time { dt_us: u64 },
    /// The on-board timer moves the clock (`Session::tick`).
    Tick { dt_us: u64 },
    /// A SCENE frame, in the window: the paper's scene with one edit.
    Scene { dt_us: u64, edit: u8, k: u8, x: u64 },
    /// A TIME frame tagged `back_us` before (or at) the last accepted tag.
    Backwards { back_us: u64 },
    /// A TIME frame more than the allowed jump ahead of the clock.
    Jump { beyond_us: u64 },
    /// A TIME frame tagged past the largest tag (up to 2^64 - 1).
    TimeMax { below_max: u64 },
    /// Two TIME frames on a new time line `offset_us` away (a re-synchronisation).
    Resync {
        forward: bool,
        offset_us: u64,
        gap_us: u64,
    },
    /// A frame of a kind the camera does not take, or a TIME frame with a payload.
    BadKind { kind: u8, len: u8 },
    /// A TIME frame with one bit flipped (after its length field).
    BitFlip { bit: u8, seed: u64 },
    /// A NAV frame cut after `at` bytes, then a valid NAV frame.
    Cut { at: u8, dt_us: u64 },
    /// Line noise without the sync word's first byte.
    Noise { len: u16, seed: u64 },
    /// A header with a version this camera does not speak.
    BadVersion { version: u8, seed: u64 },
    /// A header announcing more than the largest payload.
    Oversized { len: u16, seed: u64 },
    /// A TERRAIN frame, in the window: heights for the scene in force, valid or with
    /// one defect (a NaN, a height out of range, the wrong count).
    Terrain { dt_us: u64, what: u8, x: u64 },
    /// A bus frame (GNSS, ATTITUDE, TIME_SCALES), in the window, whose content is
    /// refused with one of the bus's faults.
    BadBus { dt_us: u64, what: u8 },
    /// A valid GNSS fix and a valid ATTITUDE frame 1 us later, in the window, tagged at
    /// their time of fix and validity: one circular orbit followed in time, the camera
    /// along its orbital frame turned by up to 1e-4 rad per axis from `seed` (a star
    /// tracker's noise, now and then past the blend's gate), rates up to 1e-3 rad/s:
    /// what drives the attitude blend and the bus's updates.
    Bus { dt_us: u64, seed: u64 },
    /// A DEM upload frame, in the window: a DEM_BEGIN or the next chunk, valid, or one
    /// of the upload's faults (a bad grid, a repeated DEM_BEGIN, a chunk missing,
    /// repeated, of another upload, with a height out of range, a tile whose CRC is
    /// wrong).
    Dem { dt_us: u64, what: u8, x: u64 },
}

/// Kinds the camera takes (and END, which ends a run): anything else is unknown.
fn is_known_kind(k: u8) -> bool {
    matches!(
        k,
        kind::NAV
            | kind::SCENE
            | kind::TERRAIN
            | kind::TIME
            | kind::END
            | kind::GNSS
            | kind::ATTITUDE
            | kind::TIME_SCALES
            | kind::DEM_BEGIN
            | kind::DEM_CHUNK
    )
}

impl Action {
    /// An action from a selector and three raw numbers (what proptest and libFuzzer
    /// generate): the weights favour valid telemetry so that updates run.
    pub fn decode(sel: u8, a: u64, b: u64, c: u64) -> Action {
        let frac = |x: u64| (x % 1_000_001) as f64 / 1e6;
        // Mostly one update period or two, sometimes up to the whole window.
        let dt = |x: u64| {
            if x.is_multiple_of(8) {
                1 + (x >> 3) % 5_000_000
            } else {
                1 + (x >> 3) % 60_000
            }
        };
        match sel % 40 {
            0..=7 => Action::Nav {
                dt_us: dt(a),
                u_rad: frac(b) * core::f64::consts::TAU,
                // Inside the band, off its edges (the altitude is recomputed from r).
                h_m: 501e3 + frac(b >> 20) * 298e3,
                i_rad: frac(c) * core::f64::consts::PI,
                roll_rad: (frac(c >> 20) as f32 - 0.5) * 0.8,
            },
            8..=12 => Action::Time { dt_us: dt(a) },
            13 => Action::Tick { dt_us: dt(a) },
            14..=16 => Action::Scene {
                dt_us: dt(a),
                edit: b as u8,
                k: (b >> 8) as u8,
                x: c,
            },
            17 => Action::BadNav {
                dt_us: dt(a),
                what: b as u8,
            },
            18 => Action::Backwards {
                back_us: a % 3_000_000,
            },
            19 => Action::Jump {
                beyond_us: 1 + a % (1 << 40),
            },
            20 => Action::TimeMax { below_max: a % 3 },
            21 => Action::Resync {
                forward: a.is_multiple_of(2),
                offset_us: 1 + (a >> 1) % 1_000_000_000,
                gap_us: 1 + b % 5_000_000,
            },
            22 => Action::BadKind {
                kind: a as u8,
                len: b as u8,
            },
            23 | 24 => Action::BitFlip {
                bit: a as u8,
                seed: b,
            },
            25 | 26 => Action::Cut {
                at: a as u8,
                dt_us: dt(b),
            },
            27 | 28 => Action::Noise {
                len: (a % 300) as u16 + 1,
                seed: b,
            },
            29 => Action::BadVersion {
                version: a as u8,
                seed: b,
            },
            30 => Action::Oversized {
                len: (a % 1000) as u16,
                seed: b,
            },
            31 => Action::Terrain {
                dt_us: dt(a),
                what: b as u8,
                x: c,
            },
            32 | 33 => Action::BadBus {
                dt_us: dt(a),
                what: b as u8,
            },
            34 | 35 => Action::Bus {
                dt_us: dt(a),
                seed: b,
            },
            _ => Action::Dem {
                dt_us: dt(a),
                what: b as u8,
                x: c,
            },
        }
    }
}

/// What the documentation says the controller's link state is.
#[derive(Clone, Debug, Default)]
pub struct Model {
    pub last_accepted_us: Option<u64>,
    pub now_us: u64,
    /// The tag of the previous frame, if it was refused for its time tag alone.
    pub candidate_us: Option<u64>,
    pub nav_time_us: Option<u64>,
    pub counts: [u32; Fault::COUNT],
    pub frames_accepted: u32,
    pub time_resyncs: u32,
    pub skipped_bytes: u32,
    /// Frames the decoder delivers (accepted or refused for their content or time).
    pub frames_delivered: u32,
    pub delivered_bytes: u64,
    pub max_jump_us: u64,
    /// The DEM tile in force (its upload id, 0: none) and the upload in progress.
    pub dem_in_force: u32,
    pub dem_upload: Option<DemUpload>,
    pub dem_committed: u32,
}

/// An upload in progress, as the model sees it.
#[derive(Clone, Copy, Debug)]
pub struct DemUpload {
    pub id: u32,
    pub next: u16,
    /// Whether its DEM_BEGIN announced the tile's true CRC.
    pub crc_ok: bool,
}

/// The model's tiles: 8 x 60 nodes (3 chunks: 224, 224, 32), heights from the upload id.
pub const DEM_ROWS: usize = 8;
pub const DEM_COLS: usize = 60;
pub const DEM_CHUNKS: u16 = 3;

pub fn dem_grid() -> core_math::earth::dem::DemGrid {
    core_math::earth::dem::DemGrid {
        lat0_deg: -12.5,
        lon0_deg: -70.25,
        dlat_deg: 0.001,
        dlon_deg: 0.002,
        nrows: DEM_ROWS,
        ncols: DEM_COLS,
    }
}

pub fn dem_heights(id: u32) -> Vec<i16> {
    (0..DEM_ROWS * DEM_COLS)
        .map(|k| ((u64::from(id) * 7919 + k as u64 * 131) % 9501) as i16 - 500)
        .collect()
}

fn dem_chunk(id: u32, index: u16, heights: &[i16]) -> Vec<u8> {
    let mut out = [0u8; MAX_PAYLOAD];
    let n = controller::dem::encode_chunk(id, index, heights, &mut out).expect("a chunk");
    out[..n].to_vec()
}

thread_local! {
    /// Tile memories given back by finished harnesses (each is 64 KiB, lent for good).
    static DEM_STORES: std::cell::RefCell<Vec<&'static mut controller::dem::DemStore>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

fn dem_store() -> &'static mut controller::dem::DemStore {
    DEM_STORES
        .with(|p| p.borrow_mut().pop())
        .unwrap_or_else(|| Box::leak(Box::new(controller::dem::DemStore::new())))
}

/// The model's verdict on one delivered frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    Accepted { resync: bool },
    Refused(Fault),
}

impl Model {
    fn count(&mut self, f: Fault) {
        self.counts[f as usize] += 1;
    }

    /// A frame of `len` bytes tagged `t_us` whose content alone would give `content`.
    pub fn frame(&mut self, t_us: u64, len: usize, content: Result<(), Fault>) -> Verdict {
        self.frames_delivered += 1;
        self.delivered_bytes += len as u64;
        let candidate = self.candidate_us.take();
        let time = if t_us > MAX_TIME_TAG_US {
            Err(Fault::TimeJump)
        } else {
            match self.last_accepted_us {
                None => Ok(()),
                Some(last) if t_us <= last => Err(Fault::TimeWentBackwards),
                Some(_) if t_us > self.now_us + self.max_jump_us => Err(Fault::TimeJump),
                Some(_) => Ok(()),
            }
        };
        let resync = match time {
            Ok(()) => false,
            Err(f) => {
                let confirms = t_us <= MAX_TIME_TAG_US
                    && candidate.is_some_and(|c| t_us > c && t_us - c <= self.max_jump_us);
                if !confirms {
                    if t_us <= MAX_TIME_TAG_US {
                        self.candidate_us = Some(t_us);
                    }
                    self.count(f);
                    return Verdict::Refused(f);
                }
                true
            }
        };
        if let Err(f) = content {
            self.count(f);
            return Verdict::Refused(f);
        }
        if resync {
            self.time_resyncs += 1;
            self.now_us = t_us;
            self.nav_time_us = None;
        }
        self.frames_accepted += 1;
        self.last_accepted_us = Some(t_us);
        self.now_us = self.now_us.max(t_us);
        Verdict::Accepted { resync }
    }
}

/// Records every period written; [`check_writes`] holds them to the scene in force
/// after the byte that caused them (a SCENE frame's last byte changes the scene, then
/// the update after it writes).
#[derive(Default)]
pub struct Recorder {
    pub writes: Vec<(u8, u32)>,
}

impl LinePeriodSink for Recorder {
    type Error = Infallible;
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), Infallible> {
        self.writes.push((index, ticks));
        Ok(())
    }
}

/// Every write inside the physical bounds, to an active segment of the scene.
pub fn check_writes(c: &Controller, writes: &[(u8, u32)]) {
    let (lo, hi) = c.period_bounds_s();
    let clock = c.scene().line_clock_hz;
    let (lo, hi) = (f64::from(lo) * clock, f64::from(hi) * clock);
    for &(index, ticks) in writes {
        let t = f64::from(ticks);
        assert!(
            t >= lo * (1.0 - 1e-6) - 1.0 && t <= hi * (1.0 + 1e-6) + 1.0,
            "period {ticks} ticks outside [{lo}, {hi}]"
        );
        assert!(
            c.scene().active().any(|(k, _)| k == usize::from(index)),
            "write to inactive segment {index}"
        );
    }
}

/// ECI state on a circular orbit.
fn state(i: f64, u: f64, h: f64) -> StateVector {
    let a = R_M + h;
    let speed = (GM_M3_S2 / a).sqrt();
    let (si, ci) = i.sin_cos();
    let (su, cu) = u.sin_cos();
    let (sn, cn) = 0.4f64.sin_cos();
    let p = [cn, sn, 0.0];
    let q = [-sn * ci, cn * ci, si];
    StateVector {
        position_m: core::array::from_fn(|k| a * (cu * p[k] + su * q[k])),
        velocity_mps: core::array::from_fn(|k| speed * (-su * p[k] + cu * q[k])),
    }
}

/// A valid GNSS fix at `t_us` and attitude at `t_us` + 1 (see [`Action::Bus`]): the
/// camera (mounted as the paper's scene mounts it, on the body's axes) along the
/// orbital frame of the fix, seen in the GCRF through C2T with `scales`, then turned.
fn bus_frames(t_us: u64, seed: u64, scales: &TimeScales) -> (Gnss, StarAttitude) {
    // The orbit's argument of latitude at t: 0.9 rad at 0, at its mean motion.
    let u_rad = 0.9 + (GM_M3_S2 / (R_M + 645e3).powi(3)).sqrt() * (t_us as f64 * 1e-6);
    let sv = state(1.7, u_rad, 645e3);
    let (r, v, w) = (sv.position_m, sv.velocity_mps, core_math::EARTH_RATE_RAD_S);
    let gnss = Gnss {
        fix_us: t_us,
        position_m: r,
        velocity_mps: [v[0] + w * r[1], v[1] - w * r[0], v[2]],
    };
    let unit = |x: [f64; 3]| {
        let n = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        x.map(|c| c / n)
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let (z, y) = (unit(r), unit(cross(r, v)));
    let x = cross(y, z);
    let c2t = core_math::earth::frames::c2t((t_us + 1) as f64 * 1e-6, scales).unwrap();
    // GCRF from camera: C2T^T [x y z].
    let body: [[f64; 3]; 3] = core::array::from_fn(|i| {
        core::array::from_fn(|j| (0..3).map(|k| c2t[k][i] * [x, y, z][j][k]).sum())
    });
    let q = core_math::earth::bus::matrix_quaternion(&body);
    let mut rng = SplitMix64(seed);
    let e: [f64; 3] = core::array::from_fn(|_| rng.uniform(-1e-4, 1e-4));
    let turn = [1.0, 0.5 * e[0], 0.5 * e[1], 0.5 * e[2]];
    let q = [
        q[0] * turn[0] - q[1] * turn[1] - q[2] * turn[2] - q[3] * turn[3],
        q[0] * turn[1] + q[1] * turn[0] + q[2] * turn[3] - q[3] * turn[2],
        q[0] * turn[2] - q[1] * turn[3] + q[2] * turn[0] + q[3] * turn[1],
        q[0] * turn[3] + q[1] * turn[2] - q[2] * turn[1] + q[3] * turn[0],
    ];
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    let attitude = StarAttitude {
        valid_us: t_us + 1,
        q: q.map(|x| (x / n) as f32),
        body_rate_rad_s: core::array::from_fn(|_| rng.uniform(-1e-3, 1e-3) as f32),
    };
    (gnss, attitude)
}

/// A bus frame's kind and payload, tagged `t_us`, that the controller must refuse,
/// and its fault (docs/telemetry.md, "The bus's frames").
fn bad_bus_payload(t_us: u64, what: u8) -> (u8, Vec<u8>, Fault) {
    let sv = state(1.7, 0.3, 645e3);
    let gnss = Gnss {
        fix_us: t_us,
        position_m: sv.position_m,
        velocity_mps: sv.velocity_mps,
    };
    let attitude = StarAttitude {
        valid_us: t_us,
        q: [0.6, 0.0, 0.8, 0.0],
        body_rate_rad_s: [0.0; 3],
    };
    let mut p = [0u8; 64];
    let gnss_bytes = |g: Gnss, p: &mut [u8; 64]| {
        let n = g.encode(p).unwrap();
        p[..n].to_vec()
    };
    let att_bytes = |a: StarAttitude, p: &mut [u8; 64]| {
        let n = a.encode(p).unwrap();
        p[..n].to_vec()
    };
    let scales = |leap: i16, dut1: f32, p: &mut [u8; 64]| {
        let n = encode_time_scales(leap, dut1, p).unwrap();
        p[..n].to_vec()
    };
    match what % 10 {
        0 => {
            let a = StarAttitude {
                q: [0.6, 0.0, 0.8, 0.05],
                ..attitude
            };
            (kind::ATTITUDE, att_bytes(a, &mut p), Fault::BadQuaternion)
        }
        1 => {
            let a = StarAttitude {
                valid_us: t_us + 1,
                ..attitude
            };
            (kind::ATTITUDE, att_bytes(a, &mut p), Fault::FixTime)
        }
        2 => {
            let g = Gnss {
                fix_us: t_us + 1,
                ..gnss
            };
            (kind::GNSS, gnss_bytes(g, &mut p), Fault::FixTime)
        }
        3 => {
            let g = Gnss {
                fix_us: t_us.saturating_sub(2_000_001),
                ..gnss
            };
            let f = if t_us >= 2_000_001 {
                Fault::FixTime
            } else {
                Fault::OutOfRange
            };
            // Near the clock's start the fix cannot be too old: an orbit below the band
            // instead.
            let g = if t_us >= 2_000_001 {
                g
            } else {
                Gnss {
                    position_m: gnss.position_m.map(|x| x * 0.9),
                    ..gnss
                }
            };
            (kind::GNSS, gnss_bytes(g, &mut p), f)
        }
        4 => (
            kind::TIME_SCALES,
            scales(61, 0.0, &mut p),
            Fault::TimeScales,
        ),
        5 => (
            kind::TIME_SCALES,
            scales(18, -0.95, &mut p),
            Fault::TimeScales,
        ),
        6 => (
            kind::TIME_SCALES,
            scales(18, f32::NAN, &mut p),
            Fault::NonFinite,
        ),
        7 => {
            let mut g = gnss;
            g.velocity_mps[2] = f64::INFINITY;
            (kind::GNSS, gnss_bytes(g, &mut p), Fault::NonFinite)
        }
        8 => {
            let a = StarAttitude {
                body_rate_rad_s: [0.0, 1.0, 0.0],
                ..attitude
            };
            (
                kind::ATTITUDE,
                att_bytes(a, &mut p),
                Fault::AttitudeOutsideModel,
            )
        }
        _ => {
            let mut b = att_bytes(attitude, &mut p);
            b.pop();
            (kind::ATTITUDE, b, Fault::BadLength)
        }
    }
}

fn nav_payload(sv: StateVector, attitude: Attitude<f32>) -> Vec<u8> {
    let mut p = [0u8; 128];
    let n = Nav {
        state: sv,
        attitude,
    }
    .encode(&mut p)
    .unwrap();
    p[..n].to_vec()
}

/// An edit of the encoded bytes, for what `Scene::encode` cannot express.
type RawEdit = Box<dyn Fn(&mut Vec<u8>)>;

/// A SCENE payload: the paper's scene with edit `edit` (on segment `k`, value `x`), and
/// the verdict the documented rules give it.
pub fn scene_case(edit: u8, k: u8, x: u64) -> (Vec<u8>, Result<(), Fault>, Option<Scene>) {
    let mut scene = Scene::paper_default();
    let k = usize::from(k % 10);
    let mut raw: Option<RawEdit> = None;
    let verdict = match edit % 20 {
        // Valid edits: fewer segments, some inactive, other stage counts.
        0 | 1 => {
            scene.count = 1 + (x % 10) as u8;
            Ok(())
        }
        2 | 3 => {
            for (j, s) in scene.segments.iter_mut().take(10).enumerate() {
                s.active = (x >> j) & 1 == 1 || j == k;
            }
            Ok(())
        }
        4 | 5 => {
            scene.max_stages = 1 + (x % 256) as u16;
            for (j, s) in scene.segments.iter_mut().take(10).enumerate() {
                s.tdi_stages = 1 + ((x >> (8 + j)) % u64::from(scene.max_stages)) as u16;
            }
            Ok(())
        }
        // Refused: an active byte outside {0, 1}.
        6 => {
            let v = 2 + (x % 254) as u8;
            raw = Some(Box::new(move |p: &mut Vec<u8>| {
                p[SCENE_HEADER_LEN + k * SEGMENT_LEN + 10] = v
            }));
            Err(Fault::InvalidScene)
        }
        // Stage counts above the scene's largest, or above what the MTF formula takes.
        7 => {
            scene.segments[k].tdi_stages = scene.max_stages + 1 + (x % 1000) as u16;
            Err(Fault::InvalidScene)
        }
        8 => {
            scene.max_stages = 257 + (x % 65_279) as u16;
            Err(Fault::InvalidScene)
        }
        9 => {
            for s in scene.segments.iter_mut() {
                s.active = false;
            }
            Err(Fault::InvalidScene)
        }
        // Overlapping, then unordered segments.
        10 => {
            let j = 1 + k % 9;
            scene.segments[j].first_px = scene.segments[j - 1].last_px - (x % 3000) as i32;
            Err(Fault::InvalidScene)
        }
        11 => {
            let j = (k + 1 + (x % 9) as usize) % 10;
            scene.segments.swap(k, j);
            Err(Fault::InvalidScene)
        }
        // More segments than the table holds, with a length that matches the count.
        12 => {
            let n = 17 + (x % 4) as usize;
            raw = Some(Box::new(move |p: &mut Vec<u8>| {
                p[42] = n as u8;
                let seg = p[SCENE_HEADER_LEN..SCENE_HEADER_LEN + SEGMENT_LEN].to_vec();
                p.truncate(SCENE_HEADER_LEN);
                for _ in 0..n {
                    p.extend_from_slice(&seg);
                }
            }));
            Err(Fault::InvalidScene)
        }
        // A pixel that never sees the Earth, even at nadir.
        13 => {
            scene.segments[9].last_px = 90_000 + (x % 1_000_000) as i32;
            Err(Fault::InvalidScene)
        }
        14 => {
            scene.mtf_floor = 1.0 + (x % 100) as f32 / 10.0;
            Err(Fault::InvalidScene)
        }
        15 => {
            scene.segments[k].tdi_stages = 0;
            Err(Fault::InvalidScene)
        }
        16 => {
            scene.camera.focal_m = f64::NAN;
            Err(Fault::NonFinite)
        }
        17 => {
            let cut = 1 + (x % 11) as usize;
            raw = Some(Box::new(move |p: &mut Vec<u8>| p.truncate(p.len() - cut)));
            Err(Fault::BadLength)
        }
        18 => {
            scene.envelope.max_roll_rad = 1.3 + (x % 100) as f32;
            Err(Fault::InvalidScene)
        }
        _ => {
            scene.count = 0;
            Err(Fault::InvalidScene)
        }
    };
    let mut p = vec![0u8; 400];
    let n = scene.encode(&mut p).unwrap();
    p.truncate(n);
    if let Some(f) = raw {
        f(&mut p);
    }
    // The decoder leaves the table beyond the count empty.
    for s in scene.segments.iter_mut().skip(usize::from(scene.count)) {
        *s = Default::default();
    }
    let accepted = verdict.is_ok().then_some(scene);
    (p, verdict, accepted)
}

/// What the session sent during one action.
#[derive(Default, Debug)]
struct Sent {
    periods: Vec<(u64, Periods)>,
    status: Vec<Status>,
}

/// A `Session` and the model, stepped together.
pub struct Harness {
    pub session: Session,
    pub model: Model,
    seq: u16,
    fed_bytes: u64,
    periods_frames: u32,
    /// PERIODS frames in mode stale whose predecessor was not (one per stale episode).
    stale_entries: u32,
    last_periods_mode: Option<u8>,
    pub steps: u32,
}

impl Drop for Harness {
    fn drop(&mut self) {
        if let Some(store) = self.session.controller.detach_dem() {
            DEM_STORES.with(|p| p.borrow_mut().push(store));
        }
    }
}

impl Default for Harness {
    fn default() -> Self {
        Self::new()
    }
}

impl Harness {
    pub fn new() -> Harness {
        Harness::with(Controller::new(Config::default(), Scene::paper_default()).unwrap())
    }

    /// A harness around `c`, a controller fresh from `Controller::new` (the fuzz target
    /// clones one, which saves planning the default scene per input).
    pub fn with(mut c: Controller) -> Harness {
        let config = c.config;
        let store = dem_store();
        store.forget();
        c.attach_dem(store);
        Harness {
            session: Session::new(c),
            model: Model {
                max_jump_us: config.max_time_jump_us,
                ..Model::default()
            },
            seq: 0,
            fed_bytes: 0,
            periods_frames: 0,
            stale_entries: 0,
            last_periods_mode: None,
            steps: 0,
        }
    }

    fn frame(&mut self, kind: u8, t_us: u64, payload: &[u8]) -> Vec<u8> {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(kind, self.seq, t_us, payload, &mut buf).unwrap();
        self.seq = self.seq.wrapping_add(1);
        buf[..n].to_vec()
    }

    /// A frame of which no byte after the first is the sync word's first byte (so that
    /// a rescan after damaging it skips all of it): the sequence number is varied.
    fn clean_frame(&mut self, kind: u8, t_us: u64, payload: &[u8]) -> Option<Vec<u8>> {
        for _ in 0..64 {
            let f = self.frame(kind, t_us, payload);
            if !f[1..].contains(&SYNC[0]) {
                return Some(f);
            }
        }
        None
    }

    fn feed(&mut self, bytes: &[u8]) -> Sent {
        let mut out = Vec::new();
        let mut sink = Recorder::default();
        for &b in bytes {
            self.session
                .feed(&[b], &mut sink, |f| out.extend_from_slice(f));
            check_writes(&self.session.controller, &sink.writes);
            sink.writes.clear();
        }
        self.fed_bytes += bytes.len() as u64;
        self.decode_downlink(&out)
    }

    fn decode_downlink(&mut self, out: &[u8]) -> Sent {
        let mut sent = Sent::default();
        let mut d = Decoder::new();
        d.feed(out, |e| match e {
            Event::Frame(f) if f.kind == kind::PERIODS => sent
                .periods
                .push((f.time_us, Periods::decode(f.payload).expect("PERIODS"))),
            Event::Frame(f) if f.kind == kind::STATUS => {
                sent.status.push(Status::decode(f.payload).expect("STATUS"))
            }
            other => panic!("unexpected downlink event {other:?}"),
        });
        assert_eq!(d.skipped_bytes, 0, "stray downlink bytes");
        for (_, p) in &sent.periods {
            self.periods_frames += 1;
            if p.mode == Mode::Stale as u8 && self.last_periods_mode != Some(p.mode) {
                self.stale_entries += 1;
            }
            self.last_periods_mode = Some(p.mode);
            for r in p.records() {
                assert!((0.0..=1.0).contains(&r.mtf), "MTF {} outside [0, 1]", r.mtf);
            }
        }
        sent
    }

    #[allow(clippy::type_complexity)]
    fn snapshot(
        &self,
    ) -> (
        Option<u64>,
        Option<u64>,
        Option<controller::track::AttitudeState>,
        Scene,
        Vec<f32>,
        Vec<SegmentOutput>,
        u32,
        controller::dem::DemStatus,
    ) {
        let c = &self.session.controller;
        (
            c.nav().map(|n| n.time_us),
            c.gnss().map(|g| g.fix_us),
            c.bus_attitude().copied(),
            *c.scene(),
            c.heights_m().to_vec(),
            c.outputs().copied().collect(),
            c.updates,
            c.dem_status(),
        )
    }

    /// One frame through the session and the model; checks the verdict's effect.
    fn one_frame(
        &mut self,
        kind: u8,
        t_us: u64,
        payload: &[u8],
        content: Result<(), Fault>,
        scene: Option<Scene>,
    ) {
        let bytes = self.frame(kind, t_us, payload);
        self.deliver(&bytes, t_us, content, scene);
    }

    fn deliver(
        &mut self,
        bytes: &[u8],
        t_us: u64,
        content: Result<(), Fault>,
        scene: Option<Scene>,
    ) {
        let before = self.snapshot();
        let verdict = self.model.frame(t_us, bytes.len(), content);
        let sent = self.feed(bytes);
        let c = &self.session.controller;
        match verdict {
            Verdict::Refused(f) => {
                assert_eq!(
                    c.last_fault,
                    Some(f),
                    "refusal of kind {kind_of:?}",
                    kind_of = bytes.get(3)
                );
                assert_eq!(
                    self.snapshot(),
                    before,
                    "a refused frame ({f:?}) changed the state"
                );
                assert!(
                    sent.periods.is_empty() && sent.status.is_empty(),
                    "a refused frame sent {sent:?}"
                );
            }
            Verdict::Accepted { resync } => {
                assert_eq!(c.now_us(), self.model.now_us, "clock");
                match bytes.get(3) {
                    Some(&kind::NAV) => {
                        self.model.nav_time_us = Some(t_us);
                        assert_eq!(c.nav().map(|n| n.time_us), Some(t_us), "NAV not taken");
                    }
                    Some(&kind::SCENE) => {
                        assert_eq!(Some(*c.scene()), scene, "SCENE not taken");
                    }
                    // The bus's data replace NAV.
                    Some(&kind::GNSS) => {
                        self.model.nav_time_us = None;
                        assert_eq!(c.gnss().map(|g| g.fix_us), Some(t_us), "GNSS not taken");
                    }
                    Some(&kind::ATTITUDE) => {
                        self.model.nav_time_us = None;
                        let taken = c.bus_attitude().map(|a| a.received.valid_us);
                        assert_eq!(taken, Some(t_us), "ATTITUDE not taken");
                    }
                    _ => {}
                }
                if resync {
                    assert_eq!(
                        sent.status.len(),
                        1,
                        "a re-synchronisation is reported at once"
                    );
                }
            }
        }
    }

    /// Checks everything the model knows, and the counter identities.
    pub fn check(&self) {
        let c = &self.session.controller;
        let m = &self.model;
        for f in Fault::ALL {
            if matches!(
                f,
                Fault::Stale | Fault::BeyondLimb | Fault::PeriodOutOfRange
            ) {
                continue;
            }
            assert_eq!(
                c.counters.get(f),
                m.counts[f as usize],
                "counter {}",
                f.name()
            );
        }
        assert_eq!(c.frames_accepted, m.frames_accepted, "frames accepted");
        assert_eq!(c.time_resyncs, m.time_resyncs, "re-synchronisations");
        assert_eq!(c.now_us(), m.now_us, "clock");
        assert_eq!(c.nav().map(|n| n.time_us), m.nav_time_us, "NAV in force");
        assert_eq!(
            self.session.decoder.buffered(),
            0,
            "bytes left in the decoder"
        );
        assert_eq!(
            self.session.decoder.skipped_bytes, m.skipped_bytes,
            "skipped bytes"
        );
        // The identities of docs/telemetry.md, "Counters".
        assert_eq!(
            self.fed_bytes,
            m.delivered_bytes + u64::from(self.session.decoder.skipped_bytes),
            "bytes received = delivered frames' bytes + skipped"
        );
        let frame_faults: u32 = [
            Fault::UnknownKind,
            Fault::BadLength,
            Fault::NonFinite,
            Fault::OutOfRange,
            Fault::TimeWentBackwards,
            Fault::AttitudeOutsideModel,
            Fault::InvalidScene,
            Fault::TimeJump,
            Fault::BadQuaternion,
            Fault::FixTime,
            Fault::TimeScales,
            Fault::DemGrid,
            Fault::DemSequence,
            Fault::DemHeight,
            Fault::DemCrc,
        ]
        .iter()
        .map(|&f| c.counters.get(f))
        .sum();
        // Only NAV frames make out_of_range, and the model generates none that the
        // update could refuse; so every out_of_range here is a refused frame.
        assert_eq!(
            c.frames_accepted + frame_faults,
            m.frames_delivered,
            "frames delivered"
        );
        assert_eq!(c.updates, self.periods_frames, "updates = PERIODS frames");
        assert_eq!(
            c.counters.get(Fault::Stale),
            self.stale_entries,
            "stale episodes"
        );
        assert!(c.now_us() <= MAX_TIME_TAG_US);
        // The DEM upload's state, and the tile in force is the model's, node bounds
        // and all.
        let d = c.dem_status();
        assert_eq!(d.in_force_id, m.dem_in_force, "DEM tile in force");
        assert_eq!(d.upload_id, m.dem_upload.map_or(0, |u| u.id), "DEM upload");
        assert_eq!(
            d.next_chunk,
            m.dem_upload.map_or(0, |u| u.next),
            "DEM next chunk"
        );
        assert_eq!(d.tiles_committed, m.dem_committed, "DEM tiles committed");
        match c.dem_tile() {
            None => assert_eq!(m.dem_in_force, 0, "no DEM tile in force"),
            Some(t) => {
                let h = dem_heights(m.dem_in_force);
                let want = core_math::earth::dem::DemTile::new(dem_grid(), &h).unwrap();
                assert_eq!(t.bounds(), want.bounds(), "DEM tile bounds");
                assert_eq!(*t.grid(), dem_grid(), "DEM grid");
            }
        }
    }

    /// Runs one action, then checks.
    pub fn step(&mut self, a: &Action) {
        self.steps += 1;
        let now = self.model.now_us;
        let last = self.model.last_accepted_us;
        match *a {
            Action::Nav {
                dt_us,
                u_rad,
                h_m,
                i_rad,
                roll_rad,
            } => {
                let p = nav_payload(
                    state(i_rad, u_rad, h_m),
                    Attitude {
                        roll_rad,
                        ..Attitude::default()
                    },
                );
                self.one_frame(kind::NAV, now + dt_us, &p, Ok(()), None);
            }
            Action::BadNav { dt_us, what } => {
                let good = state(1.7, 0.3, 645e3);
                let (sv, att, f) = match what % 5 {
                    0 => {
                        let mut s = good;
                        s.velocity_mps[1] = f64::NAN;
                        (s, Attitude::default(), Fault::NonFinite)
                    }
                    1 => (
                        state(1.7, 0.3, 100e3),
                        Attitude::default(),
                        Fault::OutOfRange,
                    ),
                    2 => (
                        good,
                        Attitude {
                            pitch_rad: 0.6,
                            ..Attitude::default()
                        },
                        Fault::AttitudeOutsideModel,
                    ),
                    3 => (
                        good,
                        Attitude {
                            roll_rad: 0.9,
                            ..Attitude::default()
                        },
                        Fault::AttitudeOutsideModel,
                    ),
                    _ => (
                        good,
                        Attitude {
                            roll_rad: f32::INFINITY,
                            ..Attitude::default()
                        },
                        Fault::NonFinite,
                    ),
                };
                self.one_frame(kind::NAV, now + dt_us, &nav_payload(sv, att), Err(f), None);
            }
            Action::Time { dt_us } => self.one_frame(kind::TIME, now + dt_us, &[], Ok(()), None),
            Action::BadBus { dt_us, what } => {
                let t = now + dt_us;
                let (k, payload, f) = bad_bus_payload(t, what);
                self.one_frame(k, t, &payload, Err(f), None);
            }
            Action::Bus { dt_us, seed } => {
                let t = now + dt_us;
                let scales = *self.session.controller.time_scales();
                let (gnss, attitude) = bus_frames(t, seed, &scales);
                let mut p = [0u8; 64];
                let n = gnss.encode(&mut p).unwrap();
                self.one_frame(kind::GNSS, t, &p[..n], Ok(()), None);
                // A tag equal to the last is refused (`time_went_backwards`): 1 us on.
                let n = attitude.encode(&mut p).unwrap();
                self.one_frame(kind::ATTITUDE, t + 1, &p[..n], Ok(()), None);
            }
            Action::Terrain { dt_us, what, x } => {
                let count = self.session.controller.scene().count;
                let mut t = Terrain {
                    heights_m: [0.0; MAX_SEGMENTS],
                    count,
                };
                let span = MAX_GROUND_H_M - MIN_GROUND_H_M;
                for (j, h) in t.heights_m.iter_mut().enumerate() {
                    *h = MIN_GROUND_H_M + span * (x.rotate_right(5 * j as u32) % 32) as f32 / 31.0;
                }
                let j = usize::from(what >> 3) % usize::from(count.max(1));
                let verdict = match what % 6 {
                    0..=2 => Ok(()),
                    3 => {
                        t.heights_m[j] = f32::NAN;
                        Err(Fault::NonFinite)
                    }
                    4 => {
                        t.heights_m[j] = if x % 2 == 0 {
                            MAX_GROUND_H_M + 1.0
                        } else {
                            MIN_GROUND_H_M - 1.0
                        };
                        Err(Fault::OutOfRange)
                    }
                    _ => {
                        t.count = if usize::from(count) < MAX_SEGMENTS {
                            count + 1
                        } else {
                            count - 1
                        };
                        Err(Fault::InvalidScene)
                    }
                };
                let mut p = [0u8; 128];
                let n = t.encode(&mut p).expect("a TERRAIN payload fits");
                let accepted = self.session.controller.frames_accepted;
                self.one_frame(kind::TERRAIN, now + dt_us, &p[..n], verdict, None);
                if self.session.controller.frames_accepted > accepted {
                    assert_eq!(
                        self.session.controller.heights_m(),
                        &t.heights_m[..usize::from(count)],
                        "TERRAIN not taken"
                    );
                }
            }
            Action::Dem { dt_us, what, x } => self.dem_step(now + dt_us, what, x),
            Action::Tick { dt_us } => {
                let mut out = Vec::new();
                let mut sink = Recorder::default();
                self.session
                    .tick(now + dt_us, &mut sink, |f| out.extend_from_slice(f));
                check_writes(&self.session.controller, &sink.writes);
                self.model.now_us = (now + dt_us).min(MAX_TIME_TAG_US).max(now);
                self.decode_downlink(&out);
            }
            Action::Scene { dt_us, edit, k, x } => {
                let (p, verdict, scene) = scene_case(edit, k, x);
                self.one_frame(kind::SCENE, now + dt_us, &p, verdict, scene);
            }
            Action::Backwards { back_us } => {
                let t = last.unwrap_or(0).saturating_sub(back_us);
                self.one_frame(kind::TIME, t, &[], Ok(()), None);
            }
            Action::Jump { beyond_us } => {
                let t = now + self.model.max_jump_us + beyond_us;
                self.one_frame(kind::TIME, t, &[], Ok(()), None);
            }
            Action::TimeMax { below_max } => {
                let t = [u64::MAX, u64::MAX - 1, MAX_TIME_TAG_US + 1][below_max as usize % 3];
                self.one_frame(kind::TIME, t, &[], Ok(()), None);
            }
            Action::Resync {
                forward,
                offset_us,
                gap_us,
            } => {
                let t = if forward {
                    (now + self.model.max_jump_us + offset_us).min(MAX_TIME_TAG_US - gap_us)
                } else {
                    last.unwrap_or(0).saturating_sub(offset_us)
                };
                self.one_frame(kind::TIME, t, &[], Ok(()), None);
                self.one_frame(kind::TIME, t + gap_us, &[], Ok(()), None);
            }
            Action::BadKind { kind: k, len } => {
                let (k, verdict) = if is_known_kind(k) {
                    (kind::TIME, Err(Fault::BadLength))
                } else {
                    (k, Err(Fault::UnknownKind))
                };
                let len = if k == kind::TIME {
                    1 + len % 40
                } else {
                    len % 40
                };
                let payload = vec![0x5A; usize::from(len)];
                self.one_frame(k, now + 1, &payload, verdict, None);
            }
            Action::BitFlip { bit, seed } => {
                let mut s = SplitMix64(seed);
                let Some(mut f) = self.clean_frame(kind::TIME, s.next_u64() & 0xFFFF_FFFF, &[])
                else {
                    return self.check();
                };
                // After the length field: sequence, time tag, CRC.
                let bit = usize::from(bit) % ((f.len() - 6) * 8);
                f[6 + bit / 8] ^= 1 << (bit % 8);
                if f[1..].contains(&SYNC[0]) {
                    return self.check();
                }
                self.model.counts[Fault::BadCrc as usize] += 1;
                self.model.skipped_bytes += f.len() as u32;
                let before = self.snapshot();
                let sent = self.feed(&f);
                assert_eq!(self.snapshot(), before, "a damaged frame changed the state");
                assert!(sent.periods.is_empty() && sent.status.is_empty());
            }
            Action::Cut { at, dt_us } => {
                let p = nav_payload(state(1.7, 0.3, 645e3), Attitude::default());
                let good = nav_payload(
                    state(1.7, 0.3 + dt_us as f64 * 1e-9, 645e3),
                    Attitude::default(),
                );
                let next = self.frame(kind::NAV, now + dt_us, &good);
                // The cut frame's tag and content do not matter (it is lost); its bytes
                // after the first must hold no sync byte, so that the rescan skips them,
                // and the cut frame with the next one's start must not pass the CRC by
                // chance (1 in 65 536: the fuzzer found one).
                let mut cut = None;
                for s in 0..64u64 {
                    let f = self.frame(kind::NAV, 0x0102_0304 + s, &p);
                    let clean = 1 + f[1..].iter().position(|&b| b == SYNC[0]).unwrap_or(f.len());
                    // At least the header; at least 3 bytes of the next frame in its span.
                    let n = (HEADER_LEN + usize::from(at) % 72)
                        .min(clean)
                        .min(f.len() - 3);
                    if n < HEADER_LEN {
                        continue;
                    }
                    let mut both = f[..n].to_vec();
                    both.extend_from_slice(&next);
                    let mut events = Vec::new();
                    Decoder::new().feed(&both, |e| {
                        events.push(matches!(e, Event::Rejected(FrameError::Truncated)))
                    });
                    if events == [true, false] {
                        cut = Some(f[..n].to_vec());
                        break;
                    }
                }
                let Some(cut) = cut else {
                    return self.check();
                };
                self.model.counts[Fault::Truncated as usize] += 1;
                self.model.skipped_bytes += cut.len() as u32;
                let before = self.snapshot();
                // The decoder holds the cut frame until the next one shows it was cut.
                let sent = self.feed(&cut);
                assert_eq!(self.snapshot(), before);
                assert!(sent.periods.is_empty() && sent.status.is_empty());
                self.deliver(&next, now + dt_us, Ok(()), None);
            }
            Action::Noise { len, seed } => {
                let mut s = SplitMix64(seed);
                let noise: Vec<u8> = (0..len)
                    .map(|_| match s.next_u64() as u8 {
                        b if b == SYNC[0] => 0x55,
                        b => b,
                    })
                    .collect();
                self.model.skipped_bytes += noise.len() as u32;
                let before = self.snapshot();
                let sent = self.feed(&noise);
                assert_eq!(self.snapshot(), before);
                assert!(
                    sent.periods.is_empty() && sent.status.is_empty(),
                    "noise sent {sent:?}"
                );
            }
            Action::BadVersion { version, seed } => {
                let version = if version == VERSION {
                    VERSION + 1
                } else {
                    version
                };
                let mut s = SplitMix64(seed);
                let Some(mut f) = self.clean_frame(kind::TIME, s.next_u64() & 0xFFFF_FFFF, &[])
                else {
                    return self.check();
                };
                f[2] = version;
                if f[1..].contains(&SYNC[0]) {
                    return self.check();
                }
                self.model.counts[Fault::UnknownVersion as usize] += 1;
                self.model.skipped_bytes += f.len() as u32;
                let sent = self.feed(&f);
                assert!(sent.periods.is_empty() && sent.status.is_empty());
            }
            Action::Oversized { len, seed } => {
                let mut s = SplitMix64(seed);
                let Some(f) = self.clean_frame(kind::TIME, s.next_u64() & 0xFFFF_FFFF, &[]) else {
                    return self.check();
                };
                let mut h = f[..HEADER_LEN].to_vec();
                let n = (MAX_PAYLOAD + 1 + usize::from(len)) as u16;
                h[4..6].copy_from_slice(&n.to_le_bytes());
                if h[1..].contains(&SYNC[0]) {
                    return self.check();
                }
                self.model.counts[Fault::Oversized as usize] += 1;
                self.model.skipped_bytes += h.len() as u32;
                let sent = self.feed(&h);
                assert!(sent.periods.is_empty() && sent.status.is_empty());
            }
        }
        self.check();
    }

    /// One DEM frame tagged `t_us` (see [`Action::Dem`]).
    fn dem_step(&mut self, t_us: u64, what: u8, x: u64) {
        let grid = dem_grid();
        let m = &self.model;
        // A fresh id: neither the tile in force's nor the upload's, never 0.
        let mut fresh = 1 + (x % 1000) as u32;
        while fresh == m.dem_in_force || m.dem_upload.is_some_and(|u| u.id == fresh) {
            fresh += 1;
        }
        let upload = m.dem_upload;
        let begin = |id: u32, g: &core_math::earth::dem::DemGrid, crc_ok: bool| {
            let crc = controller::dem::heights_crc32(&dem_heights(id));
            controller::dem::encode_begin(id, g, if crc_ok { crc } else { !crc }).to_vec()
        };
        let (k, payload, verdict) = match what % 12 {
            // A new upload (one in progress is given up); 1 in 4 with a wrong CRC.
            0 => {
                let crc_ok = !x.is_multiple_of(4);
                (kind::DEM_BEGIN, begin(fresh, &grid, crc_ok), Ok(()))
            }
            // The next chunk of the upload in progress.
            1..=6 => match upload {
                Some(u) => {
                    let last = u.next + 1 == DEM_CHUNKS;
                    let verdict = if last && !u.crc_ok {
                        Err(Fault::DemCrc)
                    } else {
                        Ok(())
                    };
                    let p = dem_chunk(u.id, u.next, &dem_heights(u.id));
                    (kind::DEM_CHUNK, p, verdict)
                }
                None => (
                    kind::DEM_CHUNK,
                    dem_chunk(fresh, 0, &dem_heights(fresh)),
                    Err(Fault::DemSequence),
                ),
            },
            // A chunk missing (the one after next), repeated (the one before), or of
            // another upload.
            7 => {
                let (id, index) = match upload {
                    Some(u) if x.is_multiple_of(3) && u.next > 0 => (u.id, u.next - 1),
                    Some(u) if x % 3 == 1 && u.next + 1 < DEM_CHUNKS => (u.id, u.next + 1),
                    _ => (fresh, 0),
                };
                (
                    kind::DEM_CHUNK,
                    dem_chunk(id, index, &dem_heights(id)),
                    Err(Fault::DemSequence),
                )
            }
            // The next chunk with a height out of range.
            8 => match upload {
                Some(u) => {
                    let mut h = dem_heights(u.id);
                    let j =
                        usize::from(u.next) * controller::dem::DEM_CHUNK_NODES + (x % 32) as usize;
                    h[j] = if x.is_multiple_of(2) { 9_001 } else { -501 };
                    (
                        kind::DEM_CHUNK,
                        dem_chunk(u.id, u.next, &h),
                        Err(Fault::DemHeight),
                    )
                }
                None => (
                    kind::DEM_CHUNK,
                    dem_chunk(fresh, 0, &dem_heights(fresh)),
                    Err(Fault::DemSequence),
                ),
            },
            // A grid the camera cannot take: a pole, the antimeridian, too many nodes.
            9 => {
                let bad = match x % 3 {
                    0 => core_math::earth::dem::DemGrid {
                        lat0_deg: 88.0,
                        ..grid
                    },
                    1 => core_math::earth::dem::DemGrid {
                        lon0_deg: 179.9,
                        ..grid
                    },
                    _ => core_math::earth::dem::DemGrid {
                        nrows: 200,
                        ncols: 100,
                        ..grid
                    },
                };
                (
                    kind::DEM_BEGIN,
                    begin(fresh, &bad, true),
                    Err(Fault::DemGrid),
                )
            }
            // A DEM_BEGIN repeating the upload in progress or the tile in force.
            10 => match (upload, m.dem_in_force) {
                (Some(u), _) => (
                    kind::DEM_BEGIN,
                    begin(u.id, &grid, true),
                    Err(Fault::DemSequence),
                ),
                (None, id) if id != 0 => (
                    kind::DEM_BEGIN,
                    begin(id, &grid, true),
                    Err(Fault::DemSequence),
                ),
                _ => (kind::DEM_BEGIN, begin(0, &grid, true), Err(Fault::DemGrid)),
            },
            // A chunk whose count is not its length's.
            _ => {
                let mut p = dem_chunk(fresh, 0, &dem_heights(fresh));
                p.truncate(p.len() - 2 * (1 + (x % 5) as usize));
                (kind::DEM_CHUNK, p, Err(Fault::BadLength))
            }
        };
        let accepted = self.session.controller.frames_accepted;
        self.one_frame(k, t_us, &payload, verdict, None);
        if self.session.controller.frames_accepted == accepted {
            return;
        }
        // Accepted: the model follows.
        let m = &mut self.model;
        if k == kind::DEM_BEGIN {
            m.dem_upload = Some(DemUpload {
                id: fresh,
                next: 0,
                crc_ok: !x.is_multiple_of(4),
            });
        } else if let Some(mut u) = m.dem_upload {
            u.next += 1;
            if u.next == DEM_CHUNKS {
                m.dem_in_force = u.id;
                m.dem_upload = None;
                m.dem_committed += 1;
            } else {
                m.dem_upload = Some(u);
            }
        }
    }

    /// END: the final STATUS carries every counter, and they reconcile.
    pub fn finish(&mut self) {
        let t = self.model.now_us;
        let end = self.frame(kind::END, t, &[]);
        self.model.frames_delivered += 1;
        self.model.delivered_bytes += end.len() as u64;
        self.model.frames_accepted += 1;
        let sent = self.feed(&end);
        assert!(self.session.is_ended());
        let s = sent.status.last().expect("a final STATUS");
        let c = &self.session.controller;
        assert_eq!(s.frames_accepted, c.frames_accepted);
        assert_eq!(s.updates, self.periods_frames);
        assert_eq!(s.skipped_bytes, self.model.skipped_bytes);
        assert_eq!(s.time_resyncs, self.model.time_resyncs);
        assert_eq!(&s.counts, c.counters.as_array());
        // The model's link takes every frame.
        assert_eq!(s.downlink_dropped, 0);
        assert_eq!(s.dem, c.dem_status(), "STATUS's DEM block");
        self.check();
    }
}

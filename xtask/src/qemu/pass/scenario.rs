//! What a pass is: NAV telemetry samples, TERRAIN uploads, the truth the checks use, and
//! the faults to inject. The built-in passes are made here: a J2 orbit, roll and pitch
//! manoeuvres, a mountain range, and the yaw steered by the firmware's own requests
//! (closed loop through a host run of the same controller); a user's pass comes from a
//! CSV file.

use anyhow::{anyhow, bail, Context, Result};
use controller::bus::{Gnss, StarAttitude};
use controller::frame::kind;
use controller::nav::{Attitude, Nav};
use controller::{Fault, EARTH};
use core_math::earth::dem::DemGrid;
use core_math::earth::kepler::Kepler;
use core_math::vector::{add, dot, scale};
use core_math::{StateVector, GM_M3_S2};

use super::bus::{EarthOrientation, Noise};
use super::stream::Frames;
use crate::csv::Table;
use core_math::earth::frames::Mat3;

/// One telemetry frame's content and time tag (pass time).
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub t_us: u64,
    pub msg: Msg,
}

/// What a telemetry frame carries: a NAV frame (a user's file), or the bus's GNSS,
/// ATTITUDE and TIME_SCALES ([`super::bus::SCALES`]) frames (the built-in passes).
#[derive(Clone, Copy, Debug)]
pub enum Msg {
    Nav(Nav),
    Gnss(Gnss),
    Attitude(StarAttitude),
    Scales,
}

/// J2 of the Earth's gravity field (EGM 2008, unnormalised) and its reference radius.
pub const J2: f64 = 1.082_626_68e-3;
/// Step of the truth orbit's grid (s).
const ORBIT_STEP_S: f64 = 1.0;

/// The truth orbit: an inertial state propagated under the Earth's central field and its
/// J2 term by fourth-order Runge-Kutta (1 s steps: the truncation error, (n h)^4 of the
/// orbit, is below 1e-12 of it), so that the firmware's two-body propagation between NAV
/// frames carries a real model error.
#[derive(Clone, Debug)]
pub struct J2Orbit {
    grid: Vec<StateVector>,
    /// Orbit time of the pass's t = 0 (s).
    start_s: f64,
}

fn accel(r: [f64; 3]) -> [f64; 3] {
    let r2 = dot(r, r);
    let rn = r2.sqrt();
    let mu_r3 = GM_M3_S2 / (r2 * rn);
    let re = EARTH.a_m;
    let z2 = r[2] * r[2] / r2;
    let k = 1.5 * J2 * re * re / r2;
    [
        -mu_r3 * r[0] * (1.0 + k * (1.0 - 5.0 * z2)),
        -mu_r3 * r[1] * (1.0 + k * (1.0 - 5.0 * z2)),
        -mu_r3 * r[2] * (1.0 + k * (3.0 - 5.0 * z2)),
    ]
}

fn rk4(s: &StateVector, h: f64) -> StateVector {
    // a + k b
    let step = |a, b, k| add(a, scale(k, b));
    let (r, v) = (s.position_m, s.velocity_mps);
    let (k1r, k1v) = (v, accel(r));
    let (k2r, k2v) = (step(v, k1v, h / 2.0), accel(step(r, k1r, h / 2.0)));
    let (k3r, k3v) = (step(v, k2v, h / 2.0), accel(step(r, k2r, h / 2.0)));
    let (k4r, k4v) = (step(v, k3v, h), accel(step(r, k3r, h)));
    StateVector {
        position_m: std::array::from_fn(|i| {
            r[i] + h / 6.0 * (k1r[i] + 2.0 * k2r[i] + 2.0 * k3r[i] + k4r[i])
        }),
        velocity_mps: std::array::from_fn(|i| {
            v[i] + h / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i])
        }),
    }
}

impl J2Orbit {
    /// From the osculating elements at t = 0: semi-major axis, eccentricity,
    /// inclination, node, argument of perigee, mean anomaly.
    pub fn new(
        a_m: f64,
        e: f64,
        i_rad: f64,
        raan_rad: f64,
        argp_rad: f64,
        m0_rad: f64,
        duration_s: f64,
    ) -> J2Orbit {
        // Kepler's equation for E, then the perifocal state turned into ECI.
        let mut ea = m0_rad;
        for _ in 0..50 {
            ea -= (ea - e * ea.sin() - m0_rad) / (1.0 - e * ea.cos());
        }
        let (se, ce) = ea.sin_cos();
        let root = (1.0 - e * e).sqrt();
        // dE/dt a = sqrt(GM a) / r.
        let speed = (GM_M3_S2 * a_m).sqrt() / (a_m * (1.0 - e * ce));
        let pf_r = [a_m * (ce - e), a_m * root * se];
        let pf_v = [-se * speed, root * ce * speed];
        let (so, co) = raan_rad.sin_cos();
        let (si, ci) = i_rad.sin_cos();
        let (sw, cw) = argp_rad.sin_cos();
        let p = [co * cw - so * sw * ci, so * cw + co * sw * ci, sw * si];
        let q = [-co * sw - so * cw * ci, -so * sw + co * cw * ci, cw * si];
        let s0 = StateVector {
            position_m: std::array::from_fn(|k| pf_r[0] * p[k] + pf_r[1] * q[k]),
            velocity_mps: std::array::from_fn(|k| pf_v[0] * p[k] + pf_v[1] * q[k]),
        };
        let steps = (duration_s / ORBIT_STEP_S).ceil() as usize + 2;
        let mut grid = Vec::with_capacity(steps);
        grid.push(s0);
        for k in 1..steps {
            let next = rk4(&grid[k - 1], ORBIT_STEP_S);
            grid.push(next);
        }
        J2Orbit { grid, start_s: 0.0 }
    }

    /// The ECI state at pass time `t_s` (0 <= t within the duration): one Runge-Kutta
    /// step from the grid point before it.
    pub fn state(&self, t_s: f64) -> StateVector {
        let t_s = t_s + self.start_s;
        let k = ((t_s / ORBIT_STEP_S).floor().max(0.0) as usize).min(self.grid.len() - 1);
        rk4(&self.grid[k], t_s - k as f64 * ORBIT_STEP_S)
    }

    /// Eccentricity of the osculating two-body orbit at `t_s` (for the pass line).
    pub fn eccentricity(&self, t_s: f64) -> f64 {
        let s = self.state(t_s);
        Kepler::new(s.position_m, s.velocity_mps, GM_M3_S2).map_or(f64::NAN, |k| k.eccentricity())
    }
}

/// An angle as a piecewise-linear function of time through `corners` (t_s, rad),
/// constant before the first and after the last.
#[derive(Clone, Debug)]
pub struct Profile {
    pub corners: Vec<(f64, f64)>,
}

impl Profile {
    /// The angle (rad) and its rate (rad/s; the rate of the piece starting at `t_s`).
    pub fn at(&self, t_s: f64) -> (f64, f64) {
        let c = &self.corners;
        let Some(&(t_first, r_first)) = c.first() else {
            return (0.0, 0.0);
        };
        if t_s < t_first {
            return (r_first, 0.0);
        }
        for w in c.windows(2) {
            let ((t0, r0), (t1, r1)) = (w[0], w[1]);
            if t_s >= t0 && t_s < t1 {
                let rate = (r1 - r0) / (t1 - t0);
                return (r0 + rate * (t_s - t0), rate);
            }
        }
        (c.last().map_or(r_first, |l| l.1), 0.0)
    }
}

/// The ground off the DEM tile: a plain a few hundred metres up, changing slowly along
/// track and across the swath (m above the ellipsoid, by time and segment index).
fn plain_m(t_s: f64, segment: usize) -> f64 {
    250.0 + 150.0 * (0.05 * t_s + 0.7 * segment as f64).sin()
}

/// The truth of a built-in pass: what the spacecraft really did.
#[derive(Clone, Debug)]
pub struct AgileTruth {
    pub orbit: J2Orbit,
    pub roll: Profile,
    pub pitch: Profile,
    /// The yaw the attitude control flew following the firmware's requests: (t_us,
    /// yaw, rate) at each NAV instant, linear in between.
    pub yaw: Vec<(u64, f64, f64)>,
    pub segments: usize,
    /// GPS time of the pass's t = 0 (us), the Earth's orientation, and C2T then.
    pub epoch_us: u64,
    pub earth: EarthOrientation,
    pub c2t0: Mat3,
}

impl AgileTruth {
    /// Attitude (rad, rad/s) at `t_s`.
    pub fn attitude(&self, t_s: f64) -> Attitude<f64> {
        let (roll, roll_rate) = self.roll.at(t_s);
        let (pitch, pitch_rate) = self.pitch.at(t_s);
        let t_us = us(t_s);
        let k = self.yaw.partition_point(|y| y.0 <= t_us);
        let (yaw, yaw_rate) = match k.checked_sub(1).and_then(|k| self.yaw.get(k)) {
            Some(&(t0, y, r)) => (y + r * (t_s - t0 as f64 * 1e-6), r),
            None => (0.0, 0.0),
        };
        Attitude {
            roll_rad: roll,
            pitch_rad: pitch,
            yaw_rad: yaw,
            roll_rate_rad_s: roll_rate,
            pitch_rate_rad_s: pitch_rate,
            yaw_rate_rad_s: yaw_rate,
        }
    }

    /// Ground heights of the scene's table at `t_s`.
    pub fn heights_m(&self, t_s: f64) -> Vec<f32> {
        (0..self.segments).map(|k| plain_m(t_s, k) as f32).collect()
    }

    /// The NAV content the spacecraft would send at `t_s`.
    pub fn nav(&self, t_s: f64) -> Nav {
        Nav {
            state: self.orbit.state(t_s),
            attitude: self.attitude(t_s).to::<f32>(),
        }
    }
}

/// A fault to inject at a pass time `t_s` (the time of its entry in [`Pass::faults`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Inject {
    /// One bit of the NAV frame at `t_s` flipped in its payload (the frame is lost).
    BitFlip,
    /// The NAV frame at `t_s` cut short after its header and 20 payload bytes.
    Truncate,
    /// `bytes` bytes of line noise (never a sync byte) after the frame at `t_s`.
    Noise { bytes: usize },
    /// After the frame at `t_s`, a good NAV frame time-tagged `back_s` earlier.
    Backwards { back_s: f64 },
    /// An extra NAV frame at `t_s` with a NaN velocity component.
    NaN,
    /// An extra NAV frame at `t_s` placing the spacecraft at `altitude_m`.
    Altitude { altitude_m: f64 },
    /// No NAV frame strictly between `t_s` and `t_s + len_s` (TIME goes on).
    Gap { len_s: f64 },
    /// After the frame at `t_s`, a TIME frame (valid CRC) tagged `tag_us`: beyond the
    /// time window, so refused as `time_jump` (issue 13's first defect).
    TimeTag { tag_us: u64 },
    /// An extra SCENE frame at `t_s` that the camera cannot use: refused as
    /// `invalid_scene` (issue 13's third defect).
    BadScene(SceneProbe),
    /// An extra TERRAIN frame at `t_s` with every height `height_m` (outside
    /// -500..=9 000 m): refused as `out_of_range`.
    Terrain { height_m: f32 },
    /// An extra NAV frame at `t_s` whose roll rate (0.5 rad/s) would carry it out of
    /// the scene's envelope: refused as `attitude_outside_model` (issue 12).
    Envelope,
    /// An extra DEM frame at `t_s` the camera refuses (issue 23).
    Dem(DemProbe),
    /// An extra ATTITUDE at `t_s` whose quaternion's norm is 1.01: `bad_quaternion`
    /// (issue 23).
    Quaternion,
    /// An extra GNSS frame at `t_s` whose fix is a second after its tag: `fix_time`.
    FixAfterTag,
    /// An extra TIME_SCALES at `t_s` with 70 leap seconds: `time_scales`.
    LeapSeconds,
}

/// The DEM frames the pass injects, each refused alone (the upload's multi-frame faults,
/// a height out of range or a wrong CRC in the middle of an upload, are the session
/// model's: `controller/tests/model/mod.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DemProbe {
    /// A DEM_BEGIN of a tile reaching past 88 deg of latitude: `dem_grid`.
    Pole,
    /// A DEM_CHUNK of no upload in progress: `dem_sequence`.
    StrayChunk,
    /// A DEM_BEGIN with the id of the tile in force: `dem_sequence`.
    SameId,
}

/// The scene the ground uploads at a pass's start: the firmware's boot scene, with the
/// camera's mounting for the bus's frames.
pub fn pass_scene(bus: bool) -> controller::Scene {
    let mut scene = controller::Scene::paper_default();
    if bus {
        scene.mounting_q = super::bus::mounting_q().map(|x| x as f32);
    }
    scene
}

/// The id of the tile the built-in passes upload at their start.
pub const PASS_DEM_ID: u32 = 23;

impl DemProbe {
    /// The payload's kind, the payload, and the fault it must be refused with.
    pub fn frame(&self, (grid, heights): &(DemGrid, Vec<i16>)) -> (u8, Vec<u8>, Fault) {
        let (grid, crc) = (*grid, controller::dem::heights_crc32(heights));
        match self {
            DemProbe::Pole => {
                let g = DemGrid {
                    lat0_deg: 87.99,
                    ..grid
                };
                let p = controller::dem::encode_begin(PASS_DEM_ID + 1, &g, crc).to_vec();
                (kind::DEM_BEGIN, p, Fault::DemGrid)
            }
            DemProbe::StrayChunk => {
                let mut out = [0u8; controller::frame::MAX_PAYLOAD];
                let n = controller::dem::encode_chunk(PASS_DEM_ID + 2, 0, heights, &mut out)
                    .unwrap_or(0);
                (kind::DEM_CHUNK, out[..n].to_vec(), Fault::DemSequence)
            }
            DemProbe::SameId => {
                let p = controller::dem::encode_begin(PASS_DEM_ID, &grid, crc).to_vec();
                (kind::DEM_BEGIN, p, Fault::DemSequence)
            }
        }
    }
}

/// The SCENE uploads an outside client found accepted before issue 13.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneProbe {
    /// A segment's `active` byte is 2.
    ActiveByte2,
    /// Largest stage count and a segment's stages 65 535.
    Stages65535,
    /// Every segment inactive.
    NoneActive,
    /// Two segments overlap.
    Overlap,
    /// 17 segments (a length that matches the count).
    Segments17,
}

impl SceneProbe {
    pub const ALL: [SceneProbe; 5] = [
        SceneProbe::ActiveByte2,
        SceneProbe::Stages65535,
        SceneProbe::NoneActive,
        SceneProbe::Overlap,
        SceneProbe::Segments17,
    ];

    /// The SCENE payload: the paper's scene, then the edit.
    pub fn payload(&self) -> Vec<u8> {
        use controller::scene::{SCENE_HEADER_LEN, SEGMENT_LEN};
        let mut scene = controller::Scene::paper_default();
        match self {
            SceneProbe::Stages65535 => {
                scene.max_stages = u16::MAX;
                scene.segments[0].tdi_stages = u16::MAX;
            }
            SceneProbe::NoneActive => scene.segments.iter_mut().for_each(|s| s.active = false),
            SceneProbe::Overlap => scene.segments[4].first_px = scene.segments[3].last_px - 999,
            SceneProbe::ActiveByte2 | SceneProbe::Segments17 => {}
        }
        let mut p = vec![0u8; controller::frame::MAX_PAYLOAD];
        let n = scene.encode(&mut p).unwrap_or(0);
        p.truncate(n);
        let seg = |k: usize| SCENE_HEADER_LEN + k * SEGMENT_LEN;
        match self {
            SceneProbe::ActiveByte2 => p[seg(3) + 10] = 2,
            SceneProbe::Segments17 => {
                // 17 chips of 3 529 pixels across the same array.
                p[42] = 17;
                let template = p[seg(0)..seg(1)].to_vec();
                p.truncate(SCENE_HEADER_LEN);
                for k in 0..17i32 {
                    let mut s = template.clone();
                    let first = -30_000 + 3_529 * k;
                    s[0..4].copy_from_slice(&first.to_le_bytes());
                    s[4..8].copy_from_slice(&(first + 3_528).to_le_bytes());
                    p.extend_from_slice(&s);
                }
            }
            _ => {}
        }
        p
    }
}

/// A pass: telemetry, truth, faults.
#[derive(Clone, Debug)]
pub struct Pass {
    pub name: String,
    /// NAV samples in sending order (the gaps already cut out).
    pub samples: Vec<Sample>,
    /// TERRAIN uploads: time tag and the heights of the scene's table (m).
    pub terrain: Vec<(u64, Vec<f32>)>,
    /// Cadence of TIME frames (us): the controller's update period.
    pub tick_us: u64,
    /// Last instant of the pass (us): TIME frames run up to it.
    pub end_us: u64,
    /// A built-in pass's truth: orbit, attitude, terrain, exact at any instant (None: a
    /// user's file, of which only the telemetry is known).
    pub truth: Option<Box<AgileTruth>>,
    /// The faults to inject, each at its pass time (s).
    pub faults: Vec<(f64, Inject)>,
    /// The DEM tile uploaded before imaging (the built-in passes'), grid and heights.
    pub dem: Option<(DemGrid, Vec<i16>)>,
    /// GPS time of t = 0 (us): the frames' time tags are this plus pass time.
    pub epoch_us: u64,
}

pub fn us(t_s: f64) -> u64 {
    (t_s * 1e6).round().max(0.0) as u64
}

/// The bus's rates in the built-in passes: GNSS at 1 Hz, the star tracker at 10 Hz.
pub const GNSS_PERIOD_US: u64 = 1_000_000;
pub const ATTITUDE_PERIOD_US: u64 = 100_000;
/// TERRAIN uploads of the built-in passes: once a second, 0.13 s after the second
/// (between two attitudes), with the heights at the middle of the second they serve.
pub const TERRAIN_PERIOD_US: u64 = 1_000_000;
pub const TERRAIN_OFFSET_US: u64 = 130_000;
/// Time constant of the attitude control's yaw tracking (s), its largest yaw rate
/// (rad/s) and yaw acceleration (rad/s^2): a yaw
/// steering law is slow and smooth (a yaw rate turns the image about the boresight, so
/// a jerky one would move the swath's ends along track).
const YAW_TAU_S: f64 = 4.0;
const MAX_YAW_RATE_RAD_S: f64 = 2e-3;
const MAX_YAW_ACCEL_RAD_S2: f64 = 4e-4;

/// The truth orbit of the built-in passes: sun-synchronous, 645 km, e = 0.001 (perigee
/// 638 km, apogee 652 km), i = 97.98 deg, J2 included; the pass's t = 0 at orbit time
/// `start_s`.
pub fn sun_synchronous(start_s: f64, duration_s: f64) -> J2Orbit {
    let orbit = J2Orbit::new(
        EARTH.a_m + 645e3,
        0.001,
        97.98f64.to_radians(),
        0.4,
        1.2,
        -1.6,
        start_s + duration_s,
    );
    J2Orbit { start_s, ..orbit }
}

/// GPS time of the orbit's t = 0 (us since 1980-01-06, late November 2026): the
/// orbit's inertial frame is the ITRF frozen then (Part I's I).
pub const EPOCH_GPS_US: u64 = 1_480_000_000_000_000;
/// Orbit time at which the short pass starts: its roll slew then looks at the ground
/// the default pass's forward stereo look sees, where the DEM tile lies.
pub const SHORT_START_S: f64 = 280.0;

/// What one kind of frame goes where in a pass's time line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlotKind {
    Nav,
    Terrain,
    Time,
}

/// The time line of a pass: NAV frames at `nav_us`, TERRAIN frames at `terrain_us`, TIME
/// frames at every tick of the update period that has no other frame, up to `end_us`,
/// all in time order (NAV before TERRAIN at one instant). The player that builds a pass
/// and the stream that sends it walk this same list.
pub fn schedule(
    nav_us: &[u64],
    terrain_us: &[u64],
    tick_us: u64,
    end_us: u64,
) -> Vec<(u64, SlotKind)> {
    let mut slots: Vec<(u64, SlotKind)> = nav_us
        .iter()
        .map(|&t| (t, SlotKind::Nav))
        .chain(terrain_us.iter().map(|&t| (t, SlotKind::Terrain)))
        .collect();
    let taken: std::collections::BTreeSet<u64> = slots.iter().map(|s| s.0).collect();
    let tick = tick_us.max(1);
    slots.extend(
        (0..=end_us / tick)
            .map(|k| k * tick)
            .filter(|t| !taken.contains(t))
            .map(|t| (t, SlotKind::Time)),
    );
    let order = |k: SlotKind| match k {
        SlotKind::Nav => 0,
        SlotKind::Terrain => 1,
        SlotKind::Time => 2,
    };
    slots.sort_by_key(|&(t, k)| (t, order(k)));
    slots
}

/// A built-in pass: its attitude manoeuvres, terrain and faults.
pub struct Manoeuvres {
    pub name: &'static str,
    /// Orbit time of the pass's t = 0 (s).
    pub start_s: f64,
    pub duration_s: f64,
    pub roll: Profile,
    pub pitch: Profile,
    /// The faults to inject, each at its pass time (s).
    pub faults: Vec<(f64, Inject)>,
}

/// Plays `m` through a host run of the firmware's controller to fly the yaw it asks
/// for: at each attitude instant the attitude control turns the yaw towards the last
/// request (the yaw at that update plus the correction) with a first-order lag, and the
/// ATTITUDE frame reports the attitude it flies. The host run sees exactly the clean
/// stream the firmware will see (the injected faults change no output, which the pass
/// checks), so its requests are the firmware's.
pub fn build(m: Manoeuvres, dem: (DemGrid, Vec<i16>), tick_us: u64) -> Result<Pass> {
    use controller::frame::kind;
    let end_us = us(m.duration_s);
    let epoch_us = EPOCH_GPS_US + us(m.start_s);
    super::check::set_epoch(epoch_us);
    let in_gap = |t_us: u64| {
        m.faults.iter().any(|&(t_s, f)| match f {
            Inject::Gap { len_s } => t_us > us(t_s) && t_us < us(t_s + len_s),
            _ => false,
        })
    };
    // Tags: TIME_SCALES first, then each attitude at its time of validity (the
    // profiles change rate at those instants, so the gyros' rate in force is the rate
    // flown: see docs/telemetry.md) and each fix 50 ms after its time of fix.
    let mut kinds = std::collections::BTreeMap::from([(0, Kind::Scales)]);
    // TIME_SCALES again every second, before the fix: a camera reset loses it.
    kinds.extend((1..end_us / GNSS_PERIOD_US).map(|k| (k * GNSS_PERIOD_US + 40_000, Kind::Scales)));
    kinds
        .extend((1..end_us / ATTITUDE_PERIOD_US).map(|k| (k * ATTITUDE_PERIOD_US, Kind::Attitude)));
    kinds.extend((0..end_us / GNSS_PERIOD_US).map(|k| (k * GNSS_PERIOD_US + 50_000, Kind::Gnss)));
    kinds.retain(|&t, _| t <= end_us && !in_gap(t));
    let tags: Vec<u64> = kinds.keys().copied().collect();
    // The first heights before the first update, after the uploads of the start.
    let terrain_us: Vec<u64> = std::iter::once(1_000)
        .chain((0..end_us / TERRAIN_PERIOD_US).map(|k| k * TERRAIN_PERIOD_US + TERRAIN_OFFSET_US))
        .collect();
    let scene = controller::Scene::paper_default();
    // From the orbit's t = 0, whose ITRF is I0.
    let gps0_s = (EPOCH_GPS_US / 1_000_000) as i64;
    let earth = EarthOrientation::new(gps0_s, (m.start_s + m.duration_s).ceil() as usize + 3)?;
    let mut truth = AgileTruth {
        orbit: sun_synchronous(m.start_s, m.duration_s + 2.0),
        roll: m.roll,
        pitch: m.pitch,
        yaw: Vec::new(),
        segments: usize::from(scene.count),
        epoch_us,
        c2t0: earth.c2t(gps0_s as f64),
        earth,
    };
    let mut controller = controller::Controller::new(controller::Config::default(), scene)
        .map_err(|f| anyhow!("the default scene was refused: {}", f.name()))?;
    // The DEM upload's memory, as the firmware's: the yaw requests the attitude follows
    // are then over the tile, as the firmware's are.
    controller.attach_dem(Box::leak(Box::new(controller::dem::DemStore::new())));
    let mut session = controller::session::Session::new(controller);
    let mut frames = Frames::default();
    let feed = |session: &mut controller::session::Session, frame: Vec<u8>| {
        session.feed(&frame, &mut super::check::Accept, |_| {});
    };
    let (mut samples, mut terrain) = (Vec::new(), Vec::new());
    // The pass starts steered: the request of a first update at t = 0 with the yaw at 0
    // (from a NAV frame: Part I's attitude, which has no mounting).
    let mut target_rad = {
        // A controller as the session's is now (fresh, the default scene).
        let mut probe = controller::Controller::new(controller::Config::default(), scene)
            .map_err(|f| anyhow!("the default scene was refused: {}", f.name()))?;
        let frame = Frames::default().nav(0, &truth.nav(0.0));
        let mut decoder = controller::frame::Decoder::new();
        decoder.feed(&frame, |e| {
            if let controller::frame::Event::Frame(f) = e {
                probe.on_frame(&f);
            }
        });
        probe.advance(epoch_us, &mut super::check::Accept);
        f64::from(
            probe
                .yaw_request_rad()
                .context("no yaw request at the start of the pass")?,
        )
    };
    truth.yaw.push((0, target_rad, 0.0));
    let mut rate_rad_s = 0.0f64;
    let (mut gnss_noise, mut star_noise) = (Noise::new(0x6e55), Noise::new(0x57a7));
    for (t_us, slot) in schedule(&tags, &terrain_us, tick_us, end_us) {
        let t_s = t_us as f64 * 1e-6;
        match (slot, kinds.get(&t_us)) {
            (SlotKind::Nav, Some(Kind::Scales)) => {
                feed(&mut session, frames.msg(t_us, &Msg::Scales));
                if t_us == 0 {
                    for f in super::stream::uploads(&mut frames, true, Some(&dem), t_us) {
                        feed(&mut session, f);
                    }
                }
                samples.push(Sample {
                    t_us,
                    msg: Msg::Scales,
                });
            }
            (SlotKind::Nav, Some(Kind::Gnss)) => {
                let fix_s = t_s - 0.05;
                let msg = Msg::Gnss(truth.gnss(fix_s, Some(&mut gnss_noise)));
                feed(&mut session, frames.msg(t_us, &msg));
                samples.push(Sample { t_us, msg });
            }
            (SlotKind::Nav, _) => {
                let valid_s = t_s;
                let c = &session.controller;
                if let (Some(request), Some(u)) = (c.yaw_request_rad(), c.last_update_us()) {
                    let u_s = (u - epoch_us) as f64 * 1e-6;
                    target_rad = truth.attitude(u_s).yaw_rad + f64::from(request);
                }
                let yaw = truth.attitude(valid_s).yaw_rad;
                let wanted =
                    ((target_rad - yaw) / YAW_TAU_S).clamp(-MAX_YAW_RATE_RAD_S, MAX_YAW_RATE_RAD_S);
                let step = MAX_YAW_ACCEL_RAD_S2 * ATTITUDE_PERIOD_US as f64 * 1e-6;
                rate_rad_s += (wanted - rate_rad_s).clamp(-step, step);
                truth.yaw.push((us(valid_s), yaw, rate_rad_s));
                let msg = Msg::Attitude(truth.star(valid_s, Some(&mut star_noise))?);
                feed(&mut session, frames.msg(t_us, &msg));
                samples.push(Sample { t_us, msg });
            }
            (SlotKind::Terrain, _) => {
                let heights = truth.heights_m(t_s + 0.5);
                let payload = terrain_payload(&heights);
                feed(&mut session, frames.frame(kind::TERRAIN, t_us, &payload));
                terrain.push((t_us, heights));
            }
            (SlotKind::Time, _) => feed(&mut session, frames.frame(kind::TIME, t_us, &[])),
        }
    }
    Ok(Pass {
        name: m.name.to_string(),
        samples,
        terrain,
        tick_us,
        end_us,
        truth: Some(Box::new(truth)),
        faults: m.faults,
        dem: Some(dem),
        epoch_us,
    })
}

/// The bus frames of a built-in pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Scales,
    Gnss,
    Attitude,
}

/// A TERRAIN payload of `heights`.
pub fn terrain_payload(heights: &[f32]) -> Vec<u8> {
    let t = controller::Terrain {
        heights_m: std::array::from_fn(|k| heights.get(k).copied().unwrap_or(0.0)),
        count: heights.len() as u8,
    };
    let mut p = [0u8; 128];
    let n = t.encode(&mut p).unwrap_or(0);
    p[..n].to_vec()
}

/// The link probes of issue 13 from `t0_s` on: a TIME frame tagged 2^64 - 1, one an
/// hour ahead, then each SCENE the camera cannot use; every one must be refused under
/// its own counter and change nothing.
fn link_probes(t0_s: f64) -> Vec<(f64, Inject)> {
    let mut out = vec![
        (t0_s, Inject::TimeTag { tag_us: u64::MAX }),
        (
            t0_s + 0.5,
            Inject::TimeTag {
                tag_us: us(t0_s + 0.5 + 3600.0),
            },
        ),
    ];
    for (k, probe) in SceneProbe::ALL.into_iter().enumerate() {
        out.push((t0_s + 1.005 + 0.001 * k as f64, Inject::BadScene(probe)));
    }
    out
}

/// The bus probes of issue 23 from `t0_s` on, a second apart.
fn bus_probes(t0_s: f64) -> [(f64, Inject); 3] {
    use Inject::{FixAfterTag, LeapSeconds, Quaternion};
    [
        (t0_s, Quaternion),
        (t0_s + 1.0, FixAfterTag),
        (t0_s + 2.0, LeapSeconds),
    ]
}

fn deg(corners: &[(f64, f64)]) -> Profile {
    Profile {
        corners: corners.iter().map(|&(t, a)| (t, a.to_radians())).collect(),
    }
}

/// The default pass: ten minutes of the sun-synchronous J2 orbit over a mountain range
/// (ridge at 300 s, up to 4 900 m). Roll 0 -> 20 deg at 1 deg/s (40-60 s), held, back
/// (140-160 s); a stereo pair: pitch 0 -> +20 deg at 0.2 deg/s (180-280 s), held
/// (forward look), -> -20 deg (310-510 s), held (backward look); yaw steered by the
/// firmware's requests. (A pitch rate is seen whole in the image motion: at 0.2 deg/s it
/// changes |v1| by a third of the ground's 0.6 deg/s; a stereo slew at 1 deg/s would
/// reverse it.) Faults spread over it, none at a corner of a profile (a lost frame there
/// would leave the controller extrapolating the old rate, which is the telemetry's loss,
/// not an error).
pub fn default_pass(dem: (DemGrid, Vec<i16>), tick_us: u64) -> Result<Pass> {
    build(default_manoeuvres(), dem, tick_us)
}

/// The default pass's manoeuvres, terrain and faults.
pub fn default_manoeuvres() -> Manoeuvres {
    use Inject::*;
    let mut faults = vec![
        (30.0, BitFlip),
        (70.5, BitFlip),
        (120.2, Truncate),
        (150.0, Noise { bytes: 48 }),
        (190.0, Backwards { back_s: 1.0 }),
        (230.335, Terrain { height_m: 9_500.0 }),
        (240.125, Envelope),
        (250.125, NaN),
        (310.125, Altitude { altitude_m: 100e3 }),
        (410.0, BitFlip),
        (520.0, Gap { len_s: 2.0 }),
    ];
    faults.extend(link_probes(160.0));
    faults.extend(bus_probes(200.125));
    Manoeuvres {
        name: "default pass (600 s)",
        start_s: 0.0,
        duration_s: 600.0,
        roll: deg(&[(40.0, 0.0), (60.0, 20.0), (140.0, 20.0), (160.0, 0.0)]),
        pitch: deg(&[(180.0, 0.0), (280.0, 20.0), (310.0, 20.0), (510.0, -20.0)]),
        faults,
    }
}

/// The end-to-end test's pass: one minute, roll 0 -> 20 deg at 1.25 deg/s, then pitch
/// 0 -> 5 deg at 0.2 deg/s, a ridge at 40 s, every kind of fault.
pub fn short_pass(dem: (DemGrid, Vec<i16>), tick_us: u64) -> Result<Pass> {
    build(short_manoeuvres(), dem, tick_us)
}

/// The short pass's manoeuvres, terrain and faults.
pub fn short_manoeuvres() -> Manoeuvres {
    use Inject::*;
    let mut faults = vec![
        (5.0, BitFlip),
        (8.0, Truncate),
        (12.0, Noise { bytes: 40 }),
        (15.0, Backwards { back_s: 0.5 }),
        (18.125, NaN),
        (22.335, Terrain { height_m: -800.0 }),
        (24.125, Envelope),
        (26.125, Altitude { altitude_m: 100e3 }),
        (40.0, BitFlip),
        (52.0, Gap { len_s: 2.0 }),
        (33.0105, Dem(DemProbe::Pole)),
        (33.0305, Dem(DemProbe::StrayChunk)),
        (33.0505, Dem(DemProbe::SameId)),
    ];
    faults.extend(link_probes(28.0));
    faults.extend(bus_probes(34.125));
    Manoeuvres {
        name: "short pass (60 s)",
        start_s: SHORT_START_S,
        duration_s: 60.0,
        roll: deg(&[(8.5, 0.0), (24.5, 20.0)]),
        pitch: deg(&[(30.0, 0.0), (55.0, 5.0)]),
        faults,
    }
}

/// The CSV columns of a telemetry file, in this order when written.
pub const CSV_COLUMNS: [&str; 13] = [
    "t_s",
    "rx_m",
    "ry_m",
    "rz_m",
    "vx_mps",
    "vy_mps",
    "vz_mps",
    "roll_rad",
    "pitch_rad",
    "yaw_rad",
    "roll_rate",
    "pitch_rate",
    "yaw_rate",
];

/// Reads a telemetry CSV file (header naming [`CSV_COLUMNS`] in any order, `#` lines
/// ignored); the rows are sent in file order.
pub fn from_csv(path: &std::path::Path, tick_us: u64) -> Result<Pass> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read telemetry {}", path.display()))?;
    let text: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    let table = Table::parse(&text).with_context(|| format!("{}", path.display()))?;
    let cols = table.columns(&CSV_COLUMNS)?;
    let mut samples = Vec::with_capacity(table.rows.len());
    for (i, row) in table.rows.iter().enumerate() {
        let at = || format!("{}: line {}", path.display(), i + 2);
        let mut v = [0.0f64; CSV_COLUMNS.len()];
        for ((x, &col), name) in v.iter_mut().zip(&cols).zip(CSV_COLUMNS) {
            let text = row
                .get(col)
                .with_context(|| format!("{}: too few fields", at()))?;
            *x = (text.parse())
                .map_err(|_| anyhow!("{}: `{text}` is not a number ({name})", at()))?;
        }
        let [t_s, rx, ry, rz, vx, vy, vz, a @ ..] = v;
        if !(0.0..1e9).contains(&t_s) {
            bail!("{}: time {t_s} s out of range", at());
        }
        let [roll, pitch, yaw, roll_rate, pitch_rate, yaw_rate] = a.map(|x| x as f32);
        let state = StateVector {
            position_m: [rx, ry, rz],
            velocity_mps: [vx, vy, vz],
        };
        let attitude = Attitude {
            roll_rad: roll,
            pitch_rad: pitch,
            yaw_rad: yaw,
            roll_rate_rad_s: roll_rate,
            pitch_rate_rad_s: pitch_rate,
            yaw_rate_rad_s: yaw_rate,
        };
        let msg = Msg::Nav(Nav { state, attitude });
        samples.push(Sample { t_us: us(t_s), msg });
    }
    let end_us = samples
        .iter()
        .map(|s| s.t_us)
        .max()
        .with_context(|| format!("{}: no telemetry rows", path.display()))?;
    Ok(Pass {
        name: format!("telemetry from {}", path.display()),
        samples,
        tick_us,
        end_us,
        terrain: Vec::new(),
        truth: None,
        faults: Vec::new(),
        dem: None,
        epoch_us: 0,
    })
}

/// The pass's NAV frames.
pub fn navs(pass: &Pass) -> Vec<(u64, Nav)> {
    let nav = |s: &Sample| match s.msg {
        Msg::Nav(n) => Some((s.t_us, n)),
        _ => None,
    };
    pass.samples.iter().filter_map(nav).collect()
}

/// Writes the pass's NAV frames as a telemetry CSV file.
pub fn to_csv(pass: &Pass, path: &std::path::Path) -> Result<()> {
    let preamble = format!("# {} (see docs/telemetry.md)\n", pass.name);
    let mut out = crate::csv::Writer::new(&preamble, &CSV_COLUMNS)?;
    // A built-in pass's NAV frames: the truth's state in I0 and Part I's attitude at
    // 4 Hz (what a NAV client would send for it).
    let navs: Vec<(u64, Nav)> = match pass.truth.as_deref() {
        Some(truth) => (0..=pass.end_us / 250_000)
            .map(|k| (k * 250_000, truth.nav(k as f64 * 0.25)))
            .collect(),
        None => navs(pass),
    };
    for (t_us, nav) in navs {
        let (r, v, a) = (nav.state.position_m, nav.state.velocity_mps, nav.attitude);
        let state = [r[0], r[1], r[2], v[0], v[1], v[2]].map(|x| format!("{x:?}"));
        let attitude = [
            a.roll_rad,
            a.pitch_rad,
            a.yaw_rad,
            a.roll_rate_rad_s,
            a.pitch_rate_rad_s,
            a.yaw_rate_rad_s,
        ]
        .map(|x| format!("{x:?}"));
        let t = (t_us as f64 * 1e-6).to_string();
        out.row(&[[t].as_slice(), &state, &attitude].concat())?;
    }
    std::fs::write(path, out.into_bytes()?).with_context(|| format!("writing {}", path.display()))
}

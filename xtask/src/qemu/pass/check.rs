//! The host side of the checks: the twin run (the same `controller` crate, same
//! `Session`, on the host), the downlink decoder, the reference periods.

use anyhow::{anyhow, Result};
use std::collections::BTreeMap;
use std::convert::Infallible;
use std::sync::atomic::{AtomicU64, Ordering};

use controller::bus::{Gnss, StarAttitude};
use controller::frame::{kind, Decoder, Event};
use controller::golden::{self, NavInput, UpdateGolden};
use controller::report::{Periods, Status};
use controller::session::Session;
use controller::{Config, Controller, LinePeriodSink, Scene};
use core_math::earth::dem::DemTile;
use core_math::earth::frames::TimeScales;
use core_math::ModelError;

/// GPS time of the pass's t = 0 (us): frames carry GPS time, the checks and reports
/// pass time. One pass is played at a time; `scenario::build` and `play` set it.
static EPOCH_US: AtomicU64 = AtomicU64::new(0);

pub fn set_epoch(epoch_us: u64) {
    EPOCH_US.store(epoch_us, Ordering::Relaxed);
}

pub fn epoch_us() -> u64 {
    EPOCH_US.load(Ordering::Relaxed)
}

/// Pass time of a frame's time tag.
pub fn pass_us(tag_us: u64) -> u64 {
    tag_us.saturating_sub(epoch_us())
}

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
                d.periods.push((pass_us(f.time_us), f.payload.to_vec()))
            }
            Event::Frame(f) if f.kind == kind::STATUS => match Status::decode(f.payload) {
                Some(s) => d.status.push((pass_us(f.time_us), s)),
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
    c.note_boot(controller::fault::ResetCause::PowerOn, 0);
    // The firmware's tile memory (retained RAM there); a host run's is never given back.
    c.attach_dem(Box::leak(Box::new(controller::dem::DemStore::new())));
    Ok(c)
}

/// What the controller had in force at one update: the NAV frame or the bus's GNSS
/// fix, attitude and time scales, the ground heights, whether a DEM tile was in force.
#[derive(Clone, Debug)]
pub struct InForce {
    pub source: Source,
    pub heights_m: Vec<f32>,
    pub dem: bool,
}

impl InForce {
    /// The f64 reference of the update at pass time `t_us` on these inputs
    /// (`controller::golden`), on the pass's DEM `tile` if one was in force, with the
    /// star tracker's attitude `turned` instead of the one received when given.
    pub fn reference(
        &self,
        c: &Controller,
        t_us: u64,
        tile: Option<&DemTile<'_, i16>>,
        turned: Option<&StarAttitude>,
    ) -> Result<UpdateGolden, ModelError> {
        let (scene, plan, h) = (c.scene(), c.plan(), &self.heights_m[..]);
        let t_gps = t_us + epoch_us();
        match (&self.source, tile.filter(|_| self.dem)) {
            (Source::Nav(nav), _) => golden::update(scene, plan, h, nav, t_gps),
            (Source::Bus(g, a, sc), None) => {
                golden::bus_update(scene, plan, h, g, turned.unwrap_or(a), sc, t_gps)
            }
            (Source::Bus(g, a, sc), Some(tile)) => {
                let a = turned.unwrap_or(a);
                golden::bus_update_on_dem(scene, plan, h, g, a, sc, t_gps, tile)
            }
        }
    }
}

#[derive(Clone, Debug)]
pub enum Source {
    Nav(NavInput),
    Bus(Gnss, StarAttitude, TimeScales),
}

/// The inputs in force at each update, by update instant.
pub type Inputs = BTreeMap<u64, InForce>;

/// A host run of the firmware's session: the session after it, the frames it sent, and
/// the inputs in force at each update (the reference check's).
pub struct HostRun {
    pub session: Session,
    pub sent: Vec<u8>,
    pub inputs: Inputs,
}

impl HostRun {
    /// A session after power-on fed `bytes`.
    pub fn new(bytes: &[u8], config: Config) -> Result<HostRun> {
        Ok(HostRun::from(Session::new(new_controller(config)?), bytes))
    }

    /// The host's model of a reset between two frames: `prefix` after power-on, then a
    /// core that comes up with `cause` (its `resets`-th since power-on), restores the
    /// snapshot the first session kept, and runs `suffix`: the frames both sent, as the
    /// firmware's downlink would carry them, and the inputs both had in force (the
    /// attitude blend restarted by the reset included).
    pub fn reset(
        prefix: &[u8],
        suffix: &[u8],
        cause: controller::fault::ResetCause,
        resets: u32,
        config: Config,
    ) -> Result<HostRun> {
        let HostRun {
            session,
            mut sent,
            mut inputs,
        } = HostRun::new(prefix, config)?;
        let after = Session::new(restarted(session, cause, resets, config)?);
        let after = HostRun::from(after, suffix);
        sent.extend_from_slice(&after.sent);
        inputs.extend(after.inputs);
        Ok(HostRun {
            sent,
            inputs,
            ..after
        })
    }

    /// `bytes` through `session` byte by byte, as the firmware takes them.
    fn from(mut session: Session, bytes: &[u8]) -> HostRun {
        let mut sent = Vec::new();
        let mut inputs = BTreeMap::new();
        for &b in bytes {
            let mut periods_sent = false;
            let ended = session.feed(&[b], &mut Accept, |frame| {
                periods_sent |= frame.get(3) == Some(&kind::PERIODS);
                sent.extend_from_slice(frame);
            });
            if let (true, Some(t)) = (periods_sent, session.controller.last_update_us()) {
                if let Some(in_force) = in_force(&session.controller) {
                    inputs.insert(pass_us(t), in_force);
                }
            }
            if ended {
                break;
            }
        }
        HostRun {
            session,
            sent,
            inputs,
        }
    }

    pub fn downlink(&self) -> Downlink {
        Downlink::decode(&self.sent)
    }
}

/// What `c` has in force for its update.
fn in_force(c: &Controller) -> Option<InForce> {
    let source = match (c.nav(), c.gnss(), c.bus_attitude()) {
        (Some(nav), ..) => Source::Nav(NavInput {
            state: nav.propagator.state,
            attitude: nav.attitude,
            time_us: nav.time_us,
        }),
        (None, Some(g), Some(a)) => {
            // The fix as received: v = v_I - w x r.
            let (r, v, w) = (
                g.propagator.state.position_m,
                g.propagator.state.velocity_mps,
                core_math::EARTH_RATE_RAD_S,
            );
            let gnss = Gnss {
                fix_us: g.fix_us,
                position_m: r,
                velocity_mps: [v[0] + w * r[1], v[1] - w * r[0], v[2]],
            };
            Source::Bus(gnss, a.received, *c.time_scales())
        }
        _ => return None,
    };
    Some(InForce {
        source,
        heights_m: c.heights_m().to_vec(),
        dem: c.dem_tile().is_some(),
    })
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

/// The controller after a reset of `before`'s: blank, its snapshot restored, the DEM
/// tile memory kept.
fn restarted(
    mut before: Session,
    cause: controller::fault::ResetCause,
    resets: u32,
    config: Config,
) -> Result<Controller> {
    let mut snapshot = controller::restart::Snapshot::EMPTY;
    let kept = before.controller.snapshot_inputs(&mut snapshot)
        && before.controller.snapshot_periods(&mut snapshot.periods)
        && before.controller.snapshot_attitude(&mut snapshot.attitude);
    if !kept {
        return Err(anyhow!("the host run kept no snapshot before the reset"));
    }
    let mut c = Controller::blank(config);
    c.note_boot(cause, resets);
    c.restore(&snapshot, &mut Accept)
        .map_err(|f| anyhow!("the host run refused its own snapshot: {}", f.name()))?;
    // The DEM tile memory outlives the reset, as the firmware's retained RAM does; the
    // firmware puts the tile recorded there back after the periods, and so does this.
    if let Some(store) = before.controller.detach_dem() {
        c.attach_dem(store);
        // Nothing recorded (no tile before the reset) is a refusal here, as there.
        let _ = c.restore_dem();
    }
    Ok(c)
}

/// Where `uplink` may be cut between two frames at `at_us`: after the last whole frame
/// tagged before it that comes before the first frame tagged within a second after it
/// (a frame far ahead, such as an injected time jump, does not mark the instant). What
/// follows the cut, noise included, belongs to the rest.
pub fn cut_before(uplink: &[u8], at_us: u64) -> usize {
    let mut decoder = Decoder::new();
    let mut cut = 0;
    for (i, &b) in uplink.iter().enumerate() {
        let mut tag = None;
        decoder.feed(&[b], |e| {
            if let Event::Frame(f) = e {
                tag = Some(f.time_us);
            }
        });
        match tag.map(pass_us) {
            Some(t) if (at_us..at_us.saturating_add(1_000_000)).contains(&t) => break,
            Some(t) if t < at_us => cut = i + 1,
            _ => {}
        }
    }
    cut
}

/// How many whole frames `bytes` holds.
pub fn frame_count(bytes: &[u8]) -> usize {
    let mut n = 0;
    Decoder::new().feed(bytes, |e| n += usize::from(matches!(e, Event::Frame(_))));
    n
}

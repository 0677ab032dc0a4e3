//! What a reset must not lose, and why the core last started.
//!
//! A [`Snapshot`] holds the scene in force, its ground heights, the time scales and the
//! last periods, each in the telemetry's own encoding (a SCENE, a TERRAIN, a TIME_SCALES
//! and a PERIODS payload): the
//! codecs and checks are the ones the link uses, and the encoding does not depend on how
//! a build lays out its structures, so a snapshot left by another build is decoded and
//! checked like any frame from the ground, not misread. The firmware keeps it in RAM that
//! survives a reset (firmware/src/retained.rs, under a CRC) and, after a reset, hands it
//! to [`Controller::restore`]: the periods go back into the registers first, then the
//! scene is planned and the heights put back; every period stays flagged held until
//! the first update on fresh telemetry (docs/target.md, "Faults and resets").

use crate::bus::{decode_time_scales, encode_time_scales, StarAttitude};
use crate::control::{Controller, SegmentOutput};
use crate::fault::Fault;
use crate::frame::MAX_PAYLOAD;
use crate::report::{encode_periods, Periods};
use crate::scene::{Scene, Terrain, MAX_SEGMENTS};
use crate::sink::LinePeriodSink;

/// One payload and its length. `repr(C)` with only integers, so that RAM kept across a
/// reset can hold one: any contents are a valid value, checked before use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct Payload {
    pub len: u16,
    pub bytes: [u8; MAX_PAYLOAD],
}

impl Payload {
    pub const EMPTY: Payload = Payload {
        len: 0,
        bytes: [0; MAX_PAYLOAD],
    };

    // Out of line: the restore inlined it at each of its payloads.
    #[inline(never)]
    pub fn as_slice(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or(&[])
    }

    /// Fills the payload with `encode`'s output; false (and empty) if it did not fit.
    fn fill(&mut self, encode: impl FnOnce(&mut [u8]) -> Option<usize>) -> bool {
        let len = encode(&mut self.bytes).and_then(|n| u16::try_from(n).ok());
        self.len = len.unwrap_or(0);
        len.is_some()
    }
}

/// The state a reset must not lose (see the module's documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct Snapshot {
    /// The scene in force (a SCENE payload).
    pub scene: Payload,
    /// The ground heights in force (a TERRAIN payload).
    pub terrain: Payload,
    /// GPS - UTC and UT1 - UTC in force (a TIME_SCALES payload): without them a reset
    /// would fall back to the defaults (UT1 - UTC = 0) until the bus sends them again,
    /// up to 0.9 s of Earth rotation in the C2T.
    pub time_scales: Payload,
    /// The outputs in force (a PERIODS payload).
    pub periods: Payload,
    /// The attitude estimate in force (an ATTITUDE payload: the blended quaternion,
    /// its body rates and time of validity; empty before the first): the attitude
    /// blend goes on from it after a reset, so that a reset that loses no frame changes
    /// no period once fresh frames arrive.
    pub attitude: Payload,
}

impl Snapshot {
    pub const EMPTY: Snapshot = Snapshot {
        scene: Payload::EMPTY,
        terrain: Payload::EMPTY,
        time_scales: Payload::EMPTY,
        periods: Payload::EMPTY,
        attitude: Payload::EMPTY,
    };
}

/// What [`Controller::restore`] put back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Restored {
    /// Periods written to the sink (and held).
    pub periods: usize,
}

impl Controller {
    /// Writes the scene, ground heights and time scales in force into `out` (they change
    /// only with a SCENE, TERRAIN or TIME_SCALES frame: [`Controller::inputs_generation`]
    /// tells when). False if they do not fit (never for values the controller accepted).
    pub fn snapshot_inputs(&self, out: &mut Snapshot) -> bool {
        let terrain = Terrain {
            heights_m: self.heights_m,
            count: self.scene.count,
        };
        // Exact: the leap seconds are whole and UT1 - UTC came in as an f32.
        let (leap_s, dut1_s) = (
            self.time_scales.gps_utc_s as i16,
            self.time_scales.dut1_s as f32,
        );
        out.scene.fill(|b| self.scene.encode(b))
            && out.terrain.fill(|b| terrain.encode(b))
            && out
                .time_scales
                .fill(|b| encode_time_scales(leap_s, dut1_s, b))
    }

    /// Writes the outputs in force into `out` (after every update).
    pub fn snapshot_periods(&self, out: &mut Payload) -> bool {
        out.fill(|b| encode_periods(self, b))
    }

    /// Writes the attitude estimate in force into `out` (empty without one; after
    /// every update, with the periods).
    pub fn snapshot_attitude(&self, out: &mut Payload) -> bool {
        match &self.attitude {
            Some(a) => out.fill(|b| a.received.encode(b)),
            None => out.fill(|_| Some(0)),
        }
    }

    /// Puts `snapshot` back after a reset: [`write_kept_periods`], then
    /// [`Controller::restore_kept`].
    pub fn restore<S: LinePeriodSink>(
        &mut self,
        snapshot: &Snapshot,
        sink: &mut S,
    ) -> Result<Restored, Fault> {
        let kept = write_kept_periods(snapshot, sink)?;
        self.restore_kept(snapshot, kept)
    }

    /// The rest of a restore once [`write_kept_periods`] has put the periods back: the
    /// scene, planned, and its heights; every output written is flagged held. The NAV
    /// state, the clock, the counters stay as they are (a controller fresh from
    /// [`Controller::blank`]: waiting for NAV).
    ///
    /// The checks are those of the frames: heights out of range or a scene the planner
    /// refuses give that fault and change nothing but the registers already written,
    /// whose periods the snapshot held in force before.
    // Not inlined: its frames (a decoded PERIODS payload, a scene) exist only while it
    // runs, once after a reset, not in every frame of its caller.
    #[inline(never)]
    pub fn restore_kept(&mut self, snapshot: &Snapshot, kept: Kept) -> Result<Restored, Fault> {
        // Decoded again rather than carried from `write_kept_periods`: the boot's
        // deepest frames are these, and the stack budget is tighter than the time here.
        let written = kept.written;
        let periods = Periods::decode(snapshot.periods.as_slice()).ok_or(Fault::BadLength)?;
        let scene = Scene::decode(snapshot.scene.as_slice())?;
        let terrain = Terrain::decode(snapshot.terrain.as_slice(), &scene)?;
        let time_scales = decode_time_scales(snapshot.time_scales.as_slice())?;
        self.set_scene(scene)?;
        self.heights_m = terrain.heights_m;
        self.time_scales = time_scales;
        self.inputs_generation = self.inputs_generation.wrapping_add(1);
        let records = periods.records().iter();
        for r in records.filter(|r| written.get(usize::from(r.index)) == Some(&true)) {
            let slot = usize::from(r.index);
            if let (Some(o), Some(h)) = (self.outputs.get_mut(slot), self.has_output.get_mut(slot))
            {
                *o = SegmentOutput { held: true, ..*r };
                *h = true;
            }
        }
        self.yaw_request_rad = periods.yaw_request_rad;
        // The blend's seed, checked as an ATTITUDE frame's payload is; none when empty
        // or refused (the blend then starts from the first frame).
        self.blend_seed = StarAttitude::decode(snapshot.attitude.as_slice())
            .ok()
            .filter(|a| crate::track::check_quaternion(a).is_ok());
        Ok(Restored {
            periods: written.iter().filter(|w| **w).count(),
        })
    }
}

/// What [`write_kept_periods`] did: which segments' periods went into the sink.
#[derive(Clone, Copy, Debug)]
pub struct Kept {
    written: [bool; MAX_SEGMENTS],
}

/// The first step after a reset, before the controller exists: each kept period into
/// `sink` (a record whose segment the kept scene does not have active, or whose period
/// is 0, is skipped). A payload that does not decode gives that fault and writes
/// nothing. Needs no [`Controller`], so that a board can program its line clocks before
/// it builds one (docs/target.md, "Faults and resets").
// Not inlined: its frames (a decoded PERIODS payload, a scene) exist only while it runs.
#[inline(never)]
pub fn write_kept_periods<S: LinePeriodSink>(
    snapshot: &Snapshot,
    sink: &mut S,
) -> Result<Kept, Fault> {
    let periods = Periods::decode(snapshot.periods.as_slice()).ok_or(Fault::BadLength)?;
    let scene = Scene::decode(snapshot.scene.as_slice())?;
    let active = |index: u8| {
        scene
            .active()
            .any(|(k, _)| usize::from(index) == k && k < MAX_SEGMENTS)
    };
    let mut written = [false; MAX_SEGMENTS];
    for r in periods
        .records()
        .iter()
        .filter(|r| r.ticks != 0 && active(r.index))
    {
        if let Some(w) = written.get_mut(usize::from(r.index)) {
            *w = sink.write_period(r.index, r.ticks).is_ok();
        }
    }
    Ok(Kept { written })
}

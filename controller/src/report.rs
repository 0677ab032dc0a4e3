//! Camera-to-ground frames: PERIODS (what was programmed) and STATUS (fault counters).
//! Encoded by the firmware, decoded by the host tools; one codec for both sides.

use heapless::Vec;

use crate::bytes::{Reader, Writer};
use crate::control::{Controller, Mode, SegmentOutput};
use crate::dem::DemStatus;
use crate::fault::{Fault, ResetCause};
use crate::scene::MAX_SEGMENTS;

/// PERIODS payload: mode, count, flags, 1 reserved, the yaw steering request (f32, rad),
/// then one [`RECORD_LEN`]-byte record per segment in force.
pub const PERIODS_HEADER_LEN: usize = 8;
pub const RECORD_LEN: usize = 28;
/// STATUS payload length: the header and four counters, one counter per [`Fault`], and
/// the downlink frames dropped (84 bytes).
pub const STATUS_LEN: usize = 20 + 4 * Fault::COUNT + 4 + DEM_STATUS_LEN;
/// STATUS's DEM block: the tile in force, the upload in progress, tiles committed.
pub const DEM_STATUS_LEN: usize = 16;

/// Flag bit of a record: the value is the last good one, held over a fault.
pub const FLAG_HELD: u8 = 1;
/// Flag bit of a record: the image moves towards +P1, against forward flight (reverse
/// the TDI transfer).
pub const FLAG_REVERSED: u8 = 2;
/// Flag bit of the header: the yaw steering request is valid (the update formed it).
pub const FLAG_YAW_REQUEST: u8 = 1;

/// Writes the PERIODS payload of the outputs in force.
pub fn encode_periods(c: &Controller, out: &mut [u8]) -> Option<usize> {
    let mut w = Writer::new(out);
    let count = c.outputs().count() as u8;
    let yaw = c.yaw_request_rad();
    let flags = if yaw.is_some() { FLAG_YAW_REQUEST } else { 0 };
    w.put(&[c.update_mode() as u8, count, flags, 0])?;
    w.put(&yaw.unwrap_or(0.0).to_le_bytes())?;
    for o in c.outputs() {
        let flags = if o.held { FLAG_HELD } else { 0 } | if o.reversed { FLAG_REVERSED } else { 0 };
        w.put(&[o.index, flags])?;
        w.put(&o.max_stages.to_le_bytes())?;
        w.put(&o.ticks.to_le_bytes())?;
        w.put(&o.mtf.to_le_bytes())?;
        w.put(&o.worst_mismatch.to_le_bytes())?;
        w.put(&o.drift_rad.to_le_bytes())?;
        w.put(&o.worst_drift_rad.to_le_bytes())?;
        w.put(&o.residual_drift_rad.to_le_bytes())?;
    }
    Some(w.len())
}

/// A decoded PERIODS payload.
#[derive(Clone, Debug, PartialEq)]
pub struct Periods {
    pub mode: u8,
    /// The yaw steering request (rad), when the update formed one.
    pub yaw_request_rad: Option<f32>,
    pub records: Vec<SegmentOutput, MAX_SEGMENTS>,
}

impl Periods {
    pub fn decode(payload: &[u8]) -> Option<Periods> {
        let mut r = Reader::new(payload);
        let mode = r.u8()?;
        let count = r.u8()?;
        let flags = r.u8()?;
        r.u8()?;
        let yaw = r.f32()?;
        // More records than segments do not fit: `push` refuses the 17th.
        let mut records = Vec::new();
        for _ in 0..count {
            let index = r.u8()?;
            let flags = r.u8()?;
            let record = SegmentOutput {
                index,
                held: flags & FLAG_HELD != 0,
                reversed: flags & FLAG_REVERSED != 0,
                max_stages: r.u16()?,
                ticks: r.u32()?,
                mtf: r.f32()?,
                worst_mismatch: r.f32()?,
                drift_rad: r.f32()?,
                worst_drift_rad: r.f32()?,
                residual_drift_rad: r.f32()?,
            };
            records.push(record).ok()?;
        }
        r.is_done().then_some(Periods {
            mode,
            yaw_request_rad: (flags & FLAG_YAW_REQUEST != 0).then_some(yaw),
            records,
        })
    }

    pub fn records(&self) -> &[SegmentOutput] {
        &self.records
    }
}

/// Writes the STATUS payload: mode, last fault (0xFF: none), the last reset's cause
/// ([`ResetCause`] as u8; 0: not noted) and the resets since power-on (saturating at
/// 255), frames
/// accepted, updates run, bytes skipped by the decoder, time re-synchronisations, then
/// one u32 counter per [`Fault`] in [`Fault::ALL`] order, then the downlink frames the
/// transmit queue had no room for (dropped whole: [`crate::downlink`]), then the DEM
/// upload's state ([`DemStatus`]: the id of the tile in force, the id of the upload in
/// progress, its next chunk and chunk count, tiles committed). What each
/// counts, and the identities between them: docs/telemetry.md, "Counters".
pub fn encode_status(
    c: &Controller,
    skipped_bytes: u32,
    downlink_dropped: u32,
    out: &mut [u8],
) -> Option<usize> {
    let mut w = Writer::new(out);
    let (cause, resets) = c.boot().map_or((0, 0), |(cause, n)| {
        (cause as u8, u8::try_from(n).unwrap_or(u8::MAX))
    });
    w.put(&[
        c.mode() as u8,
        c.last_fault.map_or(0xFF, |f| f as u8),
        cause,
        resets,
    ])?;
    w.put(&c.frames_accepted.to_le_bytes())?;
    w.put(&c.updates.to_le_bytes())?;
    w.put(&skipped_bytes.to_le_bytes())?;
    w.put(&c.time_resyncs.to_le_bytes())?;
    for n in c.counters.as_array() {
        w.put(&n.to_le_bytes())?;
    }
    w.put(&downlink_dropped.to_le_bytes())?;
    let d = c.dem_status();
    w.put(&d.in_force_id.to_le_bytes())?;
    w.put(&d.upload_id.to_le_bytes())?;
    w.put(&d.next_chunk.to_le_bytes())?;
    w.put(&d.chunks.to_le_bytes())?;
    w.put(&d.tiles_committed.to_le_bytes())?;
    Some(w.len())
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Status {
    pub mode: u8,
    pub last_fault: Option<Fault>,
    /// Why the core last started (None: not noted, as on a host).
    pub reset_cause: Option<ResetCause>,
    /// Resets since power-on (saturating at 255).
    pub resets: u8,
    pub frames_accepted: u32,
    pub updates: u32,
    pub skipped_bytes: u32,
    pub time_resyncs: u32,
    pub counts: [u32; Fault::COUNT],
    /// Downlink frames dropped whole because the transmit queue had no room for them.
    pub downlink_dropped: u32,
    /// The DEM upload's state.
    pub dem: DemStatus,
}

impl Status {
    pub fn decode(payload: &[u8]) -> Option<Status> {
        let mut r = Reader::new(payload);
        let mode = r.u8()?;
        let last = r.u8()?;
        let reset_cause = ResetCause::from_u8(r.u8()?);
        let resets = r.u8()?;
        let frames_accepted = r.u32()?;
        let updates = r.u32()?;
        let skipped_bytes = r.u32()?;
        let time_resyncs = r.u32()?;
        let mut counts = [0u32; Fault::COUNT];
        for c in counts.iter_mut() {
            *c = r.u32()?;
        }
        let downlink_dropped = r.u32()?;
        let dem = DemStatus {
            in_force_id: r.u32()?,
            upload_id: r.u32()?,
            next_chunk: r.u16()?,
            chunks: r.u16()?,
            tiles_committed: r.u32()?,
        };
        let last_fault = Fault::ALL.get(usize::from(last)).copied();
        r.is_done().then_some(Status {
            mode,
            last_fault,
            reset_cause,
            resets,
            frames_accepted,
            updates,
            skipped_bytes,
            time_resyncs,
            counts,
            downlink_dropped,
            dem,
        })
    }

    pub fn count(&self, f: Fault) -> u32 {
        self.counts[f as usize]
    }

    pub fn total(&self) -> u32 {
        self.counts.iter().fold(0u32, |a, &c| a.saturating_add(c))
    }
}

/// Mode from its wire value.
pub fn mode_from_u8(m: u8) -> Option<Mode> {
    match m {
        0 => Some(Mode::WaitingForNav),
        1 => Some(Mode::Nominal),
        2 => Some(Mode::Stale),
        _ => None,
    }
}

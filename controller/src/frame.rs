//! Telemetry framing: sync word, version, kind, length, sequence number, time tag,
//! payload, CRC. Layout and rationale: `docs/telemetry.md`.
//!
//! The decoder is a byte-stream state machine over a fixed-capacity buffer (a
//! `heapless::Vec` of one frame): it never blocks, never allocates, and after any bad
//! frame it rescans the bytes it already holds for the next sync word, so a corrupted or
//! truncated frame costs that frame only.

use heapless::Vec;

use crate::crc;

pub const SYNC: [u8; 2] = [0xEB, 0x90];
/// 4 since issue 23: the bus's own frames (GNSS, ATTITUDE, TIME_SCALES) and the camera
/// mounting in SCENE (docs/telemetry.md, "Versions").
pub const VERSION: u8 = 4;
/// sync (2) + version (1) + kind (1) + length (2) + sequence (2) + time tag (8).
pub const HEADER_LEN: usize = 16;
pub const CRC_LEN: usize = 2;
/// The longest payload: a PERIODS frame of 16 segments (8 + 16 x 28 bytes).
pub const MAX_PAYLOAD: usize = 456;
pub const MAX_FRAME: usize = HEADER_LEN + MAX_PAYLOAD + CRC_LEN;

/// Frame kinds. Ground/bus to camera below 0x80, camera to ground from 0x80.
pub mod kind {
    /// Orbit state and attitude (payload: `nav::NAV_LEN` bytes).
    pub const NAV: u8 = 0x01;
    /// Imaging scene upload (payload: `scene` module).
    pub const SCENE: u8 = 0x02;
    /// Time only: a tick of the time source (the simulation's clock; on a board the
    /// on-board timer plays this part and the frame is not needed).
    pub const TIME: u8 = 0x03;
    /// End of a simulated pass (empty payload): the host asks for a final STATUS frame
    /// and for the program to stop. Handled by [`crate::session::Session`], never
    /// passed to the controller; a flight build may ignore it.
    pub const END: u8 = 0x04;
    /// Ground heights of the scene's segments (payload: `scene::Terrain`), in force
    /// from the frame's time tag.
    pub const TERRAIN: u8 = 0x05;
    /// A GNSS fix: ITRF position and velocity at the time of fix (payload:
    /// `bus::GNSS_LEN` bytes).
    pub const GNSS: u8 = 0x06;
    /// A star tracker's GCRF quaternion with gyro body rates at the time of validity
    /// (payload: `bus::ATTITUDE_LEN` bytes).
    pub const ATTITUDE: u8 = 0x07;
    /// GPS - UTC and UT1 - UTC (payload: `bus::TIME_SCALES_LEN` bytes).
    pub const TIME_SCALES: u8 = 0x08;
    /// The start of a DEM tile upload: its id, grid and CRC-32 (payload:
    /// `dem::DEM_BEGIN_LEN` bytes).
    pub const DEM_BEGIN: u8 = 0x09;
    /// One chunk of a DEM tile's heights (payload: `dem` module).
    pub const DEM_CHUNK: u8 = 0x0A;
    /// Line periods, one record per active segment.
    pub const PERIODS: u8 = 0x81;
    /// Fault counters and state.
    pub const STATUS: u8 = 0x82;
}

/// Why bytes on the link were not a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// The CRC did not match.
    BadCrc,
    /// The frame stopped short: another frame's sync and header start inside its span.
    Truncated,
    /// The length field exceeds [`MAX_PAYLOAD`].
    Oversized,
    /// A version this firmware does not speak.
    UnknownVersion,
}

/// A decoded frame; the payload borrows the decoder's buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame<'a> {
    pub kind: u8,
    pub sequence: u16,
    pub time_us: u64,
    pub payload: &'a [u8],
}

/// What the decoder reports, one event per frame or per rejected frame.
#[derive(Debug, PartialEq, Eq)]
pub enum Event<'a> {
    Frame(Frame<'a>),
    Rejected(FrameError),
}

/// The streaming decoder.
pub struct Decoder {
    /// The bytes of the frame not yet complete: at most one frame.
    buf: Vec<u8, MAX_FRAME>,
    /// Every byte received that is not part of a delivered frame: line noise, and the
    /// bytes of rejected frames. So bytes received = delivered frames' bytes + skipped
    /// + [`Decoder::buffered`].
    pub skipped_bytes: u32,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

enum Step<'a> {
    /// Need more bytes.
    Wait,
    /// Drop this many bytes from the front and look again.
    Drop(usize),
    /// A good frame at the front, and its total length.
    Frame(Frame<'a>, usize),
    /// A bad frame at the front: report it, drop its sync's first byte, rescan.
    Reject(FrameError),
}

impl Decoder {
    pub const fn new() -> Self {
        Decoder {
            buf: Vec::new(),
            skipped_bytes: 0,
        }
    }

    /// Feeds received bytes; `on_event` is called for every frame and every rejected frame.
    pub fn feed(&mut self, bytes: &[u8], mut on_event: impl FnMut(Event<'_>)) {
        for &b in bytes {
            // Never full here: parsing leaves less than a whole frame in the buffer
            // (a frame of MAX_FRAME bytes is delivered or rejected at once).
            let _ = self.buf.push(b);
            self.parse(&mut on_event);
        }
    }

    fn parse(&mut self, on_event: &mut impl FnMut(Event<'_>)) {
        loop {
            match self.step() {
                Step::Wait => return,
                Step::Drop(n) => {
                    self.skipped_bytes = self.skipped_bytes.saturating_add(n as u32);
                    self.consume(n);
                }
                Step::Frame(frame, n) => {
                    on_event(Event::Frame(frame));
                    self.consume(n);
                }
                Step::Reject(e) => {
                    on_event(Event::Rejected(e));
                    self.skipped_bytes = self.skipped_bytes.saturating_add(1);
                    self.consume(1);
                }
            }
        }
    }

    /// Bytes held for a frame not yet complete.
    pub fn buffered(&self) -> usize {
        self.buf.len()
    }

    fn step(&self) -> Step<'_> {
        let b = self.buf.as_slice();
        if b.is_empty() {
            return Step::Wait;
        }
        if b[0] != SYNC[0] {
            let n = b.iter().position(|&x| x == SYNC[0]).unwrap_or(b.len());
            return Step::Drop(n);
        }
        if b.len() < 2 {
            return Step::Wait;
        }
        if b[1] != SYNC[1] {
            return Step::Drop(1);
        }
        if b.len() < HEADER_LEN {
            return Step::Wait;
        }
        if b[2] != VERSION {
            return Step::Reject(FrameError::UnknownVersion);
        }
        let payload_len = usize::from(u16::from_le_bytes([b[4], b[5]]));
        if payload_len > MAX_PAYLOAD {
            return Step::Reject(FrameError::Oversized);
        }
        let total = HEADER_LEN + payload_len + CRC_LEN;
        if b.len() < total {
            return Step::Wait;
        }
        let body = &b[2..total - CRC_LEN];
        let sent = u16::from_le_bytes([b[total - 2], b[total - 1]]);
        if crc::crc16(body) == sent {
            let frame = Frame {
                kind: b[3],
                sequence: u16::from_le_bytes([b[6], b[7]]),
                time_us: u64::from_le_bytes([b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15]]),
                payload: &b[HEADER_LEN..total - CRC_LEN],
            };
            return Step::Frame(frame, total);
        }
        // A sync word with our version inside the span says the frame was cut short
        // and another began; otherwise the bytes were damaged in place.
        let restarted = b[1..total]
            .windows(3)
            .any(|w| w == [SYNC[0], SYNC[1], VERSION]);
        Step::Reject(if restarted {
            FrameError::Truncated
        } else {
            FrameError::BadCrc
        })
    }

    fn consume(&mut self, n: usize) {
        let len = self.buf.len();
        let n = n.min(len);
        // A forward byte loop rather than `copy_within`: its memmove would be the flight
        // binary's only one (1.5 KB beside memcpy), for the few bytes after a frame.
        for i in n..len {
            let b = self.buf[i];
            self.buf[i - n] = b;
        }
        self.buf.truncate(len - n);
    }
}

/// Writes one frame into `out`; returns its length, or `None` if the payload is too
/// long or `out` too short.
pub fn encode(
    kind: u8,
    sequence: u16,
    time_us: u64,
    payload: &[u8],
    out: &mut [u8],
) -> Option<usize> {
    if payload.len() > MAX_PAYLOAD {
        return None;
    }
    let total = HEADER_LEN + payload.len() + CRC_LEN;
    let out = out.get_mut(..total)?;
    out[0..2].copy_from_slice(&SYNC);
    out[2] = VERSION;
    out[3] = kind;
    out[4..6].copy_from_slice(&(payload.len() as u16).to_le_bytes());
    out[6..8].copy_from_slice(&sequence.to_le_bytes());
    out[8..16].copy_from_slice(&time_us.to_le_bytes());
    out[HEADER_LEN..total - CRC_LEN].copy_from_slice(payload);
    let c = crc::crc16(&out[2..total - CRC_LEN]);
    out[total - CRC_LEN..].copy_from_slice(&c.to_le_bytes());
    Some(total)
}

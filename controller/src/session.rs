//! The controller's loop around a byte link, shared by every host of the controller:
//! the firmware (bytes from its UART) and the host tools (the twin run of
//! `cargo xtask run`, the tests). Bytes in, frames to the controller, after every frame
//! the update that is due, frames out: PERIODS after each update, STATUS every second of
//! controller time and at the end of a pass. Because the firmware and its host twin run
//! this very code, a difference between their outputs can only come from their inputs
//! (or from the target's arithmetic, which is bit-identical for this code).
//!
//! Bytes are processed one at a time (the decoder sees every byte alone), so that the
//! outputs do not depend on how the bytes were chunked by the link.
//!
//! Frames go out through a `send` closure. One that returns nothing takes every frame; one
//! that returns a `bool` says whether it took the frame (a transmit queue without room,
//! [`crate::downlink`]), and the session counts each refused frame in STATUS (*downlink
//! frames dropped*, [`Session::downlink_dropped`]).

use crate::control::Controller;
use crate::fault::Fault;
use crate::frame::{encode, kind, Decoder, Event, MAX_FRAME, MAX_PAYLOAD};
use crate::report::{encode_periods, encode_status};
use crate::sink::LinePeriodSink;

/// Time between STATUS frames (controller time, us).
pub const STATUS_PERIOD_US: u64 = 1_000_000;

/// What a `send` closure returns: nothing (the frame was taken), or whether the link took
/// the frame.
pub trait Sent {
    /// True if the frame was taken.
    fn taken(self) -> bool;
}

impl Sent for () {
    fn taken(self) -> bool {
        true
    }
}

impl Sent for bool {
    fn taken(self) -> bool {
        self
    }
}

/// The controller, its decoder and the downlink's state.
pub struct Session {
    pub decoder: Decoder,
    pub controller: Controller,
    sequence: u16,
    next_status_us: u64,
    /// The controller's re-synchronisations already reported by a STATUS frame.
    resyncs_reported: u32,
    end_requested: bool,
    ended: bool,
    /// Downlink frames that could not be encoded (never expected: the payloads are
    /// bounded by construction).
    pub encode_failures: u32,
    /// Downlink frames the link refused (a full transmit queue), each dropped whole:
    /// reported in STATUS.
    pub downlink_dropped: u32,
}

impl Session {
    #[inline(always)]
    pub fn new(controller: Controller) -> Session {
        Session {
            decoder: Decoder::new(),
            controller,
            sequence: 0,
            next_status_us: 0,
            resyncs_reported: 0,
            end_requested: false,
            ended: false,
            encode_failures: 0,
            downlink_dropped: 0,
        }
    }

    /// True once an END frame has been received (and the final STATUS sent).
    pub fn is_ended(&self) -> bool {
        self.ended
    }

    /// Feeds received bytes; `sink` receives the line periods, `send` every downlink
    /// frame (whole, ready for the link; it may refuse one: [`Sent`]). Returns true when
    /// the pass has ended (an END frame arrived): the final STATUS has been sent and
    /// later bytes are ignored.
    pub fn feed<S: LinePeriodSink, R: Sent>(
        &mut self,
        bytes: &[u8],
        sink: &mut S,
        mut send: impl FnMut(&[u8]) -> R,
    ) -> bool {
        for &b in bytes {
            if self.ended {
                break;
            }
            self.feed_byte(b, sink, &mut send);
        }
        self.ended
    }

    fn feed_byte<S: LinePeriodSink, R: Sent>(
        &mut self,
        byte: u8,
        sink: &mut S,
        send: &mut impl FnMut(&[u8]) -> R,
    ) {
        let Session {
            decoder,
            controller,
            sequence,
            end_requested,
            encode_failures,
            downlink_dropped,
            ..
        } = self;
        // Only an accepted frame moves the clock, so only it can make an update or a
        // STATUS due: a refused input sends nothing (docs/telemetry.md, "Faults").
        let mut accepted = false;
        decoder.feed(&[byte], |event| {
            if *end_requested {
                return;
            }
            match event {
                Event::Rejected(e) => controller.reject(Fault::from(e)),
                Event::Frame(f) if f.kind == kind::END => {
                    if f.payload.is_empty() {
                        *end_requested = true;
                        // Accepted like any frame, so that every frame received is
                        // either accepted or refused (docs/telemetry.md, "Counters").
                        controller.frames_accepted = controller.frames_accepted.saturating_add(1);
                    } else {
                        controller.reject(Fault::BadLength);
                    }
                }
                Event::Frame(f) => {
                    let before = controller.frames_accepted;
                    controller.on_frame(&f);
                    if controller.frames_accepted != before {
                        accepted = true;
                        let now = controller.now_us();
                        let out = Out {
                            sequence,
                            encode_failures,
                            downlink_dropped,
                        };
                        advance(controller, now, sink, out, send);
                    }
                }
            }
        });
        if accepted || self.end_requested {
            self.status_if_due(send);
        }
    }

    /// Moves the clock to `now_us` from a time source of the firmware's own (a board's
    /// timer), with the same consequences as a frame's time tag: the update that is
    /// due, its PERIODS frame, a STATUS frame when one is due. Under QEMU the telemetry
    /// is the only time source and this is not called.
    pub fn tick<S: LinePeriodSink, R: Sent>(
        &mut self,
        now_us: u64,
        sink: &mut S,
        mut send: impl FnMut(&[u8]) -> R,
    ) {
        if self.ended {
            return;
        }
        let out = Out {
            sequence: &mut self.sequence,
            encode_failures: &mut self.encode_failures,
            downlink_dropped: &mut self.downlink_dropped,
        };
        advance(&mut self.controller, now_us, sink, out, &mut send);
        self.status_if_due(&mut send);
    }

    fn status_if_due<R: Sent>(&mut self, send: &mut impl FnMut(&[u8]) -> R) {
        let now = self.controller.now_us();
        // A re-synchronisation is reported at once, and restarts the schedule (the
        // clock may have gone back).
        let resynced = self.controller.time_resyncs != self.resyncs_reported;
        if self.end_requested || resynced || now >= self.next_status_us {
            self.resyncs_reported = self.controller.time_resyncs;
            // The clock is at most MAX_TIME_TAG_US: no overflow; saturating all the same.
            self.next_status_us = (now / STATUS_PERIOD_US + 1).saturating_mul(STATUS_PERIOD_US);
            self.send_status(send);
        }
        if self.end_requested {
            self.ended = true;
        }
    }

    /// Sends a STATUS frame (time tag: the controller's clock).
    pub fn send_status<R: Sent>(&mut self, send: &mut impl FnMut(&[u8]) -> R) {
        let mut payload = [0u8; MAX_PAYLOAD];
        let skipped = self.decoder.skipped_bytes;
        let dropped = self.downlink_dropped;
        let now = self.controller.now_us();
        let out = Out {
            sequence: &mut self.sequence,
            encode_failures: &mut self.encode_failures,
            downlink_dropped: &mut self.downlink_dropped,
        };
        let encoded = encode_status(&self.controller, skipped, dropped, &mut payload);
        out.send(
            kind::STATUS,
            now,
            encoded.and_then(|n| payload.get(..n)),
            send,
        );
    }
}

/// The session's downlink counters, for sending one frame.
struct Out<'a> {
    sequence: &'a mut u16,
    encode_failures: &'a mut u32,
    downlink_dropped: &'a mut u32,
}

impl Out<'_> {
    /// Encodes one frame of `payload` (None: it could not be encoded) with the next
    /// sequence number and hands it to `send`; counts a frame that could not be encoded,
    /// and one that `send` refused.
    // Out of line: inlined into the firmware's loop beside this copy (docs/target.md,
    // flash).
    #[inline(never)]
    fn send<R: Sent>(
        self,
        kind: u8,
        time_us: u64,
        payload: Option<&[u8]>,
        send: &mut impl FnMut(&[u8]) -> R,
    ) {
        let mut frame = [0u8; MAX_FRAME];
        let encoded = payload.and_then(|p| {
            let n = encode(kind, *self.sequence, time_us, p, &mut frame)?;
            frame.get(..n)
        });
        let Some(bytes) = encoded else {
            *self.encode_failures = self.encode_failures.saturating_add(1);
            return;
        };
        *self.sequence = self.sequence.wrapping_add(1);
        if !send(bytes).taken() {
            *self.downlink_dropped = self.downlink_dropped.saturating_add(1);
        }
    }
}

/// Runs the update due at `now_us`, if any, and sends its PERIODS frame (time tag: the
/// update instant).
fn advance<S: LinePeriodSink, R: Sent>(
    controller: &mut Controller,
    now_us: u64,
    sink: &mut S,
    out: Out<'_>,
    send: &mut impl FnMut(&[u8]) -> R,
) {
    if !controller.advance(now_us, sink) {
        return;
    }
    let Some(t) = controller.last_update_us() else {
        return;
    };
    let mut payload = [0u8; MAX_PAYLOAD];
    let encoded = encode_periods(controller, &mut payload);
    out.send(
        kind::PERIODS,
        t,
        encoded.and_then(|n| payload.get(..n)),
        send,
    );
}

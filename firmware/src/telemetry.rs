//! Telemetry in, and the loop that ties the firmware together: bytes from the link go
//! through the controller's [`Session`] (frame decoder -> controller -> update due ->
//! line periods to the sink), and the frames it answers with (PERIODS after each
//! update, STATUS every second and at the end) go back out on the same link.
//!
//! The loop never waits on the link for long: it polls the receiver and, when it is
//! empty, sleeps until the receive interrupt is pending (a new byte, and nothing else,
//! can wake it: there is nothing else to do before one arrives), and a transmitter that stops taking bytes costs at most
//! [`crate::link::TX_POLL_LIMIT`] polls per frame, after which the frame is dropped and
//! counted. Time comes from the telemetry's time tags (NAV and TIME frames): under QEMU
//! the host player is the time source. On a board the same loop would also call
//! [`Session::tick`] with the on-board timer's time; the controller is the same.

use controller::session::Session;
use controller::{Controller, LinePeriodSink, Mode};

use crate::link::{flush_bounded, send_bounded, ByteLink};

/// How a pass ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Summary {
    /// Downlink frames given up because the transmitter stayed busy.
    pub tx_dropped: u32,
}

/// Runs the controller on `link` until an END frame; returns how it went.
pub fn run<L: ByteLink, S: LinePeriodSink>(
    link: &mut L,
    sink: &mut S,
    controller: Controller,
) -> Summary {
    let mut session = Session::new(controller);
    let mut tx_dropped = 0u32;
    let mut faults = 0u32;
    let mut mode = session.controller.mode();
    loop {
        let Some(byte) = link.read_byte() else {
            // Nothing received: sleep until the receiver has something (or return at
            // once, for a link without an interrupt).
            link.wait();
            continue;
        };
        let ended = session.feed(&[byte], sink, |frame| {
            if send_bounded(link, frame).is_err() {
                tx_dropped = tx_dropped.saturating_add(1);
            }
        });
        report_changes(&session, &mut faults, &mut mode);
        if ended {
            if !flush_bounded(link) {
                tx_dropped = tx_dropped.saturating_add(1);
            }
            let c = &session.controller;
            defmt::info!(
                "end of pass at t = {=u64} us: {=u32} frames accepted, {=u32} updates, {=u32} faults, {=u32} noise bytes skipped, {=u32} downlink frames dropped",
                c.now_us(),
                c.frames_accepted,
                c.updates,
                c.counters.total(),
                session.decoder.skipped_bytes,
                tx_dropped,
            );
            return Summary { tx_dropped };
        }
    }
}

/// One log line per counted fault and per change of mode.
fn report_changes(session: &Session, faults: &mut u32, mode: &mut Mode) {
    let c = &session.controller;
    let total = c.counters.total();
    if total != *faults {
        *faults = total;
        if let Some(f) = c.last_fault {
            defmt::info!(
                "t = {=u64} us: fault {=str} ({=u32} so far)",
                c.now_us(),
                f.name(),
                total
            );
        }
    }
    let now = c.mode();
    if now != *mode {
        *mode = now;
        defmt::info!("t = {=u64} us: mode {=str}", c.now_us(), mode_name(now));
    }
}

pub fn mode_name(m: Mode) -> &'static str {
    match m {
        Mode::WaitingForNav => "waiting for NAV",
        Mode::Nominal => "nominal",
        Mode::Stale => "stale (periods held)",
    }
}

//! Telemetry in, and the loop that ties the firmware together: bytes from the link go
//! through the controller's [`Session`] (frame decoder -> controller -> update due ->
//! line periods to the sink), and the frames it answers with (PERIODS after each
//! update, STATUS every second and at the end) go back out on the same link.
//!
//! The loop never waits on the link for long: it polls the receiver and, when it is
//! empty, sleeps until the receive interrupt is pending (a new byte, and nothing else,
//! can wake it: there is nothing else to do before one arrives), and a transmitter that stops taking bytes costs at most
//! [`crate::link::TX_POLL_LIMIT`] polls per frame, after which the frame is dropped and
//! counted. The controller's time comes from the telemetry's time tags (NAV and TIME
//! frames): under QEMU the host player is the time source, which keeps a pass
//! reproducible to the bit. The board's [`Monotonic`] clock times the loop instead: the
//! longest step (one byte through the session: an update and its PERIODS frame at
//! worst) is reported at the end of the pass, the figure that says whether a polled
//! receiver keeps up on a real board. (Letting the board's clock also drive updates
//! between frames, [`Session::tick`], needs a clock whose rate is right: not QEMU's.)

use controller::session::Session;
use controller::{LinePeriodSink, Mode};

use crate::board::Monotonic;
use crate::link::{flush_bounded, send_bounded, Link};

/// The words of the firmware's first log line that say the link is up: the host's pass
/// player waits for them before it sends a byte (xtask/src/qemu/pass.rs).
pub const READY: &str = "telemetry link ready";

/// How a pass ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Summary {
    /// Downlink frames given up because the transmitter stayed busy or failed.
    pub tx_dropped: u32,
    /// Errors the receiver reported (overrun, framing, noise, parity): bytes lost, which
    /// the decoder then counts as a broken frame.
    pub rx_errors: u32,
    /// The longest step of the loop by the board's clock (us).
    pub longest_step_us: u64,
}

/// Runs the session's controller on `link` until an END frame; returns how it went.
pub fn run<L: Link, S: LinePeriodSink, C: Monotonic>(
    link: &mut L,
    sink: &mut S,
    clock: &mut C,
    session: &mut Session,
) -> Summary {
    let mut summary = Summary {
        tx_dropped: 0,
        rx_errors: 0,
        longest_step_us: 0,
    };
    let mut faults = 0u32;
    let mut mode = session.controller.mode();
    let started_us = clock.now_us();
    loop {
        let byte = match link.read() {
            Ok(byte) => byte,
            Err(nb::Error::WouldBlock) => {
                // Nothing received: sleep until the receiver has something (or return
                // at once, for a link without an interrupt).
                link.wait_for_rx();
                continue;
            }
            Err(nb::Error::Other(e)) => {
                summary.rx_errors = summary.rx_errors.saturating_add(1);
                defmt::warn!(
                    "receive error: {=str} ({=u32} so far)",
                    e.name(),
                    summary.rx_errors
                );
                continue;
            }
        };
        let step_start_us = clock.now_us();
        let ended = session.feed(&[byte], sink, |frame| {
            if send_bounded(link, frame).is_err() {
                summary.tx_dropped = summary.tx_dropped.saturating_add(1);
            }
        });
        let step_us = clock.now_us().saturating_sub(step_start_us);
        summary.longest_step_us = summary.longest_step_us.max(step_us);
        report_changes(session, &mut faults, &mut mode);
        if ended {
            if !flush_bounded(link) {
                summary.tx_dropped = summary.tx_dropped.saturating_add(1);
            }
            let c = &session.controller;
            defmt::info!(
                "end of pass at t = {=u64} us: {=u32} frames accepted, {=u32} updates, {=u32} faults, {=u32} noise bytes skipped, {=u32} downlink frames dropped",
                c.now_us(),
                c.frames_accepted,
                c.updates,
                c.counters.total(),
                session.decoder.skipped_bytes,
                summary.tx_dropped,
            );
            defmt::info!(
                "board clock: pass {=u64} us, longest step {=u64} us",
                clock.now_us().saturating_sub(started_us),
                summary.longest_step_us
            );
            return summary;
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

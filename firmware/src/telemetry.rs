//! Telemetry in, and the loop that ties the firmware together: bytes from the link go
//! through the controller's [`Session`] (frame decoder -> controller -> update due ->
//! line periods to the sink), and the frames it answers with (PERIODS after each
//! update, STATUS every second and at the end) go back out on the same link.
//!
//! The loop never polls the link: when the receive queue is empty it sleeps until the
//! receive interrupt is pending (a new byte, and nothing else, can wake it: there is
//! nothing else to do before one arrives); it hands every frame whole to the transmit
//! queue, which the UART's transmit interrupt drains ([`crate::tx`]), a frame the queue
//! has no room for being dropped whole and counted in STATUS (*downlink frames
//! dropped*); and before it takes the next byte it makes sure the transmit queue has
//! room for everything that byte can make the session send, sleeping until the
//! transmit interrupt has made it if not, so that a slow downlink holds the uplink back
//! instead of losing frames (docs/telemetry.md, "The transmit queue"). At the end of a
//! pass it sleeps until the queue has drained, so that the final STATUS leaves before
//! the firmware exits. The controller's time comes from the telemetry's time tags (NAV
//! and TIME frames): under QEMU the host player is the time source, which keeps a pass
//! reproducible to the bit. The board's [`Monotonic`] clock times the loop instead: the
//! longest step (one byte through the session: an update and its PERIODS frame at
//! worst) is reported at the end of the pass, the figure that says whether a polled
//! receiver keeps up on a real board. (Letting the board's clock also drive updates
//! between frames, [`Session::tick`], needs a clock whose rate is right: not QEMU's.)

use controller::downlink::MAX_STEP_OUTPUT;
use controller::session::Session;
use controller::{LinePeriodSink, Mode};

use crate::board::{Monotonic, Watchdog};
use crate::link::Link;
use crate::retained;

/// The words of the firmware's first log line that say the link is up: the host's pass
/// player waits for them before it sends a byte (xtask/src/qemu/pass.rs).
pub const READY: &str = "telemetry link ready";

/// How a pass ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Summary {
    /// Downlink frames dropped whole because the transmit queue had no room for them.
    pub tx_dropped: u32,
    /// Times the loop found less room in the transmit queue than one step may need, and
    /// slept until the transmit interrupt had made some.
    pub tx_waits: u32,
    /// Errors the receiver reported (overrun, framing, noise, parity): bytes lost, which
    /// the decoder then counts as a broken frame.
    pub rx_errors: u32,
    /// The longest step of the loop by the board's clock (us).
    pub longest_step_us: u64,
}

/// Runs the session's controller on `link` until an END frame; returns how it went.
/// Feeds `watchdog` once per turn of the loop: a byte handled, a wait for room or for a
/// byte ended (the heartbeat ends a wait at least every `board::HEARTBEAT_MS`).
pub fn run<L: Link, S: LinePeriodSink, C: Monotonic, W: Watchdog>(
    link: &mut L,
    sink: &mut S,
    clock: &mut C,
    watchdog: &mut W,
    session: &mut Session,
) -> Summary {
    let mut summary = Summary {
        tx_dropped: 0,
        tx_waits: 0,
        rx_errors: 0,
        longest_step_us: 0,
    };
    let mut faults = 0u32;
    let mut mode = session.controller.mode();
    let mut kept = retained::Kept::default();
    retained::keep(&session.controller, &mut kept);
    let started_us = clock.now_us();
    loop {
        watchdog.feed();
        // Room first for everything the next byte can make the session send (a PERIODS
        // and a STATUS frame): the downlink paces the uplink, as the receive queue's
        // stall paces the ground (docs/telemetry.md, "The transmit queue").
        if link.tx_room() < MAX_STEP_OUTPUT && link.wait_for_tx_room(MAX_STEP_OUTPUT) {
            summary.tx_waits = summary.tx_waits.saturating_add(1);
            continue;
        }
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
        let ended = session.feed(&[byte], sink, |frame| link.send_frame(frame));
        retained::keep(&session.controller, &mut kept);
        let step_us = clock.now_us().saturating_sub(step_start_us);
        summary.longest_step_us = summary.longest_step_us.max(step_us);
        report_changes(session, &mut faults, &mut mode);
        if ended {
            drain(link, watchdog);
            summary.tx_dropped = session.downlink_dropped;
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

/// Waits until every queued byte has left the UART, sleeping between transmit interrupts.
/// Bytes that still arrive are read and ignored (the pass has ended): reading them lets
/// a receive side that stalled its queue unmask its line, which on the STM32F405 is the
/// transmitter's too.
fn drain<L: Link, W: Watchdog>(link: &mut L, watchdog: &mut W) {
    while !link.tx_drained() {
        watchdog.feed();
        while link.read().is_ok() {}
        link.wait_for_tx_drained();
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

//! Firmware entry point: the telemetry-driven line-rate controller.
//!
//! the board's link, line clock and clock ([`firmware::board`]) -> telemetry in
//! ([`firmware::telemetry`]) -> scene and math (the `controller` crate on core-math) ->
//! line periods out ([`firmware::line_clock`]: the board's reload register for segment
//! 0, PERIODS frames to the ground). Runs until the link sends END, then exits by
//! semihosting (status 0; 1 if the controller could not start, 2 if a frame or a line
//! clock write was lost, 3 if the board could not be brought up).
#![no_std]
#![no_main]

use controller::restart::{self, Kept, Snapshot};
use controller::session::Session;
use controller::{Controller, Fault, LinePeriodSink, Scene};
use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};
use cortex_m_rt::entry;
use firmware::board::{self, Monotonic, Parts};
use firmware::line_clock::LineClocks;
use firmware::link::FrameTx;
use firmware::{heartbeat, platform, retained, rx, stack, telemetry, tx};

/// The controller and its link state live here, not on `main`'s stack: the stack
/// budget (12 KiB, docs/target.md) cannot hold them beside the update's frames. In
/// `.uninit`, not `.bss`: the start-up code would zero it word by word before `main`,
/// on the way to the first period after a reset, and [`blank_session`] writes all of it
/// anyway.
#[link_section = ".uninit.SESSION"]
static mut SESSION: MaybeUninit<Session> = MaybeUninit::uninit();
/// Set once [`blank_session`] has handed out [`SESSION`].
static SESSION_TAKEN: AtomicBool = AtomicBool::new(false);

/// The session, blank (no scene yet). Its own function, never inlined: the blank value
/// passes through this frame once, at boot, and the frame is gone before the telemetry
/// loop runs (docs/target.md, "Stack").
/// None only if called twice (`main` calls it once): a flag, not a panic
/// (docs/no-panic.md).
#[inline(never)]
fn blank_session() -> Option<&'static mut Session> {
    if SESSION_TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    // SAFETY: the flag lets exactly one caller past, once, so this is the only
    // reference to `SESSION` there will ever be.
    let slot = unsafe { &mut *core::ptr::addr_of_mut!(SESSION) };
    Some(slot.write(Session::new(Controller::blank(board::controller_config()))))
}

/// The periods of the snapshot kept before a reset, back into the registers: the first
/// thing after the board is up, before the session exists (`controller::restart`).
/// Not inlined, so that its frames are not part of `main`'s through the whole pass.
#[inline(never)]
fn write_kept_periods<C: Monotonic>(
    snapshot: &Snapshot,
    clocks: &mut LineClocks<board::LineClock>,
    clock: &mut C,
) -> Result<(Kept, Option<u64>), Fault> {
    let mut timed = FirstWrite {
        sink: clocks,
        clock,
        at_us: None,
    };
    let kept = restart::write_kept_periods(snapshot, &mut timed)?;
    Ok((kept, timed.at_us))
}

/// The rest of the snapshot back into the session: the scene and heights, every period
/// written flagged held until fresh telemetry. Err if it did not check out (then the
/// default scene). Not inlined, for the same reason.
#[inline(never)]
fn restore(
    session: &mut Session,
    snapshot: &Snapshot,
    kept: Result<(Kept, Option<u64>), Fault>,
) -> Result<(), ()> {
    match kept
        .and_then(|(kept, at_us)| Ok((session.controller.restore_kept(snapshot, kept)?, at_us)))
    {
        Ok((restored, at_us)) => {
            defmt::info!(
                "restored after the reset: {=usize} periods programmed {=u64} us after the board came up, held until fresh telemetry",
                restored.periods,
                at_us.unwrap_or(0)
            );
            Ok(())
        }
        Err(f) => {
            defmt::warn!(
                "the kept snapshot was refused ({=str}): default scene",
                f.name()
            );
            Err(())
        }
    }
}

/// Lends the controller its DEM tile memory and, after a reset, puts the tile kept
/// there back in force if it checks out. Not inlined, as `restore`.
#[inline(never)]
fn restore_dem(session: &mut Session, boot: &retained::Boot) {
    let Some(store) = retained::dem_store(boot) else {
        defmt::error!("no DEM tile memory: DEM frames will be refused");
        return;
    };
    session.controller.attach_dem(store);
    if boot.cause == retained::ResetCause::PowerOn {
        return;
    }
    match session.controller.restore_dem() {
        Ok(id) => defmt::info!("DEM tile {=u32} kept through the reset, in force", id),
        Err(f) => defmt::info!("no DEM tile kept through the reset ({=str})", f.name()),
    }
}

/// A period sink that notes when its first write went through (the board's clock).
struct FirstWrite<'a, S, C> {
    sink: &'a mut S,
    clock: &'a mut C,
    at_us: Option<u64>,
}

impl<S: LinePeriodSink, C: Monotonic> LinePeriodSink for FirstWrite<'_, S, C> {
    type Error = S::Error;
    // Not inlined: its first instruction marks where the first period after a reset is
    // written, for the instruction count of `cargo xtask run --reset-at`.
    #[inline(never)]
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), S::Error> {
        let written = self.sink.write_period(index, ticks);
        if written.is_ok() && self.at_us.is_none() {
            self.at_us = Some(self.clock.now_us());
        }
        written
    }
}

/// What [`start`] gives `main`.
struct Start {
    session: &'static mut Session,
    /// Ok if the kept snapshot was put back.
    restored: Result<(), ()>,
    /// The lowest address of the stack's first paint, for `stack::paint_rest`.
    painted: usize,
}

/// The kept periods into the registers, the stack's first paint, the session built and
/// the rest of the snapshot put back. Its own frame, never inlined: what the restore
/// carries from the first step to the last (the kept scene and periods) lives here
/// during the boot, not in `main`'s frame through the whole pass.
#[inline(never)]
fn start<C: Monotonic>(
    boot: &retained::Boot,
    clocks: &mut LineClocks<board::LineClock>,
    clock: &mut C,
) -> Start {
    let kept = retained::snapshot(boot)
        .map(|snapshot| (snapshot, write_kept_periods(snapshot, clocks, clock)));
    let painted = stack::paint_boot_window();
    let Some(session) = blank_session() else {
        defmt::error!("the session was already taken");
        platform::exit(1)
    };
    session.controller.note_boot(boot.cause, boot.resets);
    let restored = match kept {
        Some((snapshot, kept)) => restore(session, snapshot, kept),
        None => Err(()),
    };
    // The DEM tile kept before the reset, after the periods: its check is a pass over
    // 32 KiB, far more than the boot's budget for the periods.
    restore_dem(session, boot);
    Start {
        session,
        restored,
        painted,
    }
}

#[entry]
fn main() -> ! {
    let Parts {
        mut link,
        line_clock,
        mut clock,
        mut watchdog,
        reset_cause,
        core_clock_hz,
        timer_clock_hz,
    } = match board::take() {
        Ok(parts) => parts,
        Err(e) => {
            defmt::error!("board {=str}: {}", board::NAME, e);
            platform::exit(3)
        }
    };
    // After a reset the last periods go back into the registers first, before anything
    // else that takes time (the stack's paint, the session, logging): docs/target.md,
    // "Faults and resets".
    let boot = retained::boot(reset_cause);
    let mut clocks = LineClocks::new(line_clock);
    let Start {
        session,
        restored,
        painted,
    } = start(&boot, &mut clocks, &mut clock);
    stack::paint_rest(painted);
    // The host's pass player starts sending when it reads this line (a link that is not
    // enabled yet may drop bytes): keep `telemetry::READY` in it.
    defmt::info!(
        "tdi-camera firmware {=str} on {=str}: line-rate controller, {=str} on {=str}",
        env!("CARGO_PKG_VERSION"),
        board::NAME,
        telemetry::READY,
        board::LINK
    );
    defmt::info!(
        "boot: reset cause {=str}, {=u32} resets since power-on, core clock {=u32} Hz",
        boot.cause.name(),
        boot.resets,
        core_clock_hz
    );
    // SysTick and the MPU are the core's: nothing else takes the core peripherals.
    let Some(mut core) = cortex_m::Peripherals::take() else {
        defmt::error!("the core peripherals were already taken");
        platform::exit(3)
    };
    if stack::guard(&mut core.MPU).is_none() {
        defmt::error!("no room for the stack's guard");
        platform::exit(3)
    }
    if heartbeat::start(core.SYST, core_clock_hz).is_none() {
        defmt::error!("no heartbeat at a {=u32} Hz core clock", core_clock_hz);
        platform::exit(3)
    }
    let in_force = restored.or_else(|()| {
        session
            .controller
            .set_scene(Scene::paper_default())
            .map_err(|f| defmt::error!("the default scene was refused: {=str}", f.name()))
    });
    let code = match in_force {
        Ok(()) => {
            let line_clock_hz = session.controller.plan().line_clock_hz;
            if timer_clock_hz as f32 != line_clock_hz {
                defmt::info!(
                    "segment 0's timer counts at {=u32} Hz here, the scene's line clock is {=f32} Hz: the reload register is programmed, the rate is not the line clock's",
                    timer_clock_hz,
                    line_clock_hz
                );
            }
            let summary =
                telemetry::run(&mut link, &mut clocks, &mut clock, &mut watchdog, session);
            let queue = rx::stats();
            defmt::info!(
                "receive queue: at most {=u32} of {=usize} bytes held, full {=u32} times (the UART waited)",
                queue.high_water,
                rx::QUEUE_SLOTS - 1,
                queue.stalls
            );
            let sent = link.tx_stats();
            defmt::info!(
                "transmit queue: at most {=u32} of {=usize} bytes held, the loop slept {=u32} times for room, {=u32} frames dropped whole, {=u32} transmit errors",
                sent.high_water,
                tx::QUEUE_SLOTS - 1,
                summary.tx_waits,
                sent.dropped,
                sent.errors
            );
            if summary.tx_dropped == 0
                && sent.errors == 0
                && summary.rx_errors == 0
                && clocks.errors == 0
            {
                0
            } else {
                defmt::error!(
                    "{=u32} downlink frames dropped, {=u32} transmit errors, {=u32} receive errors, {=u32} line clock writes refused",
                    summary.tx_dropped,
                    sent.errors,
                    summary.rx_errors,
                    clocks.errors
                );
                2
            }
        }
        Err(()) => 1,
    };
    if stack::boot_window_overrun() {
        defmt::warn!(
            "stack: the boot used all {=usize} bytes painted for it; the mark below is a lower bound",
            stack::BOOT_WINDOW_BYTES
        );
    }
    defmt::info!(
        "stack high-water mark: {=usize} bytes (the session, in static memory: {=usize} bytes)",
        stack::high_water_mark_bytes(),
        core::mem::size_of::<controller::session::Session>()
    );
    platform::exit(code)
}

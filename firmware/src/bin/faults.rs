//! A build that fails on purpose, twice, to show that the firmware comes back (docs/
//! target.md, "Faults and resets"; `cargo xtask test` runs it on the mps2-an386, whose
//! watchdog, MPU and system reset QEMU models).
//!
//! Each boot brings the board up as the flight binary does (watchdog started, stack
//! guard and heartbeat set up), reads the reset record and goes on by its cause:
//! 1. after power-on it stops feeding the watchdog (the heartbeat still wakes the core):
//!    the watchdog's early warning notes the cause and resets the core;
//! 2. after the watchdog's reset it recurses until the stack runs into its guard: the
//!    HardFault handler notes a stack overflow and resets the core;
//! 3. after that reset it exits with status 0.
//!
//! Any other cause, or a step that does not end in the reset it should, exits with 1
//! (or hangs until the runner's time limit, if no watchdog fires).
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::board::{self, Monotonic, Parts, WATCHDOG_TIMEOUT_MS};
use firmware::retained::{self, ResetCause};
use firmware::{heartbeat, platform, stack};

#[entry]
fn main() -> ! {
    let Parts {
        mut clock,
        reset_cause,
        core_clock_hz,
        ..
    } = match board::take() {
        Ok(parts) => parts,
        Err(e) => {
            defmt::error!("board {=str}: {}", board::NAME, e);
            platform::exit(3)
        }
    };
    let boot = retained::boot(reset_cause);
    defmt::info!(
        "boot: reset cause {=str}, {=u32} resets since power-on",
        boot.cause.name(),
        boot.resets
    );
    let Some(mut core) = cortex_m::Peripherals::take() else {
        platform::exit(3)
    };
    let Some(guard) = stack::guard(&mut core.MPU) else {
        platform::exit(3)
    };
    let Some(_syst) = heartbeat::start(core.SYST, core_clock_hz) else {
        platform::exit(3)
    };
    match (boot.resets, boot.cause) {
        (0, ResetCause::PowerOn) => {
            defmt::info!(
                "hanging on purpose at t = {=u64} us: nothing feeds the watchdog (time-out {=u32} ms)",
                clock.now_us(),
                WATCHDOG_TIMEOUT_MS
            );
            loop {
                // The heartbeat wakes the core; nothing feeds the watchdog.
                cortex_m::asm::wfi();
            }
        }
        (1, ResetCause::Watchdog) => {
            defmt::info!(
                "overflowing the stack on purpose: guard at {=usize:#010x}..{=usize:#010x}",
                guard.start,
                guard.end
            );
            let depth = recurse(u32::MAX);
            defmt::error!("the recursion returned ({=u32}): no overflow", depth);
            platform::exit(1)
        }
        (2, ResetCause::StackOverflow) => {
            defmt::info!("recovered: running again after a watchdog reset and a stack overflow");
            platform::exit(0)
        }
        (resets, cause) => {
            defmt::error!(
                "unexpected: reset cause {=str} after {=u32} resets",
                cause.name(),
                resets
            );
            platform::exit(1)
        }
    }
}

/// Recursion `n` deep, each frame holding 64 bytes the optimiser cannot drop.
#[inline(never)]
fn recurse(n: u32) -> u32 {
    let frame = core::hint::black_box([n; 16]);
    if n == 0 {
        return 0;
    }
    let below = recurse(core::hint::black_box(n - 1));
    below.wrapping_add(frame.iter().fold(0, |a, b| a ^ b))
}

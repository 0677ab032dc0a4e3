//! A build that hangs on purpose, to show the watchdog at work (docs/target.md, "Faults
//! and resets"; `cargo xtask test` runs it on the mps2-an386, whose watchdog QEMU
//! models).
//!
//! After power-on it brings the board up as the flight binary does (watchdog started,
//! heartbeat running) and then stops feeding the watchdog: the loop that feeds it is
//! gone, the heartbeat still wakes the core. The watchdog's early warning notes the
//! cause in retained RAM and resets the core; the next boot reads the cause and the
//! count, reports them and exits with status 0 if the cause is the watchdog (1 if not).
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::board::{self, Monotonic, Parts, WATCHDOG_TIMEOUT_MS};
use firmware::retained::{self, ResetCause};
use firmware::{heartbeat, platform};

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
    if boot.resets > 0 {
        let code = if boot.cause == ResetCause::Watchdog {
            0
        } else {
            1
        };
        defmt::info!(
            "recovered: running again after a {=str} reset",
            boot.cause.name()
        );
        platform::exit(code)
    }
    let Some(syst) = cortex_m::Peripherals::take().map(|p| p.SYST) else {
        platform::exit(3)
    };
    let Some(_syst) = heartbeat::start(syst, core_clock_hz) else {
        platform::exit(3)
    };
    defmt::info!(
        "hanging on purpose at t = {=u64} us: nothing feeds the watchdog (time-out {=u32} ms)",
        clock.now_us(),
        WATCHDOG_TIMEOUT_MS
    );
    loop {
        // The heartbeat wakes the core every HEARTBEAT_MS; nothing feeds the watchdog.
        cortex_m::asm::wfi();
    }
}

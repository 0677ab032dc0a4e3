//! The heartbeat: SysTick, the core's own timer (the same on every board), raises an
//! exception every [`HEARTBEAT_MS`] that wakes the loop from its sleep. The loop then
//! goes round once and feeds the watchdog, so that a link with nothing to say is not
//! taken for a hung loop; the exception itself does nothing else, so a loop that is
//! stuck elsewhere still starves the watchdog.

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use cortex_m_rt::exception;

use crate::board::HEARTBEAT_MS;

/// Starts SysTick on the core clock of `core_clock_hz`. None if the period does not fit
/// its 24-bit counter at that clock.
pub fn start(mut syst: SYST, core_clock_hz: u32) -> Option<SYST> {
    let ticks = core_clock_hz / 1000 * HEARTBEAT_MS;
    let reload = ticks.checked_sub(1).filter(|r| *r < (1 << 24))?;
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(reload);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
    Some(syst)
}

#[exception]
fn SysTick() {}

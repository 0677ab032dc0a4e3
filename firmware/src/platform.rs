//! What ties the application to the chip and the debugger: the defmt logger, the panic
//! and fault handlers, and the way out.
//!
//! Logging goes through semihosting (`defmt-semihosting`): under QEMU the host runner
//! (`cargo xtask qemu`) decodes the frames; on a board, probe-rs does. The exit status
//! reaches QEMU's (and so the runner's) exit status by semihosting as well.

use cortex_m as _; // critical-section implementation for defmt-semihosting
use cortex_m_rt::{exception, ExceptionFrame};
use defmt_semihosting as _; // the global defmt logger

/// Exit status of a panic (never expected: the firmware's own paths return `Result`).
pub const EXIT_PANIC: i32 = 101;
/// Exit status of a HardFault.
pub const EXIT_HARD_FAULT: i32 = 102;

/// Ends the program with `code` as the debugger's (QEMU's) exit status.
pub fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    exit(EXIT_PANIC)
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    exit(EXIT_PANIC)
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    defmt::error!("hard fault at pc {=u32:#010x}", frame.pc());
    exit(EXIT_HARD_FAULT)
}

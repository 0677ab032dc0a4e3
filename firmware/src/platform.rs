//! What ties the application to the chip and the debugger: the defmt logger, the panic
//! and fault handlers, and the way out.
//!
//! Logging goes through semihosting (the global defmt logger in `crate::logger`):
//! under QEMU the host runner (`cargo xtask qemu`) decodes the frames. On a real board
//! the feature `defmt-rtt` puts the logger in RTT memory instead, where probe-rs reads
//! it without halting the core. The exit status reaches QEMU's (and so the runner's)
//! exit status by semihosting, on a board probe-rs's.

use cortex_m as _; // critical-section implementation for the logger
use cortex_m_rt::{exception, ExceptionFrame};

use crate::retained::{self, ResetCause};
#[cfg(feature = "defmt-rtt")]
use defmt_rtt as _; // the global defmt logger on a real board

/// Exit status of a panic (never expected: the firmware's own paths return `Result`).
pub const EXIT_PANIC: i32 = 101;
/// Exit status of an interrupt the firmware never unmasks (mps2-an386's default handler).
pub const EXIT_UNEXPECTED_INTERRUPT: i32 = 103;

/// Ends the program with `code` as the debugger's (QEMU's) exit status.
// Out of line in the flight binary: `main`, the start-up and the default handler each
// inlined a copy. Not in the bench binary, whose single-pixel regions it moved (the
// harness's registers around `black_box`, docs/target.md).
#[cfg_attr(not(feature = "bench"), inline(never))]
pub fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}

#[cfg(not(feature = "no-panic-check"))]
#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    exit(EXIT_PANIC)
}

#[cfg(not(feature = "no-panic-check"))]
#[defmt::panic_handler]
fn defmt_panic() -> ! {
    exit(EXIT_PANIC)
}

// The no-panic proof (docs/no-panic.md): built with `--features no-panic-check`, both
// panic handlers call a function that no object defines. After fat LTO and the linker's
// garbage collection, a handler that no reachable code calls is gone with its call, and
// the link succeeds; a single surviving panic path keeps it, and the link fails with
// "undefined symbol: NO_PANIC_CHECK__...". Such a binary must never run, so the feature
// is only for that one link (`cargo xtask test`, xtask/src/no_panic.rs).
#[cfg(feature = "no-panic-check")]
extern "C" {
    fn NO_PANIC_CHECK__a_panic_path_is_reachable__see_docs_no_panic_md(
        location: *const core::ffi::c_void,
    ) -> !;
}

#[cfg(feature = "no-panic-check")]
#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    // The location is passed on only so that the panic sites' `Location` records stay in
    // the ELF, where `cargo xtask test` finds them when the link has failed (it then links
    // once more with the symbol left unresolved, never to run).
    let location = info.location().map_or(core::ptr::null(), |l| {
        core::ptr::from_ref(l).cast::<core::ffi::c_void>()
    });
    // SAFETY: never runs: the symbol is undefined, so a binary that calls it cannot link.
    unsafe { NO_PANIC_CHECK__a_panic_path_is_reachable__see_docs_no_panic_md(location) }
}

#[cfg(feature = "no-panic-check")]
#[defmt::panic_handler]
fn defmt_panic() -> ! {
    // SAFETY: as in `panic`.
    unsafe { NO_PANIC_CHECK__a_panic_path_is_reachable__see_docs_no_panic_md(core::ptr::null()) }
}

/// A HardFault, the stack's guard included (crate::stack): the cause is noted in
/// retained RAM for the next boot, and the core is reset, as the watchdog would (docs/
/// target.md, "Faults and resets"). Runs with the MPU off, on the guard's room if the
/// stack overflowed.
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    let cause = if crate::stack::overflowed() {
        ResetCause::StackOverflow
    } else {
        ResetCause::Fault
    };
    retained::note_cause(cause);
    // After an overflow the exception frame could not be stacked: no pc to show.
    let pc = if cause == ResetCause::StackOverflow {
        0
    } else {
        frame.pc()
    };
    defmt::error!(
        "{=str} (pc {=u32:#010x}; 0: none stacked): resetting",
        cause.name(),
        pc
    );
    cortex_m::peripheral::SCB::sys_reset()
}

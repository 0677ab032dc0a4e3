//! The global defmt logger: defmt frames, rzCOBS-encoded by [`defmt::Encoder`], written
//! to the debugger's stdout by Arm semihosting (`SYS_OPEN ":tt"`, `SYS_WRITE`), the same
//! bytes `defmt-semihosting` 0.4 wrote, so the host side (`cargo xtask qemu`, probe-rs,
//! `defmt-print`) decodes them unchanged.
//!
//! Why not `defmt-semihosting`: it panics when the logger is taken re-entrantly or used
//! out of its acquire/release pair, and on a `-1` file handle (`semihosting`'s
//! `BorrowedFd::borrow_raw` asserts it); those were the only panic paths of the flight
//! binary outside its own code (docs/no-panic.md). This logger never panics:
//!
//! - [`defmt::Logger`]'s contract (defmt 1.2): `acquire`, any number of `write`, one
//!   `release`, in one execution context; `acquire` "panics if already acquired in the
//!   current execution context". Here the first `acquire` takes a critical section
//!   (`critical-section`, PRIMASK on this single-core chip) and holds it until its
//!   `release`, like `defmt-semihosting`. What can still run inside it is a fault
//!   handler (HardFault, NMI: PRIMASK does not mask them), or code called while a frame
//!   is being formatted. Such a nested frame is dropped whole (its `acquire`, `write`s
//!   and `release` only count), so the interrupted frame continues intact: the stream
//!   stays decodable and nothing panics. The HardFault handler's own line is lost in
//!   that one case; the cause it notes in retained RAM still says what happened.
//! - `write` or `release` without `acquire` (a broken contract) does nothing.
//! - Semihosting errors are ignored ("best effort", as the contract asks); if stdout
//!   cannot be opened, frames go nowhere and the next `acquire` tries again.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use semihosting::fd::{BorrowedFd, RawFd};
use semihosting::sys::arm_compat::{sys_open, sys_write_orig, OpenMode};

#[defmt::global_logger]
struct Logger;

/// The logger's state. The `UnsafeCell`s are touched only by the context that holds the
/// logger (`taken` set by it, inside its critical section) and not nested.
struct State {
    /// Set between the outermost `acquire` and its `release`.
    taken: AtomicBool,
    /// `acquire`s made while `taken` whose `release` has not come yet.
    nested: AtomicU32,
    /// Frames dropped because they were nested (see the module documentation).
    dropped: AtomicU32,
    /// The critical section's restore state, from the outermost `acquire`.
    restore: UnsafeCell<critical_section::RestoreState>,
    encoder: UnsafeCell<defmt::Encoder>,
    /// Semihosting stdout once it is open (it is never closed).
    fd: UnsafeCell<Option<RawFd>>,
}

// SAFETY: the cells are accessed only by the context that set `taken` inside its
// critical section (single core): no other context reads or writes them until it
// releases. Nested contexts see `taken` and touch only the atomics.
unsafe impl Sync for State {}

static STATE: State = State {
    taken: AtomicBool::new(false),
    nested: AtomicU32::new(0),
    dropped: AtomicU32::new(0),
    restore: UnsafeCell::new(critical_section::RestoreState::invalid()),
    encoder: UnsafeCell::new(defmt::Encoder::new()),
    fd: UnsafeCell::new(None),
};

/// Frames dropped because they were logged from inside another frame (a fault handler
/// that interrupted a log line).
pub fn dropped_frames() -> u32 {
    STATE.dropped.load(Ordering::Relaxed)
}

/// Writes all of `bytes` to `fd`, giving up silently on an error or no progress.
// Out of line: inlined into each of defmt's three entry points (docs/target.md, flash).
#[inline(never)]
fn write_all(fd: Option<RawFd>, mut bytes: &[u8]) {
    // -1 is no handle (and `BorrowedFd::borrow_raw` asserts it is not: this test lets
    // the optimiser drop that assertion's panic).
    let Some(fd) = fd.filter(|&fd| fd != -1) else {
        return;
    };
    // SAFETY: `fd` was returned by SYS_OPEN, is never closed, and is not -1.
    let fd = unsafe { BorrowedFd::borrow_raw(fd) };
    while !bytes.is_empty() {
        // SYS_WRITE answers with the number of bytes *not* written.
        let Ok(not_written) = sys_write_orig(fd, bytes) else {
            return;
        };
        let rest = bytes
            .len()
            .checked_sub(not_written)
            .and_then(|written| bytes.get(written..));
        match rest {
            Some(rest) if rest.len() < bytes.len() => bytes = rest,
            _ => return,
        }
    }
}

/// The open stdout handle, opening it first if needed; `None` if that fails.
///
/// # Safety
/// Only the context holding the logger may call this. Out of line: `acquire`, `write`
/// and `release` each inlined the open (docs/target.md, `m3-flash3`).
#[inline(never)]
unsafe fn stdout_fd() -> Option<RawFd> {
    // SAFETY: the caller holds the logger: nobody else touches the cell.
    let fd = unsafe { &mut *STATE.fd.get() };
    if fd.is_none() {
        *fd = sys_open(c":tt", OpenMode::WRONLY_TRUNC)
            .ok()
            .map(|owned| owned.into_raw_fd());
    }
    *fd
}

// SAFETY: `acquire` takes the logger once per execution context (nested contexts are
// counted and dropped, never given the encoder), `write`/`release` act only for the
// holder, and `release` ends the critical section `acquire` began.
unsafe impl defmt::Logger for Logger {
    fn acquire() {
        // SAFETY: paired with exactly one `critical_section::release`: below for a
        // nested context, in `release` for the holder.
        let restore = unsafe { critical_section::acquire() };
        if STATE.taken.load(Ordering::Relaxed) {
            // Nested: drop this frame. Leave the (inner, LIFO) critical section at
            // once; the holder's is still in force.
            let n = STATE.nested.load(Ordering::Relaxed);
            STATE.nested.store(n.saturating_add(1), Ordering::Relaxed);
            let d = STATE.dropped.load(Ordering::Relaxed);
            STATE.dropped.store(d.saturating_add(1), Ordering::Relaxed);
            // SAFETY: the section taken just above, released before the outer one.
            unsafe { critical_section::release(restore) };
            return;
        }
        STATE.taken.store(true, Ordering::Relaxed);
        // SAFETY: we hold the logger now (taken, inside our critical section).
        unsafe {
            STATE.restore.get().write(restore);
            let fd = stdout_fd();
            (*STATE.encoder.get()).start_frame(|b| write_all(fd, b));
        }
    }

    unsafe fn flush() {
        // Semihosting writes are synchronous: once SYS_WRITE returns, the host has the
        // bytes. Nothing to flush.
    }

    unsafe fn release() {
        let n = STATE.nested.load(Ordering::Relaxed);
        if n > 0 {
            // The end of a dropped nested frame.
            STATE.nested.store(n - 1, Ordering::Relaxed);
            return;
        }
        if !STATE.taken.load(Ordering::Relaxed) {
            return;
        }
        // SAFETY: we hold the logger (taken, not nested).
        unsafe {
            let fd = stdout_fd();
            (*STATE.encoder.get()).end_frame(|b| write_all(fd, b));
            let restore = STATE.restore.get().read();
            STATE.taken.store(false, Ordering::Relaxed);
            // SAFETY: ends the critical section of the matching `acquire`.
            critical_section::release(restore);
        }
    }

    unsafe fn write(bytes: &[u8]) {
        if STATE.nested.load(Ordering::Relaxed) > 0 || !STATE.taken.load(Ordering::Relaxed) {
            return;
        }
        // SAFETY: we hold the logger (taken, not nested).
        unsafe {
            let fd = stdout_fd();
            (*STATE.encoder.get()).write(bytes, |b| write_all(fd, b));
        }
    }
}

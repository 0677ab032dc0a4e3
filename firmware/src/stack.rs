//! The stack: its high-water mark, and the guard that makes an overflow a fault.
//!
//! cortex-m-rt puts the stack at the top of RAM, growing down towards `.bss`. `main`
//! paints the stack region below its frame, from `_stack_end` (the end of `.bss` and
//! `.uninit`) up, with [`STACK_PAINT_VALUE`]; the deepest word the stack has overwritten
//! since is the lowest one that no longer holds the paint. The firmware has no heap and a
//! few bytes of static data, so this peak is its RAM use.
//!
//! The paint comes in two strokes: [`paint_boot_window`] first, the [`BOOT_WINDOW_BYTES`]
//! below `main`'s frame, which the board's bring-up and a reset's restore run in; then,
//! once the periods are back in the registers, [`paint_rest`], the region below. Painting
//! the whole region before `main` (cortex-m-rt's `paint-stack`) would hold the periods
//! back after a reset by its length: 4 MiB of stack on the mps2 (docs/target.md, "Faults
//! and resets").
//!
//! The guard ([`guard`]) is an MPU region of [`GUARD_BYTES`] with no access at the
//! bottom of the stack region, between the stack and `.bss`: a push that reaches it is a
//! MemManage fault, which (MemManage not being enabled) escalates to HardFault. The MPU
//! stays off for HardFault and NMI (MPU_CTRL.HFNMIENA clear), so the HardFault handler's
//! own frames land in the guard, which is large enough for them, and never in `.bss`:
//! the handler notes the cause in retained RAM and resets (crate::platform). That is
//! how `flip-link` would do it too, from the other side (the stack below `.bss`, the
//! fault from the end of RAM); the MPU needs no extra linker and works on every board.

use core::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use cortex_m::peripheral::MPU;

/// The paint: cortex-m-rt's value (its `paint-stack` feature, not used here, would write
/// the same), unlikely as data and odd as an address.
pub const STACK_PAINT_VALUE: u32 = 0xcccc_cccc;

extern "C" {
    // Symbols of cortex-m-rt's link.x: only their addresses are used.
    static _stack_end: u32;
    static _stack_start: u32;
}

/// The guard's size (bytes): a power of two (an ARMv7-M MPU region), room for the
/// HardFault handler's exception frame (up to 104 bytes with the FPU's context) and its
/// calls, logger included.
pub const GUARD_BYTES: usize = 1024;

/// The first address above the guard (0 while there is none).
static GUARD_TOP: AtomicUsize = AtomicUsize::new(0);

/// The guard's address range, if [`guard`] has set it up.
pub fn guard_range() -> Option<core::ops::Range<usize>> {
    let top = GUARD_TOP.load(Ordering::Relaxed);
    (top != 0).then(|| top - GUARD_BYTES..top)
}

/// Sets up the guard: MPU region 0, [`GUARD_BYTES`] aligned to its size, at the bottom
/// of the stack region; every other address keeps the default memory map. Returns the
/// guard's range, None if the stack region cannot hold it.
pub fn guard(mpu: &mut MPU) -> Option<core::ops::Range<usize>> {
    let low = (&raw const _stack_end) as usize;
    let high = (&raw const _stack_start) as usize;
    let base = low.checked_next_multiple_of(GUARD_BYTES)?;
    let top = base.checked_add(GUARD_BYTES)?;
    if top >= high {
        return None;
    }
    // RASR: XN (bit 28), AP 0b000 (no access, bits 26:24), TEX 0 C 1 B 0 (normal memory,
    // as RAM is), SIZE = log2(bytes) - 1 (bits 5:1), ENABLE.
    let size_field = GUARD_BYTES.trailing_zeros() - 1;
    let rasr = (1 << 28) | (1 << 17) | (size_field << 1) | 1;
    // CTRL: ENABLE, PRIVDEFENA (the default map elsewhere); HFNMIENA clear.
    let ctrl = 0b101;
    // SAFETY: one region of no access over stack RAM that nothing uses while the stack
    // is shallower than the region's top (the paint shows how deep it has been: checked
    // below), and the default map everywhere else: no access the firmware makes changes
    // meaning, except a push into the guard, which is the point.
    unsafe {
        mpu.rnr.write(0);
        mpu.rbar.write(base as u32);
        mpu.rasr.write(rasr);
        mpu.ctrl.write(ctrl);
    }
    cortex_m::asm::dsb();
    cortex_m::asm::isb();
    GUARD_TOP.store(top, Ordering::Relaxed);
    Some(base..top)
}

/// The stack the boot may use before [`paint_rest`]: the stack budget of the firmware
/// (docs/target.md). A mark of this size or more says the boot went past it.
pub const BOOT_WINDOW_BYTES: usize = 12 * 1024;

/// Set by [`paint_rest`] when the boot's frames had reached the bottom of the boot
/// window: then the high-water mark is a lower bound, not the peak.
static BOOT_WINDOW_OVERRUN: AtomicBool = AtomicBool::new(false);

/// Whether the boot used the whole window painted for it ([`BOOT_WINDOW_OVERRUN`]).
pub fn boot_window_overrun() -> bool {
    BOOT_WINDOW_OVERRUN.load(Ordering::Relaxed)
}

/// Paints the [`BOOT_WINDOW_BYTES`] below the caller's frame (down to the region's
/// bottom at most); returns the lowest address painted, for [`paint_rest`].
#[inline(never)]
pub fn paint_boot_window() -> usize {
    let low = (&raw const _stack_end) as usize;
    // The stack pointer as read here may be above this function's own frame (its
    // prologue may come after the read): stop short of it by a margin.
    let below_frame = (cortex_m::register::msp::read() as usize & !3).saturating_sub(256);
    let from = below_frame.saturating_sub(BOOT_WINDOW_BYTES).max(low);
    paint(from, below_frame);
    from
}

/// Paints the stack region below `painted` (what [`paint_boot_window`] returned).
#[inline(never)]
pub fn paint_rest(painted: usize) {
    let low = (&raw const _stack_end) as usize;
    // SAFETY: `painted` is a word of the stack region that `paint_boot_window` painted,
    // below every frame since unless the boot reached it: a read.
    let reached = painted > low
        && unsafe { core::ptr::read_volatile(painted as *const u32) } != STACK_PAINT_VALUE;
    BOOT_WINDOW_OVERRUN.store(reached, Ordering::Relaxed);
    paint(low, painted);
}

/// Writes the paint over [from, to), word by word.
fn paint(from: usize, to: usize) {
    let mut p = from;
    while p < to {
        // SAFETY: [from, to) lies in the stack region (word-aligned: link.x asserts it)
        // below the running frames: nothing lives there (ARMv7-M code keeps nothing
        // below the stack pointer; an interrupt's frames there are gone by the time this
        // loop runs again), and no guard is set up yet (`main` paints before `guard`).
        unsafe { core::ptr::write_volatile(p as *mut u32, STACK_PAINT_VALUE) };
        p += 4;
    }
}

/// Bytes of stack used since reset: from the top of RAM down to the lowest word whose
/// paint is gone (a word that the stack wrote with the paint value itself would count as
/// unused: the figure can be low by the few bytes above such a word, never high). With
/// the guard set up, the scan starts above it (the guard cannot be read).
pub fn high_water_mark_bytes() -> usize {
    let low = (&raw const _stack_end) as usize;
    let high = (&raw const _stack_start) as usize;
    let mut p = low.max(GUARD_TOP.load(Ordering::Relaxed));
    while p < high {
        // SAFETY: [low, high) is the stack region of RAM, word-aligned (link.x asserts
        // it), the guard excluded; below the deepest frame so far nothing is in use, and
        // the scan stops at the first word above that: it reads, never writes.
        if unsafe { core::ptr::read_volatile(p as *const u32) } != STACK_PAINT_VALUE {
            break;
        }
        p += 4;
    }
    high.saturating_sub(p)
}

/// Whether the fault being handled is the stack running into the guard: a MemManage
/// fault (escalated) while stacking, or a data access the MPU refused inside the guard.
/// For the HardFault handler.
pub fn overflowed() -> bool {
    // CFSR's MemManage byte: DACCVIOL (bit 1), MSTKERR (bit 4), MMARVALID (bit 7).
    // SAFETY: reads of the System Control Block's fault status and address registers.
    let (cfsr, mmfar) = unsafe {
        let scb = &*cortex_m::peripheral::SCB::PTR;
        (scb.cfsr.read(), scb.mmfar.read() as usize)
    };
    let stacking = cfsr & (1 << 4) != 0;
    let in_guard = cfsr & (1 << 1) != 0
        && cfsr & (1 << 7) != 0
        && guard_range().is_some_and(|g| g.contains(&mmfar));
    guard_range().is_some() && (stacking || in_guard)
}

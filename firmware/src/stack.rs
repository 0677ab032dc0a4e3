//! Stack high-water mark. cortex-m-rt (feature `paint-stack`) paints the whole stack
//! region, from `_stack_end` (the end of `.bss` and `.uninit`) up to `_stack_start`
//! (the top of RAM), with [`STACK_PAINT_VALUE`] before `main` runs; the deepest word the
//! stack has overwritten since is the lowest one that no longer holds the paint. The
//! firmware has no heap and a few bytes of static data, so this peak is its RAM use.

use cortex_m_rt::STACK_PAINT_VALUE;

extern "C" {
    // Symbols of cortex-m-rt's link.x: only their addresses are used.
    static _stack_end: u32;
    static _stack_start: u32;
}

/// Bytes of stack used since reset: from the top of RAM down to the lowest word whose
/// paint is gone (a word that the stack wrote with the paint value itself would count as
/// unused: the figure can be low by the few bytes above such a word, never high).
pub fn high_water_mark_bytes() -> usize {
    let low = (&raw const _stack_end) as usize;
    let high = (&raw const _stack_start) as usize;
    let mut p = low;
    while p < high {
        // SAFETY: [low, high) is the stack region of RAM, word-aligned (link.x asserts
        // it); below the deepest frame so far nothing is in use, and the scan stops at
        // the first word above that: it reads, never writes.
        if unsafe { core::ptr::read_volatile(p as *const u32) } != STACK_PAINT_VALUE {
            break;
        }
        p += 4;
    }
    high.saturating_sub(p)
}

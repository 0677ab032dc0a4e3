//! Stack high-water mark: paint a band below the stack pointer with a pattern at boot,
//! find later how far down the pattern was overwritten. The firmware has no heap and
//! only 16 bytes of static data, so this peak is its RAM use.

/// How far below the painting function's stack pointer the band reaches (bytes).
pub const BAND: usize = 64 * 1024;
const PATTERN: u32 = 0x5AC3_5AC3;
/// Left untouched just below the stack pointer (the painting call's own frame).
const GUARD: usize = 256;

/// A painted band: `[low, high)`, and the stack pointer it was measured from.
pub struct Painted {
    low: usize,
    high: usize,
    top: usize,
}

/// Paints the band; call first thing in `main`.
pub fn paint() -> Painted {
    let sp = cortex_m::register::msp::read() as usize;
    let high = sp.saturating_sub(GUARD) & !3;
    let low = high.saturating_sub(BAND);
    let mut p = low;
    while p < high {
        // SAFETY: [low, high) is RAM below the live stack (the RAM is 4 MiB and
        // nothing but the stack lives above .bss), not yet used by any frame.
        unsafe { core::ptr::write_volatile(p as *mut u32, PATTERN) };
        p += 4;
    }
    Painted { low, high, top: sp }
}

impl Painted {
    /// Bytes of stack used below the painting point's stack pointer so far (at least
    /// the band's size if the pattern is gone entirely).
    pub fn peak(&self) -> usize {
        let mut p = self.low;
        while p < self.high {
            // SAFETY: as in `paint`: RAM, word-aligned, read only.
            if unsafe { core::ptr::read_volatile(p as *const u32) } != PATTERN {
                break;
            }
            p += 4;
        }
        self.top.saturating_sub(p)
    }
}

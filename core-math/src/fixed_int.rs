//! Integer helpers the two fixed-point backends share (the round Earth's,
//! `sphere::fixed_point`, and the real Earth's, `earth::fixed`): the seed table of their
//! per-pixel square roots and a 64-bit shift in 32-bit halves.

/// Seeds r0 = 1/sqrt(f) in Q14 at the centres of the intervals [i/1024, (i+1)/1024),
/// i in 128..1024, that split [1/8, 1): isqrt(2^39 / (2i + 1)) =
/// floor(2^14 sqrt(1024 / (i + 1/2))) < 46 251. Relative error of a seed: at most
/// 2^-11 / (2 f) <= 2^-9. Built at compile time, integer only. Entries 0..128 are never
/// read (each caller keeps f >= 1/8); they make the index a 10-bit field with no bounds
/// check. 2 KiB of flash.
pub(crate) const RSQRT_SEED: [u16; 1024] = {
    let mut t = [0u16; 1024];
    let mut i = 128;
    while i < 1024 {
        t[i] = ((1u64 << 39) / (2 * i as u64 + 1)).isqrt() as u16;
        i += 1;
    }
    t
};

/// x >> sh (arithmetic) for sh in 1..=31, in 32-bit halves: the compiler cannot know
/// that the shift is below 32 and would otherwise emit the general 64-bit sequence.
#[inline(always)]
pub(crate) fn shr(x: i64, sh: u32) -> i64 {
    debug_assert!((1..32).contains(&sh));
    let lo = x as u32;
    let hi = (x >> 32) as i32;
    let lo = (lo >> (sh & 31)) | ((hi as u32) << ((32 - sh) & 31));
    (((hi >> (sh & 31)) as i64) << 32) | lo as i64
}

//! Radians (I24F40) to binary angle (turns, Q64): the one multiplication that makes
//! range reduction free.

/// round(2^87 / pi): turns * 2^128 = x_bits * 2^-40 / (2 pi) * 2^128 = x_bits * 2^87 / pi.
const K_TURNS: i128 = 49_256_069_125_910_843_489_192_406;

/// The angle `x_bits * 2^-40` rad as a fraction of a turn in Q64 (u64, wrapping: the
/// integer number of turns falls off the top of the 128-bit product, which is exactly
/// the reduction modulo 2 pi). Error: |x_bits| / 2 units of 2^-128 turn from the rounding
/// of `K_TURNS`, below 2^-71 turn (3e-21 rad) for any I24F40 input.
#[inline]
pub(crate) fn rad_to_turns(x_bits: i64) -> u64 {
    // Wrapping is the point here: only the product modulo 2^128 is wanted.
    ((x_bits as i128).wrapping_mul(K_TURNS) >> 64) as u64
}

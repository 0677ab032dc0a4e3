//! The per-pixel function of the real-Earth fixed-point backend behind a C symbol, for
//! `tools/check-no-float.sh`, and a canary the script must flag (proof that its
//! detector works).
#![no_std]

use core_math::earth::fixed::{EarthFixedPixel, EarthFixedUpdate};
use core_math::{Backend, EARTH_FIXED};

/// `EARTH_FIXED.motion`: v1 and v2 as I24F40 bits in `out`; 0, or 1 + the error's
/// discriminant position in a stable order.
#[no_mangle]
pub extern "C" fn earth_fixed_motion(
    up: &EarthFixedUpdate,
    px: &EarthFixedPixel,
    out: &mut [i64; 2],
) -> u32 {
    match EARTH_FIXED.motion(up, px) {
        Ok(m) => {
            *out = [m.v1_mps.to_bits(), m.v2_mps.to_bits()];
            0
        }
        Err(core_math::ModelError::LineOfSightMissesEarth) => 1,
        Err(_) => 2,
    }
}

/// A function that does use floating point (soft float on thumbv7m): the script checks
/// that it flags this one, or its verdict on `earth_fixed_motion` would mean nothing.
#[no_mangle]
pub extern "C" fn float_canary(x: f64, y: f32) -> f64 {
    x * 1.5 + y as f64
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}

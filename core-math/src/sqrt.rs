//! Correctly rounded f32 square root at the cost of one FPU instruction on the Cortex-M4F.
//!
//! `f32::sqrt` lives in `std`, and `libm::sqrtf` is a software loop on this target
//! (its cost: shared/EMBEDDED-NOTES.md). The FPv4-SP unit has `vsqrt.f32`, correctly rounded like
//! `sqrtf`, so results are bit-identical to the host's `libm::sqrtf`. Stable Rust refuses
//! inline `asm!` with `sreg` operands on thumbv7em (no `vfp2` target feature at the asm
//! level), so the instruction sits in a two-instruction `global_asm!` leaf function that
//! follows the hard-float ABI (argument and result in s0).

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
mod asm {
    core::arch::global_asm!(
        ".section .text.core_math_vsqrt_f32,\"ax\",%progbits",
        ".fpu fpv4-sp-d16",
        ".thumb",
        ".global core_math_vsqrt_f32",
        ".type core_math_vsqrt_f32,%function",
        ".thumb_func",
        "core_math_vsqrt_f32:",
        "vsqrt.f32 s0, s0",
        "bx lr",
        ".size core_math_vsqrt_f32, . - core_math_vsqrt_f32",
    );
}

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
extern "C" {
    fn core_math_vsqrt_f32(x: f32) -> f32;
}

/// sqrt(x), correctly rounded; NaN for x < 0 as IEEE 754 says (callers check first).
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[inline(always)]
#[allow(unsafe_code)]
pub fn sqrt_f32(x: f32) -> f32 {
    // SAFETY: the callee reads s0, writes s0 and touches no memory; it follows the
    // AAPCS-VFP calling convention that `extern "C"` uses on this target.
    unsafe { core_math_vsqrt_f32(x) }
}

/// sqrt(x), correctly rounded; NaN for x < 0 as IEEE 754 says (callers check first).
/// Without the FPU a call: inlined, libm's software loop was one more copy in each
/// caller (docs/target.md, flash).
#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
#[inline(never)]
pub fn sqrt_f32(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// sqrt(x) in f64, libm's (correctly rounded), as a call: the cold paths that take
/// square roots in f64 (the plan build, the scene's checks) share one copy instead of
/// fat LTO inlining the soft-float routine into each (docs/target.md, flash).
#[inline(never)]
pub fn sqrt_f64(x: f64) -> f64 {
    libm::sqrt(x)
}

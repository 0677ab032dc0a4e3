//! Image-motion velocity of a TDI push-broom camera on an agile satellite, and what
//! follows from it: the line period, the MTF lost to a velocity mismatch and to drift,
//! the TDI stage limit.
//!
//! The model the firmware flies is the real-Earth model of `../shared/EARTH-MODEL.md`
//! ([`earth`]): a satellite on a Kepler orbit given by its state vector, a camera turned
//! by roll, pitch and yaw moving at their own rates, a pixel anywhere on the focal plane,
//! the ground as the WGS 84 ellipsoid raised by the terrain. Its backends, each one
//! implementation of [`Backend`]`<`[`Earth`]`>`:
//! - [`General<f32>`] ([`GENERAL_F32`]): the closed general form in f32, split into a
//!   per-update and a per-pixel part: the flown path;
//! - [`General<f64>`] ([`GENERAL_F64`]): the same form in f64;
//! - `EarthFixed` (`EARTH_FIXED`, feature `earth-fixed`): the same form with the
//!   per-pixel part in integers only, for cores without an FPU;
//! - [`EarthReference`] (feature `reference`): the construction evaluated literally on
//!   dual numbers in f64, independent of the closed form: the golden source.
//!
//! Around it: [`line_period`] (seconds and clock ticks), [`mtf`] (mismatch, drift smear,
//! stage limit), [`accuracy`] (the measured error bounds), [`trig`] and [`vector`].
//! Start reading at [`earth`] and its [`earth::general`]; [`model`] holds the interface
//! every backend implements.
//!
//! The paper this started from (LI Guang-ze, KONG De-zhu, LIU Jin-guo, "Computation of
//! scroll image motion velocity of wide coverage optical remote camera", Chinese Optics
//! 6(5), 2013: a round Earth, roll only, its Eqs. 14-15 re-derived and corrected in
//! `docs/derivation.md`) lives in [`sphere`] behind the feature `sphere`, with its own
//! backends (closed form in f64, f32 and fixed point, its transform chain, a naive f32
//! baseline). The flight firmware does not enable it.
//!
//! `no_std`, no allocation, no panics on any input: every refusal is a [`ModelError`].
#![no_std]
// The one exception is the documented `vsqrt.f32` wrapper in `sqrt.rs`, on the target only.
#![cfg_attr(
    not(all(target_arch = "arm", target_abi = "eabihf")),
    forbid(unsafe_code)
)]
#![cfg_attr(all(target_arch = "arm", target_abi = "eabihf"), deny(unsafe_code))]
// `!(x > 0.0)` is how this crate says "not positive, or NaN": every such test must also
// refuse NaN, which `x <= 0.0` would let through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

#[cfg(feature = "reference")]
pub mod accuracy;
#[cfg(feature = "reference")]
pub mod dual;
pub mod earth;
pub mod error;
#[cfg(feature = "earth-fixed")]
mod fixed_int;
pub mod line_period;
pub mod model;
pub mod mtf;
pub mod orbit;
pub mod real;
#[cfg(feature = "reference")]
pub mod sample;
#[cfg(feature = "sphere")]
pub mod sphere;
mod sqrt;
pub mod trig;
pub mod trig_f64;
pub mod vector;
pub mod wide;

#[cfg(feature = "reference")]
pub use earth::EarthReference;
pub use earth::{Earth, EarthCamera, EarthGeometry, Ellipsoid, General};
pub use error::{ModelError, Param};
pub use line_period::{line_period_s, line_period_ticks, nearest_ticks, Ticks};
pub use model::{domain, Backend, Camera, ImageMotion, Model, EARTH_RATE_RAD_S, GM_M3_S2};
pub use mtf::{mtf_drift, mtf_mismatch, sinc, smear_mtf, StageRule};
pub use orbit::StateVector;
pub use real::{Real, Scalar};
pub use sqrt::{sqrt_f32, sqrt_f64};

/// The real-Earth general form in f32, the form the firmware flies.
pub const GENERAL_F32: General<f32> = General::new();
/// The real-Earth general form in f64.
pub const GENERAL_F64: General<f64> = General::new();
/// The real-Earth general form in fixed point (integer-only per pixel).
#[cfg(feature = "earth-fixed")]
pub const EARTH_FIXED: earth::fixed::EarthFixed = earth::fixed::EarthFixed;

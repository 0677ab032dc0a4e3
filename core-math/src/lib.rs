//! Image-motion velocity of a rolling TDI push-broom camera, and what follows from it:
//! MTF loss from a velocity mismatch, the line period, the TDI stage limit.
//!
//! After LI Guang-ze, KONG De-zhu, LIU Jin-guo, "Computation of scroll image motion
//! velocity of wide coverage optical remote camera", Chinese Optics 6(5), 2013, with its
//! Eqs. 14-15 re-derived and corrected (see `docs/derivation.md`).
//!
//! Backends, each one implementation of [`Backend`]:
//! - [`Reference`]: the paper's transform chain (Eqs. 1-13) on dual numbers, f64;
//! - [`ClosedForm<f64>`] and [`ClosedForm<f32>`]: the stable closed form;
//! - [`Fixed`]: the same closed form in fixed point (I24F40 interface, integer-only
//!   `update` and `motion`) for controllers without an FPU;
//! - [`ClosedForm<MicroF32>`] (feature `micromath`, the report only): the f32 closed
//!   form with micromath's sine and cosine;
//! - [`NaiveF32`] (feature `naive`, host tools and the bench only): the paper's route in
//!   f32 with libm trig per pixel, the baseline the others are measured against.
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
pub mod closed_form;
#[cfg(feature = "reference")]
pub mod dual;
pub mod earth;
pub mod error;
#[cfg(feature = "fixed-point")]
pub mod fixed_point;
pub mod line_period;
#[cfg(feature = "micromath")]
pub mod micromath_f32;
pub mod model;
pub mod mtf;
#[cfg(feature = "naive")]
pub mod naive;
pub mod orbit;
pub mod real;
#[cfg(feature = "reference")]
pub mod reference;
#[cfg(feature = "reference")]
pub mod sample;
mod sqrt;
pub mod trig;
pub mod vector;

pub use closed_form::ClosedForm;
#[cfg(feature = "reference")]
pub use earth::EarthReference;
pub use earth::{Earth, EarthCamera, EarthGeometry, Ellipsoid, General};
pub use error::{ModelError, Param};
#[cfg(feature = "fixed-point")]
pub use fixed_point::{Fixed, FixedReal, FIXED};
pub use line_period::{line_period_s, line_period_ticks, nearest_ticks, Ticks};
#[cfg(feature = "micromath")]
pub use micromath_f32::MicroF32;
pub use model::{
    domain, orbital_rate_rad_s, Backend, Camera, Geometry, ImageMotion, Model, Sphere,
    EARTH_RATE_RAD_S, GM_M3_S2,
};
pub use mtf::{mtf_drift, mtf_mismatch, sinc, StageRule};
#[cfg(feature = "naive")]
pub use naive::NaiveF32;
pub use orbit::{OrbitState, StateVector};
pub use real::{Real, Scalar};
#[cfg(feature = "reference")]
pub use reference::Reference;

/// The real-Earth general form in f64.
pub const GENERAL_F64: General<f64> = General::new();
/// The real-Earth general form in f32, the form the firmware flies.
pub const GENERAL_F32: General<f32> = General::new();
/// The closed form in f64.
pub const CLOSED_F64: ClosedForm<f64> = ClosedForm::new();
/// The closed form in f32, the shipped path.
pub const CLOSED_F32: ClosedForm<f32> = ClosedForm::new();
/// The closed form in f32 with micromath's sine and cosine (a report variant).
#[cfg(feature = "micromath")]
pub const CLOSED_MICROMATH: ClosedForm<MicroF32> = ClosedForm::new();

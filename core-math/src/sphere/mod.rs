//! The paper's round-Earth model (feature `sphere`): a circular orbit over a sphere, a
//! camera that only rolls, the ground at sea level. The firmware does not fly it: it
//! is kept as the paper's baseline, reproduced and corrected (`docs/derivation.md`,
//! `docs/paper-reproduction.md`), and as what the real-Earth model is measured against
//! (`docs/earth-model.md`).
//!
//! Backends, each one implementation of [`crate::Backend`]`<`[`Sphere`]`>`:
//! - [`Reference`] (feature `reference`): the paper's transform chain (Eqs. 1-13) on
//!   dual numbers, f64;
//! - [`ClosedForm<f64>`] and [`ClosedForm<f32>`]: the stable closed form (Eqs. 14-15,
//!   re-derived);
//! - [`Fixed`] (feature `fixed-point`): the same closed form in fixed point (I24F40
//!   interface, integer-only `update` and `motion`) for controllers without an FPU;
//! - [`ClosedForm<MicroF32>`] (feature `micromath`, the report only): the f32 closed
//!   form with micromath's sine and cosine;
//! - [`NaiveF32`] (feature `naive`, host tools and the bench only): the paper's route in
//!   f32 with libm trig per pixel, the baseline the others are measured against.

#[cfg(feature = "reference")]
pub mod accuracy;
pub mod closed_form;
#[cfg(feature = "fixed-point")]
pub mod fixed_point;
pub mod geometry;
pub mod line_period;
#[cfg(feature = "micromath")]
pub mod micromath_f32;
#[cfg(feature = "naive")]
pub mod naive;
pub mod orbit;
#[cfg(feature = "reference")]
pub mod reference;

pub use closed_form::ClosedForm;
#[cfg(feature = "fixed-point")]
pub use fixed_point::{Fixed, FixedReal, FIXED};
pub use geometry::{orbital_rate_rad_s, Geometry, Sphere};
pub use line_period::speed_line_period_s;
#[cfg(feature = "micromath")]
pub use micromath_f32::MicroF32;
#[cfg(feature = "naive")]
pub use naive::NaiveF32;
pub use orbit::OrbitState;
#[cfg(feature = "reference")]
pub use reference::Reference;

/// The closed form in f64.
pub const CLOSED_F64: ClosedForm<f64> = ClosedForm::new();
/// The closed form in f32.
pub const CLOSED_F32: ClosedForm<f32> = ClosedForm::new();
/// The closed form in f32 with micromath's sine and cosine (a report variant).
#[cfg(feature = "micromath")]
pub const CLOSED_MICROMATH: ClosedForm<MicroF32> = ClosedForm::new();

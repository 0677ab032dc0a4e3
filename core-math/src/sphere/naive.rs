//! The baseline a user would write first: the paper's route (Eqs. 1-6 and the corrected
//! Eq. 14, v2 from `docs/derivation.md` section 3) transcribed literally in f32 with
//! libm's f32 functions, every transcendental evaluated per pixel.
//!
//! It exists to be measured, not flown: `cargo xtask bench` shows its cost on the
//! Cortex-M4 (libm's `sinf`/`cosf` work in soft f64 there) and
//! `core-math/tests/naive.rs` its error against [`crate::sphere::Reference`] (about 1e-5 away from
//! the limb, growing like u/q^2 toward it: the asin of Eq. 1 and the difference
//! `pi - phi - alpha - beta` of Eq. 3 both lose digits there). The flight firmware builds
//! core-math without the `naive` feature and never links it.
//!
//! Per pixel: `atanf` (Eq. 2), `sinf` + `asinf` (Eq. 1), `sinf`/`cosf` of theta (Eqs. 4-6),
//! and the `sinf`/`cosf` of roll, inclination and argument of latitude that a literal
//! transcription evaluates inside the formula. The one liberty taken: a line of sight is
//! refused when |phi + alpha| >= pi/2 (above the horizontal, or not reduced to
//! (-pi/2, pi/2)) rather than by a further `cosf`, and when |(R+H) sin(eta)/R| >= 1.

use core::f32::consts::{FRAC_PI_2, PI};

use crate::error::ModelError;
use crate::model::{Backend, Camera, ImageMotion};
use crate::sphere::{Geometry, Sphere};

/// The naive f32 backend (paper's route, libm f32 trig, all of it per pixel).
#[derive(Clone, Copy, Debug, Default)]
pub struct NaiveF32;

/// A field point as the naive code keeps it: N A / f and f, rounded to f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NaivePixel {
    /// tan(alpha) = N A / f (Eq. 2).
    pub tan_field: f32,
    pub focal_m: f32,
}

impl Backend<Sphere> for NaiveF32 {
    type Real = f32;
    type Pixel = NaivePixel;
    type Update = Geometry<f32>;

    fn pixel(&self, camera: &Camera, n_px: f64) -> Result<NaivePixel, ModelError> {
        let t = camera.tan_field(n_px)?;
        Ok(NaivePixel {
            tan_field: t as f32,
            focal_m: camera.focal_m as f32,
        })
    }

    /// Only checks and stores the geometry: the naive route does everything per pixel.
    fn update(&self, g: &Geometry<f32>) -> Result<Geometry<f32>, ModelError> {
        g.validate()?;
        Ok(*g)
    }

    fn motion(&self, g: &Geometry<f32>, p: &NaivePixel) -> Result<ImageMotion<f32>, ModelError> {
        let (r, h, f) = (g.earth_radius_m, g.altitude_m, p.focal_m);
        let phi = g.roll_rad;
        // Eq. 2.
        let alpha = libm::atanf(p.tan_field);
        let eta = alpha + phi;
        if !(libm::fabsf(eta) < FRAC_PI_2) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        // Eq. 1: law of sines, beta obtuse (the near intersection).
        let sin_beta = (r + h) * libm::sinf(eta) / r;
        if !(libm::fabsf(sin_beta) < 1.0) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let beta = PI - libm::asinf(sin_beta);
        // Eq. 3, Eqs. 4-6.
        let theta = PI - phi - alpha - beta;
        let g2 = r * libm::sinf(theta);
        let g3 = r * (libm::cosf(theta) - 1.0);
        // Corrected Eq. 14 and v2 (docs/derivation.md, section 3).
        let (i0, g0, w, om) = (
            g.inclination_rad,
            g.arg_latitude_rad,
            g.earth_rate_rad_s,
            g.orbit_rate_rad_s,
        );
        let d = libm::sinf(phi) * g2 - libm::cosf(phi) * g3 + libm::cosf(phi) * h;
        if !(d > 0.0) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let v1 = f
            * ((w * libm::cosf(i0) - om) * (g3 + r) - w * libm::sinf(i0) * libm::sinf(g0) * g2)
            / d;
        let a = w * libm::sinf(i0) * libm::cosf(g0);
        let v2 = f * a * ((g3 + r) * (g3 - h) + g2 * g2) / (d * d);
        Ok(ImageMotion {
            v1_mps: v1,
            v2_mps: v2,
        })
    }
}

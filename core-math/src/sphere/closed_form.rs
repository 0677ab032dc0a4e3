//! The closed-form image-motion velocity (the paper's Eqs. 14-15, re-derived and
//! corrected; see `docs/derivation.md`), written once for any [`Real`].
//!
//! Lengths are scaled by the Earth radius R, so every intermediate is of order 1:
//! k = (R + H)/R, q = cos e (e the incidence angle at the ground point), and the
//! slant range enters only through den = k cos(eta) + q = (k^2 - 1) R / rho, the stable
//! root of the ray/sphere quadratic. No asin, no cos(theta) - 1, no difference of
//! slant-range terms, and per pixel no division and no transcendental call:
//!
//! ```text
//! sin(eta), cos(eta) = angle sums of roll and field angle      (eta = phi + alpha)
//! q^2       = (1 - k sin eta)(1 + k sin eta)                   (> 0 iff the ray meets the sphere)
//! den       = k cos eta + q
//! cos theta = q cos eta + k sin^2 eta
//! v1 = f/cos(alpha)   * [ (b/c0) cos(theta) den - c sin(eta) ]
//! v2 = -f/cos^2(alpha) * (a/c0) q den
//! ```
//! with c0 = k^2 - 1 = h(2 + h), h = H/R, and the rates of the relative rotation
//! (a, b, c) = (w sin i0 cos g0, w cos i0 - Omega, w sin i0 sin g0).

use core::marker::PhantomData;

use crate::error::ModelError;
use crate::model::{Backend, Camera, ImageMotion};
use crate::real::Real;
use crate::sphere::{Geometry, Sphere};

/// The closed-form backend in scalar `T` (`f64` or `f32`).
#[derive(Clone, Copy, Debug, Default)]
pub struct ClosedForm<T>(PhantomData<T>);

impl<T> ClosedForm<T> {
    pub const fn new() -> Self {
        ClosedForm(PhantomData)
    }
}

/// Constants of one field point, known at boot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelConst<T> {
    /// Field angle alpha as an unevaluated sum hi + lo (rad), for the limb distance.
    pub field_hi_rad: T,
    pub field_lo_rad: T,
    pub sin_field: T,
    pub cos_field: T,
    /// f / cos(alpha) (m).
    pub w1_m: T,
    /// f / cos^2(alpha) (m).
    pub w2_m: T,
}

/// Constants of one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateConst<T> {
    /// L - phi and L + phi as unevaluated sums hi + lo (rad), L = asin(R/(R+H)) the
    /// nadir angle of the limb: the angular distance to the left and right limbs of a
    /// ray with field angle alpha is (L - phi) - alpha and (L + phi) + alpha.
    pub limb_left_hi_rad: T,
    pub limb_left_lo_rad: T,
    pub limb_right_hi_rad: T,
    pub limb_right_lo_rad: T,
    /// sqrt(k^2 - 1) = k cos L.
    pub sqrt_c0: T,
    /// 1 - k|sin eta| of a ray [`LIMB_BRANCH_RAD`] from the limb at this altitude: a ray
    /// with 1 - k|sin eta| at or below it takes the near-limb form. The test costs one
    /// comparison where a test on the limb distance itself would first have to form it.
    pub near_limb_below: T,
    pub sin_roll: T,
    pub cos_roll: T,
    /// (R + H) / R.
    pub k: T,
    /// w sin(i0) cos(g0) / (k^2 - 1) (rad/s).
    pub a_rad_s: T,
    /// (w cos(i0) - Omega) / (k^2 - 1) (rad/s).
    pub b_rad_s: T,
    /// w sin(i0) sin(g0) (rad/s).
    pub c_rad_s: T,
}

/// Below this limb distance (rad) the near-limb form is used, with x = delta/2 <= 0.15
/// as [`Real::small_sin_cos`] requires. Above it, q^2 >= (about) 0.2 for every altitude of the domain and the direct form's
/// error, ~3u/q, stays under 5e-7 (see docs/accuracy.md).
pub const LIMB_BRANCH_RAD: f64 = 0.3;

/// x reduced to (-pi, pi].
fn wrap_pi(x: f64) -> f64 {
    let tau = core::f64::consts::TAU;
    let r = x - tau * libm::round(x / tau);
    if r <= -core::f64::consts::PI {
        r + tau
    } else {
        r
    }
}

/// x as hi + lo in T, hi = round(x), lo = round(x - hi).
fn split<T: Real>(x: f64) -> (T, T) {
    let hi = T::from_f64(x);
    (hi, T::from_f64(x - hi.to_f64()))
}

impl<T: Real> Backend<Sphere> for ClosedForm<T> {
    type Real = T;
    type Pixel = PixelConst<T>;
    type Update = UpdateConst<T>;

    /// Boot-time work, done in f64 whatever `T` is, then rounded once: the constants
    /// are as exact as `T` can hold, at no per-update cost.
    fn pixel(&self, camera: &Camera, n_px: f64) -> Result<PixelConst<T>, ModelError> {
        let t = camera.tan_field(n_px)?;
        let sec2 = 1.0 + t * t;
        let sec = libm::sqrt(sec2);
        let (field_hi_rad, field_lo_rad) = split::<T>(libm::atan(t));
        Ok(PixelConst {
            field_hi_rad,
            field_lo_rad,
            sin_field: T::from_f64(t / sec),
            cos_field: T::from_f64(1.0 / sec),
            w1_m: T::from_f64(camera.focal_m * sec),
            w2_m: T::from_f64(camera.focal_m * sec2),
        })
    }

    fn update(&self, g: &Geometry<T>) -> Result<UpdateConst<T>, ModelError> {
        g.validate()?;
        let (sin_roll, cos_roll) = g.roll_rad.sin_cos();
        let (sin_i, cos_i) = g.inclination_rad.sin_cos();
        let (sin_g, cos_g) = g.arg_latitude_rad.sin_cos();
        let h = g.altitude_m / g.earth_radius_m;
        // k^2 - 1 without the cancellation of forming k^2 first.
        let c0 = h * (T::ONE + T::ONE + h);
        let w = g.earth_rate_rad_s;
        // The limb angle in f64 (once per update), so that L -/+ phi is known to far
        // better than T's precision: near the limb it is the small difference that
        // decides everything, and it must not inherit an absolute rounding of ~u.
        let h64 = g.altitude_m.to_f64() / g.earth_radius_m.to_f64();
        let limb = libm::asin(1.0 / (1.0 + h64));
        // Reduced to (-pi, pi]: sin and cos of the roll wrap, so must the limb distance
        // (an unreduced roll of 2 pi + x would put the limb 2 pi away).
        let phi = wrap_pi(g.roll_rad.to_f64());
        let (limb_left_hi_rad, limb_left_lo_rad) = split::<T>(limb - phi);
        let (limb_right_hi_rad, limb_right_lo_rad) = split::<T>(limb + phi);
        let sqrt_c0 = c0.sqrt();
        // 1 - k sin(L - d) = (1 - cos d) + sqrt(k^2 - 1) sin d, increasing in d on
        // [0, pi/2]: at or below this value a ray is within LIMB_BRANCH_RAD of the limb.
        let (sin_branch, cos_branch) = T::from_f64(LIMB_BRANCH_RAD).sin_cos();
        let near_limb_below = (T::ONE - cos_branch) + sqrt_c0 * sin_branch;
        Ok(UpdateConst {
            limb_left_hi_rad,
            limb_left_lo_rad,
            limb_right_hi_rad,
            limb_right_lo_rad,
            sqrt_c0,
            near_limb_below,
            sin_roll,
            cos_roll,
            k: T::ONE + h,
            a_rad_s: w * sin_i * cos_g / c0,
            b_rad_s: (w * cos_i - g.orbit_rate_rad_s) / c0,
            c_rad_s: w * sin_i * sin_g,
        })
    }

    #[inline]
    fn motion(&self, u: &UpdateConst<T>, p: &PixelConst<T>) -> Result<ImageMotion<T>, ModelError> {
        self.motion_terms::<true, true>(u, p)
    }
}

impl<T: Real> ClosedForm<T> {
    /// The closed form with terms a scene plan has proved it can do without:
    /// - `LIMB = false` skips the limb-distance form and uses 1 - k|sin eta| directly,
    ///   valid where every line of sight stays at least [`LIMB_BRANCH_RAD`] from the limb
    ///   (there both forms agree to T's precision; the sign test still refuses a ray that
    ///   misses the Earth);
    /// - `DRIFT = false` returns v2 = 0 without computing it, valid where
    ///   (v2/v1)^2 / 2, the relative change of |v_P|, is under the budget.
    ///
    /// `motion` is `motion_terms::<true, true>`.
    #[inline(always)]
    pub fn motion_terms<const LIMB: bool, const DRIFT: bool>(
        &self,
        u: &UpdateConst<T>,
        p: &PixelConst<T>,
    ) -> Result<ImageMotion<T>, ModelError> {
        let sin_eta = u.sin_roll * p.cos_field + u.cos_roll * p.sin_field;
        let cos_eta = u.cos_roll * p.cos_field - u.sin_roll * p.sin_field;
        // The near root of the ray/sphere quadratic lies in front of the camera only
        // when the ray points below the horizontal.
        if !(cos_eta > T::ZERO) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let ks = u.k * sin_eta;
        let direct = T::ONE - ks.abs();
        // 1 - k|sin eta| is small near the limb, where a rounding of k sin(eta) would
        // cost all its digits: there it comes from the limb distance instead.
        let one_minus = if LIMB && !(direct > u.near_limb_below) {
            // Angular distance delta = L - |eta| to the limb the ray looks toward. The
            // hi parts cancel exactly (Sterbenz) near the limb, so delta keeps T's
            // relative precision however small it is.
            let delta = if sin_eta >= T::ZERO {
                (u.limb_left_hi_rad - p.field_hi_rad) + (u.limb_left_lo_rad - p.field_lo_rad)
            } else {
                (u.limb_right_hi_rad + p.field_hi_rad) + (u.limb_right_lo_rad + p.field_lo_rad)
            };
            // Beyond the limb, or (rounding at the branch point) a hair above
            // LIMB_BRANCH_RAD, where the series is still far inside its range.
            if !(delta > T::ZERO) {
                return Err(ModelError::LineOfSightMissesEarth);
            }
            // 1 - k|sin eta| = 2 s (s + sqrt(k^2-1) c), s = sin(delta/2),
            // c = cos(delta/2): all terms positive, no cancellation.
            let (s, c) = T::small_sin_cos(T::from_f64(0.5) * delta);
            (s + s) * (s + u.sqrt_c0 * c)
        } else {
            direct
        };
        // One test for every path: no ground point, no square root of a negative.
        if !(one_minus > T::ZERO) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let q2 = one_minus * (T::ONE + T::ONE - one_minus);
        let q = q2.sqrt();
        let den = u.k * cos_eta + q;
        let cos_theta = q * cos_eta + ks * sin_eta;
        Ok(ImageMotion {
            v1_mps: p.w1_m * (u.b_rad_s * cos_theta * den - u.c_rad_s * sin_eta),
            v2_mps: if DRIFT {
                -(p.w2_m * u.a_rad_s * q * den)
            } else {
                T::ZERO
            },
        })
    }
}

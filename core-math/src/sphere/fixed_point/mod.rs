//! The closed form in fixed point, for controllers without an FPU (Cortex-M0+/M3):
//! `update` and `motion` use integer arithmetic only; `pixel` (boot) stays in f64.
//!
//! The formulas are those of [`crate::sphere::closed_form`]: q^2 = m (2 - m) with
//! m = 1 - k|sin eta| formed directly, or within 9.7e-4 rad of the limb from the limb
//! distance delta = (L -/+ phi) -/+ alpha carried in Q61 (the near-limb form). Formats,
//! range analysis and measured error: `docs/fixed-point.md`. In short (Qn = integer
//! times 2^-n):
//!
//! - interface (`Geometry<I24F40>`, `ImageMotion<I24F40>`): SI units, I24F40, |x| < 2^23;
//! - sines and cosines: I1F31 (a cosine of 1 saturates to 1 - 2^-31); h = H/R: I0F32
//!   (k = 1 + h is never stored); L -/+ phi and alpha: I3F61; sqrt(c0): I1F31;
//! - rates (per update) in units of 2^-10 rad/s (the orbital rate is 0.84-1.22 such
//!   units over the envelope): A = a/c0, B = b/c0, C = c as I7F25;
//! - optics (per pixel): f/cos(alpha), f/cos^2(alpha) as a shared binary exponent and
//!   I2F30 mantissas in [1/2, 1], so any focal length 0.01-1000 m keeps 30 bits;
//! - per pixel, intermediates in i64/u64 at Q62/Q60/Q54 from 32x32 -> 64 products,
//!   narrowed to i32/u32 at Q30/Q29/Q24, and one table-seeded square root.
//!
//! `PixelConst` and `UpdateConst` are meant to be built by [`Fixed::pixel`] and
//! [`Fixed::update`]: the range analysis holds for those values only.
//!
//! Outside the envelope ([`envelope`]) every entry point answers
//! [`ModelError::OutOfDomain`], never a wrapped value.

mod limb;
mod sin_cos;
mod sqrt;
mod turns;

use fixed::types::{I0F32, I1F31, I24F40, I2F30, I3F61, I7F25};

use crate::error::{ModelError, Param};
use crate::fixed_int::shr;
use crate::model::{Backend, Camera, ImageMotion};
use crate::real::Scalar;
use crate::sphere::{Geometry, Sphere};

pub use fixed;

/// The interface scalar of [`Fixed`]: SI units with 40 fraction bits, range +/-2^23
/// (8 388 km, enough for R + H in metres; 9.1e-13 resolution for rates in rad/s and
/// velocities in m/s).
pub type FixedReal = I24F40;

/// The envelope the range analysis covers (`docs/fixed-point.md`); everything outside
/// is refused with [`ModelError::OutOfDomain`]. Inclusive bounds.
pub mod envelope {
    use fixed::types::I24F40;

    /// Altitude (m): 200 to 2 000 km.
    pub const ALTITUDE_M: (I24F40, I24F40) = (I24F40::lit("200000"), I24F40::lit("2000000"));
    /// Earth radius (m): any Earth radius, equatorial to polar, with margin.
    pub const EARTH_RADIUS_M: (I24F40, I24F40) = (I24F40::lit("6300000"), I24F40::lit("6400000"));
    /// |roll| (rad): 45 deg (pi/4 = 0.785398...) and a hair, so that 45 deg rounded
    /// either way is accepted.
    pub const MAX_ROLL_RAD: I24F40 = I24F40::lit("0.7854");
    /// |inclination|, |argument of latitude| (rad): any angle, up to the crate-wide
    /// [`crate::domain::MAX_ANGLE_RAD`]; the reduction to turns is good to 2^-71 turn for all.
    pub const MAX_ANGLE_RAD: I24F40 = I24F40::lit("100000");
    /// |Earth rate| (rad/s): 1e-4 (the Earth: 7.29e-5).
    pub const MAX_EARTH_RATE_RAD_S: I24F40 = I24F40::lit("0.0001");
    /// |orbit rate| (rad/s): 2e-3 (circular orbits of the envelope: 8.2e-4 to 1.19e-3).
    pub const MAX_ORBIT_RATE_RAD_S: I24F40 = I24F40::lit("0.002");
    /// |field angle| (rad): 40 deg (0.698132) and a hair.
    pub const MAX_FIELD_RAD: f64 = 0.698_14;
    /// Focal length (m); the Camera's own domain caps it at 1 000 m.
    pub const MIN_FOCAL_M: f64 = 0.01;
}

/// The fixed-point backend (no FPU needed per update or per pixel).
#[derive(Clone, Copy, Debug, Default)]
pub struct Fixed;

/// The fixed-point backend (a value, like [`crate::sphere::CLOSED_F32`]).
pub const FIXED: Fixed = Fixed;

/// Constants of one field point, computed at boot in f64 and rounded once (build it
/// with [`Fixed::pixel`]).
///
/// The optics are stored as mantissas with a shared exponent e = 30 - (binary exponent
/// of f/cos^2(alpha)): w = (mantissa bits) 2^-e m = mantissa 2^(30 - e) m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelConst {
    /// The field angle alpha (rad), for the limb distance of the near-limb form.
    pub field_rad: I3F61,
    pub sin_field: I1F31,
    /// cos(alpha), saturated at 1 - 2^-31 (so that all four factors of the angle sum
    /// are i32 and each product one `smull`/`smlal`).
    pub cos_field: I1F31,
    /// f/cos(alpha) = w1_mant 2^(30 - e) m, mantissa in [0.38, 1].
    pub w1_mant: I2F30,
    /// f/cos^2(alpha) = w2_mant 2^(30 - e) m, mantissa in [1/2, 1].
    pub w2_mant: I2F30,
    /// shift = e - 6: the right shift that turns (mantissa bits) x (I8F24 bracket
    /// bits) into I24F40 m/s. In [13, 30] over the envelope (focal 0.01-1000 m).
    pub shift: u32,
}

/// Constants of one instant, integer only (build it with [`Fixed::update`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateConst {
    pub sin_roll: I1F31,
    /// cos(roll), saturated at 1 - 2^-31.
    pub cos_roll: I1F31,
    /// h = H/R (k = 1 + h), in [0.031, 0.318].
    pub h: I0F32,
    /// L - phi and L + phi (rad), L = asin(1/k) the nadir angle of the limb: the
    /// distance to the limb of a ray of field angle alpha is (L - phi) - alpha or
    /// (L + phi) + alpha. In [0.07, 2.11].
    pub limb_left_rad: I3F61,
    pub limb_right_rad: I3F61,
    /// sqrt(c0) = k cos(L), in [0.25, 0.86].
    pub sqrt_c0: I1F31,
    /// -a/c0 (the sign of v2 folded in), b/c0, c, in units of 2^-10 rad/s.
    pub neg_a: I7F25,
    pub b: I7F25,
    pub c: I7F25,
}

/// A `Geometry<f64>` (SI units) rounded to the fixed backend's input (to nearest).
/// Non-finite fields are [`ModelError::NonFinite`], values beyond I24F40's range
/// [`ModelError::OutOfDomain`]; the envelope itself is checked by [`Fixed::update`].
/// Host and boot code only (it works in f64).
pub fn geometry_from_f64(g: &Geometry<f64>) -> Result<Geometry<I24F40>, ModelError> {
    let conv = |x: f64, p: Param| -> Result<I24F40, ModelError> {
        if !x.is_finite() {
            return Err(ModelError::NonFinite(p));
        }
        I24F40::checked_from_num(x).ok_or(ModelError::OutOfDomain(p))
    };
    Ok(Geometry {
        roll_rad: conv(g.roll_rad, Param::Roll)?,
        inclination_rad: conv(g.inclination_rad, Param::Inclination)?,
        arg_latitude_rad: conv(g.arg_latitude_rad, Param::ArgLatitude)?,
        altitude_m: conv(g.altitude_m, Param::Altitude)?,
        earth_radius_m: conv(g.earth_radius_m, Param::EarthRadius)?,
        earth_rate_rad_s: conv(g.earth_rate_rad_s, Param::EarthRate)?,
        orbit_rate_rad_s: conv(g.orbit_rate_rad_s, Param::OrbitRate)?,
    })
}

/// The fixed backend's output widened to f64 (for tools and tests).
pub fn motion_to_f64(m: &ImageMotion<I24F40>) -> ImageMotion<f64> {
    ImageMotion {
        v1_mps: m.v1_mps.to_f64(),
        v2_mps: m.v2_mps.to_f64(),
    }
}

/// Checks a geometry against [`envelope`], integer compares only.
pub fn validate(g: &Geometry<I24F40>) -> Result<(), ModelError> {
    let within = |x: I24F40, max: I24F40| x <= max && -max <= x;
    if !within(g.roll_rad, envelope::MAX_ROLL_RAD) {
        return Err(ModelError::OutOfDomain(Param::Roll));
    }
    if !within(g.inclination_rad, envelope::MAX_ANGLE_RAD) {
        return Err(ModelError::OutOfDomain(Param::Inclination));
    }
    if !within(g.arg_latitude_rad, envelope::MAX_ANGLE_RAD) {
        return Err(ModelError::OutOfDomain(Param::ArgLatitude));
    }
    if g.earth_radius_m <= 0 {
        return Err(ModelError::NonPositiveEarthRadius);
    }
    let (r_min, r_max) = envelope::EARTH_RADIUS_M;
    if !(r_min <= g.earth_radius_m && g.earth_radius_m <= r_max) {
        return Err(ModelError::OutOfDomain(Param::EarthRadius));
    }
    if g.altitude_m <= 0 {
        return Err(ModelError::NonPositiveAltitude);
    }
    let (h_min, h_max) = envelope::ALTITUDE_M;
    if !(h_min <= g.altitude_m && g.altitude_m <= h_max) {
        return Err(ModelError::OutOfDomain(Param::Altitude));
    }
    if !within(g.earth_rate_rad_s, envelope::MAX_EARTH_RATE_RAD_S) {
        return Err(ModelError::OutOfDomain(Param::EarthRate));
    }
    if !within(g.orbit_rate_rad_s, envelope::MAX_ORBIT_RATE_RAD_S) {
        return Err(ModelError::OutOfDomain(Param::OrbitRate));
    }
    Ok(())
}

/// (sin, cos) of an I24F40 angle in rad, Q62.
fn sin_cos(x: I24F40) -> (i64, i64) {
    sin_cos::sin_cos_turns(turns::rad_to_turns(x.to_bits()))
}

/// Q62 -> Q31, rounded.
#[inline]
fn q62_to_q31(x: i64) -> i64 {
    (x + (1 << 30)) >> 31
}

/// n / d rounded to nearest (d > 0).
fn div_round(n: i128, d: i128) -> i128 {
    if n >= 0 {
        (n + d / 2) / d
    } else {
        -((-n + d / 2) / d)
    }
}

/// I7F25 from bits, checked against the range analysis in debug builds.
fn i7f25(bits: i128) -> I7F25 {
    debug_assert!(bits.unsigned_abs() < 1 << 31);
    I7F25::from_bits(bits as i32)
}

impl Backend<Sphere> for Fixed {
    type Real = I24F40;
    type Pixel = PixelConst;
    type Update = UpdateConst;

    /// Boot-time work in f64 (like the float backends), rounded once to the formats.
    fn pixel(&self, camera: &Camera, n_px: f64) -> Result<PixelConst, ModelError> {
        let t = camera.tan_field(n_px)?;
        if !(camera.focal_m >= envelope::MIN_FOCAL_M) {
            return Err(ModelError::OutOfDomain(Param::FocalLength));
        }
        if !(libm::fabs(libm::atan(t)) <= envelope::MAX_FIELD_RAD) {
            return Err(ModelError::OutOfDomain(Param::PixelOffset));
        }
        let sec2 = 1.0 + t * t;
        let sec = libm::sqrt(sec2);
        let w1 = camera.focal_m * sec;
        let w2 = camera.focal_m * sec2;
        // w2 = m 2^ex, m in [1/2, 1): w2 2^e in [2^29, 2^30) with e = 30 - ex.
        let (_, ex) = libm::frexp(w2);
        let e = 30 - ex;
        let mant = |w: f64| I2F30::from_bits(libm::round(libm::ldexp(w, e)) as i32);
        Ok(PixelConst {
            field_rad: I3F61::from_num(libm::atan(t)),
            sin_field: I1F31::from_num(t / sec),
            cos_field: I1F31::saturating_from_num(1.0 / sec),
            w1_mant: mant(w1),
            w2_mant: mant(w2),
            shift: (e - 6) as u32,
        })
    }

    /// Integer only: three sin/cos by binary angle and Taylor series in Q62; h = H/R,
    /// the limb angle L = pi/3 - atan(y) (one division for y) and the rates' divisions
    /// by c0 in i128 (the only divisions of the backend); sqrt(c0) by u128 `isqrt`.
    fn update(&self, g: &Geometry<I24F40>) -> Result<UpdateConst, ModelError> {
        validate(g)?;
        let (sr, cr) = sin_cos(g.roll_rad);
        let (si, ci) = sin_cos(g.inclination_rad);
        let (sg, cg) = sin_cos(g.arg_latitude_rad);
        // h in Q62: H < 2^61 (I24F40 bits of 2e6 m), shifted < 2^123.
        let h = ((g.altitude_m.to_bits() as i128) << 62) / g.earth_radius_m.to_bits() as i128;
        // c0 = h (2 + h), Q62, in [0.0634, 0.736].
        let c0 = (h * ((2 << 62) + h)) >> 62;
        let w = g.earth_rate_rad_s.to_bits() as i128; // Q40, |w| < 2^26.8
        let om = g.orbit_rate_rad_s.to_bits() as i128; // Q40, |om| < 2^31.1
        let w_si = (w * si as i128) >> 30; // Q72, < 2^58.8
        let a = (w_si * cg as i128) >> 62; // Q72
        let c = (w_si * sg as i128) >> 62; // Q72
        let b = ((w * ci as i128) >> 30) - (om << 32); // Q72, < 2^63.2

        // The limb: L and sqrt(c0) in Q62, L -/+ phi in Q61 (phi is exact: Q40 << 21).
        let (limb, sqrt_c0) = limb::limb_angle(c0);
        let phi = (g.roll_rad.to_bits() as i128) << 21;
        let limb = limb >> 1;
        // Rates in Q35 rad/s = Q25 of 2^-10 rad/s.
        let a = div_round(a << 25, c0);
        let b = div_round(b << 25, c0);
        let c = (c + (1 << 36)) >> 37;
        Ok(UpdateConst {
            sin_roll: I1F31::from_bits(q62_to_q31(sr) as i32),
            cos_roll: I1F31::from_bits(q62_to_q31(cr).min(i32::MAX as i64) as i32),
            h: I0F32::from_bits(((h + (1 << 29)) >> 30) as i32),
            limb_left_rad: I3F61::from_bits((limb - phi) as i64),
            limb_right_rad: I3F61::from_bits((limb + phi) as i64),
            sqrt_c0: I1F31::from_bits(((sqrt_c0 + (1 << 30)) >> 31) as i32),
            neg_a: i7f25(-a),
            b: i7f25(b),
            c: i7f25(c),
        })
    }

    /// Per pixel: 32x32 -> 64 multiplies (most of them reduced to their high word),
    /// one table-seeded square root, no division. Bounds of every intermediate:
    /// `docs/fixed-point.md`; the comments give each format (Qn) and bound.
    #[inline]
    fn motion(&self, u: &UpdateConst, p: &PixelConst) -> Result<ImageMotion<I24F40>, ModelError> {
        let sr = u.sin_roll.to_bits() as i64;
        let cr = u.cos_roll.to_bits() as i64;
        let sf = p.sin_field.to_bits() as i64;
        let cf = p.cos_field.to_bits() as i64;
        // sin(eta), cos(eta), Q62: each product < 0.71 * 2^62, sums < 1.35 * 2^62.
        let s62 = sr * cf + cr * sf;
        let c62 = cr * cf - sr * sf;
        let s30 = (s62 >> 32) as i32; // Q30, |.| < 2^30
        let c30 = (c62 >> 32) as i32; // Q30, <= 2^30
        if c30 <= 0 {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let c30 = c30 as u32;
        let h = u.h.to_bits(); // Q32, < 0.318 * 2^32

        // k sin(eta) = sin(eta) + h sin(eta), Q62, |.| < 1.32 * 2^62.
        let ks = s62 + h as i64 * s30 as i64;
        let ks_abs = ks.unsigned_abs();
        // m = 1 - k|sin eta|, Q62. Far from the limb (m >= 2^-12) directly; closer in
        // from the limb distance (near-limb form), where the absolute error of the
        // direct m (~1e-9) would cost 1e-9/q in |v|.
        let m62 = (1i64 << 62) - ks_abs as i64;
        let q = if m62 >= NEAR_LIMB_M62 {
            let m31 = to_u32(m62 as u64 >> 31); // Q31, in [2^19, 2^31]
            sqrt::q_from_m(m31, m31.wrapping_neg(), 0) // q = cos(e), Q30, <= 2^30
        } else {
            near_limb_q(u, p, s62 >= 0)?
        };
        let ks30 = (ks_abs >> 32) as u32; // k|sin eta|, Q30, < 1.32 * 2^30

        // cos(theta) = q cos(eta) + k sin^2(eta), Q60 (both terms >= 0, sum <= 2^60).
        let cos_theta = q as u64 * c30 as u64 + ks30 as u64 * s30.unsigned_abs() as u64;
        let ct30 = to_u32(cos_theta >> 30); // Q30, <= 2^30

        // den = k cos(eta) + q = cos(eta) + h cos(eta) + q, Q30, < 2.32 * 2^30 < 2^32.
        let den = c30 + ((h as u32 as u64 * c30 as u64) >> 32) as u32 + q;
        let t1 = to_i32(((ct30 as u64 * den as u64) >> 31) as i64); // cos(theta) den, Q29, < 2^30.3
        let qden = to_i32(((q as u64 * den as u64) >> 31) as i64); // q den, Q29, < 2^30.3

        // v1 bracket (b/c0) cos(theta) den - c sin(eta): Q54, |.| < 78.6 * 2^54.
        let br = u.b.to_bits() as i64 * t1 as i64 - u.c.to_bits() as i64 * (s30 >> 1) as i64;
        let br24 = to_i32(br >> 30); // I8F24 bits, |.| < 2^30.3
        let aq = u.neg_a.to_bits() as i64 * qden as i64; // -(a/c0) q den, Q54, < 3.8 * 2^54
        let aq24 = to_i32(aq >> 30);
        // Optics: Q30 mantissa (<= 2^30) x I8F24 bits (< 2^30.3), shifted right by
        // 13..30 into I24F40 m/s.
        let v1 = shr(p.w1_mant.to_bits() as i64 * br24 as i64, p.shift);
        let v2 = shr(p.w2_mant.to_bits() as i64 * aq24 as i64, p.shift);
        Ok(ImageMotion {
            v1_mps: I24F40::from_bits(v1),
            v2_mps: I24F40::from_bits(v2),
        })
    }
}

/// Narrowing casts of the range analysis, checked in debug builds (tests).
#[inline(always)]
fn to_i32(x: i64) -> i32 {
    debug_assert!(i32::try_from(x).is_ok(), "{x}");
    x as i32
}

#[inline(always)]
fn to_u32(x: u64) -> u32 {
    debug_assert!(u32::try_from(x).is_ok(), "{x}");
    x as u32
}

/// Below m = 2^-12 (limb distance < 9.7e-4 rad) `motion` uses the near-limb form.
const NEAR_LIMB_M62: i64 = 1 << 50;

/// q from the limb distance delta = (L -/+ phi) -/+ alpha (exact in Q61: the leading
/// parts cancel without error) for delta in (0, 9.7e-4]:
/// m = 1 - k|sin eta| = (1 - cos delta) + sqrt(c0) sin delta
///   = delta (sqrt(c0) + delta/2) - sqrt(c0) delta^3/6 + O(delta^4/24),
/// evaluated without the cubic term (at most 1.3e-10 in m, which moves |v| by at most
/// 1.4e-8 at delta = 9.7e-4 and by less closer in, as delta^2.5), with m kept in Q39
/// (absolute 2^-40 instead of the direct form's ~1e-9), then q = sqrt(m (2 - m)).
/// `LineOfSightMissesEarth` for delta <= 0 (at or beyond the limb) or m < 2^-39.
#[inline(always)]
fn near_limb_q(u: &UpdateConst, p: &PixelConst, toward_left: bool) -> Result<u32, ModelError> {
    let alpha = p.field_rad.to_bits();
    let delta = if toward_left {
        u.limb_left_rad.to_bits() - alpha
    } else {
        u.limb_right_rad.to_bits() + alpha
    }; // Q61
    if delta <= 0 {
        return Err(ModelError::LineOfSightMissesEarth);
    }
    // delta < 9.8e-4 < 2^-10 whenever m < 2^-12 (m >= sqrt(c0) delta, sqrt(c0) > 0.2519),
    // four times below the 2^-8 that Q40 in a u32 can hold.
    debug_assert!(delta < 1 << 53);
    let d40 = to_u32((delta >> 21) as u64); // Q40, < 2^30.1
    let f = u.sqrt_c0.to_bits() as u32 + (d40 >> 10); // sqrt(c0) + delta/2, Q31, < 0.87 * 2^31
    let m39 = ((d40 as u64 * f as u64) >> 32) as u32; // m, Q39, < 2^27
    if m39 == 0 {
        return Err(ModelError::LineOfSightMissesEarth);
    }
    // 2 - m in Q31 as 2^32 - 1 - m/2^8: off by 2^-31 of 2, a relative 2^-32.
    Ok(sqrt::q_from_m(m39, !(m39 >> 8), 4))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limb_angle_against_libm() {
        let mut worst = 0f64;
        for i in 0..=10_000 {
            let h = 0.03 + 0.3 * i as f64 / 10_000.0;
            let hq = (h * 2f64.powi(62)) as i128;
            let c0 = (hq * ((2 << 62) + hq)) >> 62;
            let (l, x) = limb::limb_angle(c0);
            let k = 1.0 + hq as f64 / 2f64.powi(62);
            let exact = libm::asin(1.0 / k);
            worst = worst.max((l as f64 / 2f64.powi(62) - exact).abs());
            let c0f = c0 as f64 / 2f64.powi(62);
            assert!((x as f64 / 2f64.powi(62) - libm::sqrt(c0f)).abs() < 1e-15);
        }
        assert!(worst < 3e-14, "{worst}");
    }

    #[test]
    fn sin_cos_against_libm() {
        let mut worst = 0f64;
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        for _ in 0..1_000_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let a = I24F40::from_bits((x as i64) >> 6); // |a| < 2^17 rad
            let (s, c) = sin_cos(a);
            let af = a.to_num::<f64>();
            let (se, ce) = libm::sincos(af);
            let q = 2f64.powi(62);
            // The reference's own argument error at 1e5 rad is ~1e-11.
            let tol_arg = af.abs() * 2e-16;
            worst = worst
                .max(((s as f64 / q - se).abs() - tol_arg).max(0.0))
                .max(((c as f64 / q - ce).abs() - tol_arg).max(0.0));
        }
        assert!(worst < 2e-11, "{worst}");
    }
}

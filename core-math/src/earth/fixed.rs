//! The real-Earth general form in fixed point, for controllers without an FPU
//! (Cortex-M3): [`EarthFixed`], one more [`Backend`]`<`[`Earth`]`>`.
//!
//! - `pixel` (boot, scene upload): f64, rounded once to the formats below.
//! - `update` (per NAV state): the general form's per-update quantities by
//!   [`General<f64>`] (soft f64 on an M3: one update is a few trigonometric calls and
//!   divisions, against thousands of pixels), normalised by |r| and rounded to integers.
//! - `motion` (per pixel): integers only, 32x32 -> 64 products, one 64-bit integer
//!   square root, no division, no float.
//!
//! With u' = u / f = (t1, t2, -1) (t = p / f) and every length divided by |r|, the near
//! root of the ray/ellipsoid quadratic is 1/sigma = (sqrt(beta^2 - alpha C) - beta) / C
//! (beta = rho.u', alpha = |u'|^2 + (kappa^2 - 1)(n.u')^2, C = |K r|^2 / |r|^2 - A^2 /
//! |r|^2), and the image motion is f times
//!
//! ```text
//! v1/f = W2 (1 + t1^2) + W3 t2 - W1 t1 t2 - (V1 + t1 V3) / sigma
//! v2/f = -W1 (1 + t2^2) - W3 t1 + W2 t1 t2 - (V2 + t2 V3) / sigma
//! ```
//!
//! (W the camera's angular velocity relative to the Earth, V = V_B / |r|, both in rad/s;
//! [`crate::earth::general`] for the derivation). Formats, range analysis and the error
//! bound: `docs/fixed-point.md`, "The real-Earth backend". Qn is an integer times 2^-n.
//!
//! Every contract error of the general form is kept (its own checks run per update);
//! what the formats cannot hold is refused as [`ModelError::OutOfDomain`] ([`envelope`]).

use ::fixed::types::I24F40;

use crate::earth::{Attitude, Earth, EarthCamera, EarthGeometry, General, InertialGeometry};
use crate::error::{ModelError, Param};
use crate::fixed_int::{shr, RSQRT_SEED};
use crate::model::{Backend, ImageMotion};
use crate::real::Scalar;

/// The envelope the range analysis covers (`docs/fixed-point.md`): everything outside is
/// refused with [`ModelError::OutOfDomain`], never evaluated into a wrapped value.
pub mod envelope {
    /// Focal length (m).
    pub const FOCAL_M: (f64, f64) = (0.01, 1000.0);
    /// |p1| / f and |p2| / f: field angles up to 45 deg along either axis.
    pub const MAX_TAN_FIELD: f64 = 1.0;
    /// C / |r|^2 = |K r|^2 / |r|^2 - A^2 / |r|^2: about 2 H / |r|; 0.05 is about 165 km
    /// above the ground, 0.5 about 2 640 km.
    pub const C_OVER_R2: (f64, f64) = (0.05, 0.5);
    /// kappa^2 - 1 (WGS 84: 6.7e-3; 0.025 is a flattening of about 0.0124).
    pub const MAX_STRETCH2_MINUS_1: f64 = 0.025;
    /// |roll'|, |pitch'|, |yaw'| (rad/s): 0.04 = 2.3 deg/s.
    pub const MAX_ATTITUDE_RATE_RAD_S: f64 = 0.04;
    /// Each component of W (rad/s), the camera's angular velocity relative to the Earth.
    pub const MAX_W_RAD_S: f64 = 0.125;
    /// Each component of V_B / |r| (rad/s): below 2^-9, about 12.7 km/s at 6 500 km
    /// (2^-9 itself is refused: the format, Q40 in 32 bits, stops one unit short).
    pub const MAX_V_OVER_R_RAD_S: f64 = 1.0 / 512.0;
    /// Each component of a unit vector (n_B): 1 and the rounding of a rotation's axes
    /// (Part II accepts axes within 1e-5 of orthonormal).
    pub const MAX_UNIT: f64 = 1.001;
    /// Each component of sqrt(kappa^2 - 1) n_B: sqrt([`MAX_STRETCH2_MINUS_1`])
    /// [`MAX_UNIT`] = 0.15827, rounded up.
    pub const MAX_M: f64 = 0.1583;
}

/// The envelope's bounds in each field's format (`round_update` refuses the same).
mod limit {
    use super::envelope;
    pub const C_LO: i64 = (envelope::C_OVER_R2.0 * 4_294_967_296.0) as i64;
    pub const C_HI: i64 = (envelope::C_OVER_R2.1 * 4_294_967_296.0) as i64;
    pub const K2M1: i64 = (envelope::MAX_STRETCH2_MINUS_1 * (1u64 << 36) as f64) as i64;
    pub const M: i64 = (envelope::MAX_M * (1u64 << 33) as f64) as i64;
    pub const RHO: i64 =
        ((envelope::MAX_UNIT + envelope::MAX_STRETCH2_MINUS_1) * (1u64 << 30) as f64) as i64;
    pub const N: i64 = (envelope::MAX_UNIT * (1u64 << 30) as f64) as i64;
    pub const W: i64 = (envelope::MAX_W_RAD_S * (1u64 << 33) as f64) as i64;
    /// Below 2^-9 in Q40: one unit short of 2^31.
    pub const V: i64 = (1 << 31) - 1;
}

/// The fixed-point real-Earth backend.
#[derive(Clone, Copy, Debug, Default)]
pub struct EarthFixed;

/// Constants of one pixel (build with [`Backend::pixel`]; the range analysis holds for
/// those values only, hence the private fields).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthFixedPixel {
    /// t1 = p1/f, t2 = p2/f, t1^2, t1 t2, t2^2, Q30, each within [-1, 1].
    t1: i32,
    t2: i32,
    t11: i32,
    t12: i32,
    t22: i32,
    /// |u'|^2 = 1 + t1^2 + t2^2, Q30, within [1, 3].
    uu: u32,
    /// f = f_mant 2^-e with f_mant in [2^31, 2^32).
    f_mant: u32,
    /// e - 9: the right shift from (v/f in Q63) x f_mant / 2^32 to I24F40 m/s; 13..29.
    shift: u32,
}

/// Constants of one instant (build with [`Backend::update`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthFixedUpdate {
    /// sqrt(kappa^2 - 1) n_B (n_B the spin axis in B), Q33, |.| <= 0.159: the stretch
    /// term of alpha is (m.u')^2.
    m: [i32; 3],
    /// rho_B / |r|, Q30, |.| <= 1.026.
    rho: [i32; 3],
    /// C / |r|^2, Q32, within [0.05, 0.5].
    c: u32,
    /// |r|^2 / C, Q27, within [2, 20].
    inv_c: u32,
    /// W_B (rad/s), Q33, |.| <= 2^-3.
    w: [i32; 3],
    /// V_B / |r| (rad/s), Q40, |.| < 2^-9.
    v: [i32; 3],
    /// What `motion` needs of the fields above, folded once per update ([`Terms`]).
    k: Terms,
}

/// The per-update constants of [`Backend::motion`], in the signs and shifts its sums
/// take, so that each sum is a chain of 32 x 32 -> 64 multiply-accumulates from a
/// preset accumulator (rounding constants folded in). Derived from the other fields of
/// [`EarthFixedUpdate`] by `EarthFixedUpdate::set`, never set on their own.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Terms {
    /// rho3 2^30 + 2^28, Q60: -beta's constant term, and half a unit of Q31.
    beta0: i64,
    /// -rho1, -rho2, Q30.
    nrho: [i32; 2],
    /// -m3 2^30 + 2^31, Q63: m.u''s constant term, and half a unit of Q31.
    s0: i64,
    /// W2 2^30 and -W1 2^30, Q63: the constant terms of v1/f and v2/f.
    w0: [i64; 2],
    /// -W1, -W3, Q33.
    nw: [i32; 2],
    /// V1 2^30 + 2^30 and V2 2^30 + 2^30, Q70: the constant terms of V_k + t_k V3, and
    /// half a unit of Q39.
    v0: [i64; 2],
}

impl Terms {
    const ZERO: Terms = Terms {
        beta0: 0,
        nrho: [0; 2],
        s0: 0,
        w0: [0; 2],
        nw: [0; 2],
        v0: [0; 2],
    };
}

impl EarthFixedUpdate {
    /// All zeros: a place to build an update into ([`EarthFixed::from_general_f32_into`],
    /// [`EarthFixedUpdate::yawed_into`]) without copying one, never one to evaluate
    /// (`motion` on it refuses every pixel as [`ModelError::NoAlongTrackMotion`]).
    pub const ZERO: EarthFixedUpdate = EarthFixedUpdate {
        m: [0; 3],
        rho: [0; 3],
        c: 0,
        inv_c: 0,
        w: [0; 3],
        v: [0; 3],
        k: Terms::ZERO,
    };

    /// The update from its rounded fields (each within its format's bound).
    fn new(m: [i32; 3], rho: [i32; 3], c: u32, inv_c: u32, w: [i32; 3], v: [i32; 3]) -> Self {
        let mut up = EarthFixedUpdate::ZERO;
        up.set(m, rho, c, inv_c, w, v);
        up
    }

    /// Overwrites every field, [`Terms`] derived from the others, in place.
    // Out of line: one copy for every constructor of the update (flash).
    #[inline(never)]
    fn set(&mut self, m: [i32; 3], rho: [i32; 3], c: u32, inv_c: u32, w: [i32; 3], v: [i32; 3]) {
        let wide = |x: i32| i64::from(x);
        self.k.beta0 = (wide(rho[2]) << 30) + (1 << 28);
        self.k.nrho = [-rho[0], -rho[1]];
        self.k.s0 = -(wide(m[2]) << 30) + (1 << 31);
        self.k.w0 = [wide(w[1]) << 30, -(wide(w[0]) << 30)];
        self.k.nw = [-w[0], -w[2]];
        self.k.v0 = [
            (wide(v[0]) << 30) + (1 << 30),
            (wide(v[1]) << 30) + (1 << 30),
        ];
        self.m = m;
        self.rho = rho;
        self.c = c;
        self.inv_c = inv_c;
        self.w = w;
        self.v = v;
    }
}

/// x 2^frac rounded to nearest, refused as `err` unless |x| <= max. The caller's `max`
/// keeps the result within i32 (checked in debug builds).
// Out of line: with its soft-float rounding it was inlined into the plan build
// (docs/target.md, flash).
#[inline(never)]
fn to_q(x: f64, frac: i32, max: f64, err: ModelError) -> Result<i32, ModelError> {
    if !(x.abs() <= max) {
        return Err(err);
    }
    let q = libm::round(x * libm::ldexp(1.0, frac));
    debug_assert!(q.abs() < 2_147_483_648.0, "{x} Q{frac}");
    Ok(q as i32)
}

/// As [`to_q`] for a value known to lie in [0, max] with max 2^frac < 2^32.
/// Out of line as [`to_q`].
#[inline(never)]
fn to_uq(x: f64, frac: i32) -> u32 {
    let q = libm::round(x * libm::ldexp(1.0, frac));
    debug_assert!((0.0..4_294_967_296.0).contains(&q), "{x} UQ{frac}");
    q as u32
}

/// An [`EarthGeometry<f64>`] with the attitude rounded to the backend's I24F40 (to
/// nearest; 2^-41 rad and rad/s). Non-finite angles are [`ModelError::NonFinite`],
/// angles beyond I24F40's range [`ModelError::OutOfDomain`]. Host and boot code only.
pub fn geometry_from_f64(g: &EarthGeometry<f64>) -> Result<EarthGeometry<I24F40>, ModelError> {
    let conv = |x: f64, p: Param| -> Result<I24F40, ModelError> {
        if !x.is_finite() {
            return Err(ModelError::NonFinite(p));
        }
        I24F40::checked_from_num(x).ok_or(ModelError::OutOfDomain(p))
    };
    let a = &g.attitude;
    Ok(EarthGeometry {
        state: g.state,
        attitude: Attitude {
            roll_rad: conv(a.roll_rad, Param::Roll)?,
            pitch_rad: conv(a.pitch_rad, Param::Pitch)?,
            yaw_rad: conv(a.yaw_rad, Param::Yaw)?,
            roll_rate_rad_s: conv(a.roll_rate_rad_s, Param::RollRate)?,
            pitch_rate_rad_s: conv(a.pitch_rate_rad_s, Param::PitchRate)?,
            yaw_rate_rad_s: conv(a.yaw_rate_rad_s, Param::YawRate)?,
        },
        ground_h_m: g.ground_h_m,
        ellipsoid: g.ellipsoid,
        earth_rate_rad_s: g.earth_rate_rad_s,
    })
}

/// The backend's output widened to f64 (exact: 40 fraction bits and |v| < 2^23).
pub fn motion_to_f64(m: &ImageMotion<I24F40>) -> ImageMotion<f64> {
    ImageMotion {
        v1_mps: m.v1_mps.to_f64(),
        v2_mps: m.v2_mps.to_f64(),
    }
}

impl EarthFixed {
    /// [`Backend::update`] for Part II's attitude (the camera's axes in I and its angular
    /// velocity): [`General::update_inertial`] in f64, then the same rounding. The
    /// angular velocity is checked through W, the envelope's [`envelope::MAX_W_RAD_S`].
    pub fn update_inertial(
        &self,
        g: &InertialGeometry<f64>,
    ) -> Result<EarthFixedUpdate, ModelError> {
        let up = General::<f64>::new().update_inertial(g)?;
        let p = g.state.position_m;
        Self::round_update(&up, p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    }

    /// The per-pixel constants from a general-form update made elsewhere (`up`, with
    /// `r2_m2` = |r|^2 of the same instant): for a caller that already forms the update
    /// in its own precision, e.g. the controller's f32 update widened to f64. Only the
    /// envelope's checks run here (W through [`envelope::MAX_W_RAD_S`]); the error bound
    /// of `docs/fixed-point.md` then adds to `up`'s own error.
    pub fn from_general(
        &self,
        up: &crate::earth::GeneralUpdate<f64>,
        r2_m2: f64,
    ) -> Result<EarthFixedUpdate, ModelError> {
        if !(r2_m2 > 0.0 && r2_m2.is_finite()) {
            return Err(ModelError::OutOfDomain(Param::Position));
        }
        Self::round_update(up, r2_m2)
    }

    /// [`EarthFixed::from_general`] for an update formed in f32, in integers only (no
    /// soft f64 on a core without an FPU): every f32 is an exact integer times a power
    /// of two, 1/|r| comes from an integer square root and one 64-bit division (within
    /// 1.5e-9 relative), and each product is rounded once to its format. The same
    /// checks and refusals; each value within a unit or two of the format of
    /// `from_general` on the same update widened to f64
    /// (`core-math/tests/earth_fixed.rs`).
    pub fn from_general_f32(
        &self,
        up: &crate::earth::GeneralUpdate<f32>,
        r2_m2: f32,
    ) -> Result<EarthFixedUpdate, ModelError> {
        let mut out = EarthFixedUpdate::ZERO;
        self.from_general_f32_into(up, r2_m2, &mut out)?;
        Ok(out)
    }

    /// [`EarthFixed::from_general_f32`] written into `out` (left as it was on a refusal):
    /// for a caller that keeps the update in place, where returning one copied it.
    pub fn from_general_f32_into(
        &self,
        up: &crate::earth::GeneralUpdate<f32>,
        r2_m2: f32,
        out: &mut EarthFixedUpdate,
    ) -> Result<(), ModelError> {
        let position = ModelError::OutOfDomain(Param::Position);
        if !(r2_m2 > 0.0 && r2_m2.is_finite()) {
            return Err(position);
        }
        let (rm, re) = parts(r2_m2);
        // r^2 = M 2^(re - sh), M = rm 2^sh in [2^62, 2^64), re - sh even.
        let sh = if (re - 40) % 2 == 0 { 40 } else { 39 };
        let big_m = (rm as u64) << sh;
        // |r| = s 2^h, s in [2^31, 2^32] (within 2 units), 1/|r| = inv 2^(-63 - h).
        let s = u64::from(sqrt_per_update(big_m));
        let h = (re - sh) / 2;
        let inv = recip_63(s).ok_or(position)?;
        // x / |r| in Q`frac`: its mantissa times inv, exact in i64 (< 2^56).
        let over_r = |x: f32, frac: i32| -> Option<i64> {
            let (m, e) = parts(x);
            round_shift(m * inv, e - 63 - h + frac)
        };
        // (1/|r|)^2 = inv2 2^(-94 - 2h), inv2 = inv^2 2^-32 <= 2^32 (inv <= 2^32).
        let inv2 = if inv >= 1 << 32 {
            1 << 32
        } else {
            ((inv as u64 * inv as u64) >> 32) as i64
        };
        let (cm, ce) = parts(up.c_m2);
        if cm <= 0 {
            return Err(position);
        }
        // C / r^2 = cm inv2 2^(ce - 126 - 2h + 32).
        let c_prod = cm * inv2;
        let c_exp = ce - 94 - 2 * h;
        let c = round_shift(c_prod, c_exp + 32).ok_or(position)?;
        use limit::{C_HI, C_LO, K2M1, M, RHO, V, W};
        if !(C_LO..=C_HI).contains(&c) {
            return Err(position);
        }
        // r^2 / C in Q27 = 2^(27 - c_exp) / c_prod. With c_prod = d 2^t + (less than
        // 2^t), d in [2^31, 2^32): 2^(27 - c_exp - t) / d = (2^63 / d) 2^(-36 - c_exp - t),
        // one division of 2^63 by 32 bits (within 2^-31 relative, d's truncation
        // included).
        let t = 32 - (c_prod as u64).leading_zeros() as i32;
        let d = (c_prod as u64).checked_shr(t.max(0) as u32).unwrap_or(0);
        let quotient = recip_63(d).ok_or(position)?;
        let inv_c = round_shift(quotient, -36 - c_exp - t).ok_or(position)?;
        let direct = |x: f32, frac: i32| -> Option<i64> {
            let (m, e) = parts(x);
            round_shift(m, e + frac)
        };
        let flattening = ModelError::OutOfDomain(Param::Flattening);
        let (km, ke) = parts(up.stretch2_minus_1);
        if !(km >= 0 && matches!(direct(up.stretch2_minus_1, 36), Some(k) if k <= K2M1)) {
            return Err(flattening);
        }
        // sqrt(kappa^2 - 1) = sk 2^((ke - sh) / 2) (within 2 units of 32 bits), sh making
        // the exponent even.
        let sh = if (ke - 40) % 2 == 0 { 40 } else { 39 };
        let sk = i64::from(sqrt_per_update((km as u64) << sh));
        let stretched = |x: f32| -> Option<i64> {
            let (m, e) = parts(x);
            round_shift(sk * m, (ke - sh) / 2 + e + 33)
        };
        let within = |q: Option<i64>, max: i64, err: ModelError| match q {
            Some(q) if q.abs() <= max => Ok(q as i32),
            _ => Err(err),
        };
        let mut m = [0; 3];
        let mut rho = [0; 3];
        let mut w = [0; 3];
        let mut v = [0; 3];
        for k in 0..3 {
            within(direct(up.n_b[k], 30), limit::N, position)?;
            m[k] = within(stretched(up.n_b[k]), M, position)?;
            rho[k] = within(over_r(up.rho_b_m[k], 30), RHO, position)?;
            w[k] = within(
                direct(up.w_b_rad_s[k], 33),
                W,
                ModelError::OutOfDomain(Param::AngularVelocity),
            )?;
            v[k] = within(
                over_r(up.v_b_mps[k], 40),
                V,
                ModelError::OutOfDomain(Param::Velocity),
            )?;
        }
        let inv_c = u32::try_from(inv_c).map_err(|_| position)?;
        out.set(m, rho, c as u32, inv_c, w, v);
        Ok(())
    }

    /// [`EarthFixed::from_general_f32_into`] of `General::<f32>::ground(inst, e,
    /// ground_h_m)` (`e` the ellipsoid of `consts`), without that f32 update: straight
    /// from the f32 instant in integers. kappa^2 - 1 = (A - B)(A + B) / B^2 (A - B = a f)
    /// by one `div_64_32` in Q38; C / |r|^2 = (|r|^2 - a^2 - (2a + h) h) / |r|^2 +
    /// (kappa^2 - 1)(r_z / |r|)^2 in Q60; rho / |r| = rho0 / |r| + (kappa^2 - 1)(r_z /
    /// |r|) n in Q40; each rounded once to its format. The same checks and refusals in
    /// the same order; a height of 2^16 m or more, or |r|^2 - A^2 <= 0, takes the f32
    /// ground and [`EarthFixed::from_general_f32_into`], which refuse as before. Within
    /// a unit or two of each format of [`EarthFixed::from_general`] on the f64 ground of
    /// the same instant (`ground_f32_matches_the_f64_ground`).
    pub fn ground_f32_into(
        &self,
        inst: &crate::earth::GeneralInstant<f32>,
        consts: &GroundConsts,
        ground_h_m: f32,
        out: &mut EarthFixedUpdate,
    ) -> Result<(), ModelError> {
        match self.ground_int_into(inst, consts, ground_h_m, out) {
            Some(r) => r,
            None => ground_cold(inst, consts, ground_h_m, out),
        }
    }

    /// [`EarthFixed::ground_f32_into`] where the integers reach, None elsewhere: for a
    /// caller that makes the f32 ground itself there (one copy of it in flash) and
    /// rounds it by [`EarthFixed::from_general_f32_into`].
    #[inline(always)]
    pub fn ground_int_into(
        &self,
        inst: &crate::earth::GeneralInstant<f32>,
        consts: &GroundConsts,
        ground_h_m: f32,
        out: &mut EarthFixedUpdate,
    ) -> Option<Result<(), ModelError>> {
        ground_q(inst, consts, ground_h_m, out)
    }

    /// The f64 update, every length over |r|, rounded to the per-pixel formats.
    fn round_update(
        up: &crate::earth::GeneralUpdate<f64>,
        r2_m2: f64,
    ) -> Result<EarthFixedUpdate, ModelError> {
        let r_m = libm::sqrt(r2_m2);
        let c = up.c_m2 / r2_m2;
        let (c_min, c_max) = envelope::C_OVER_R2;
        if !(c >= c_min && c <= c_max) {
            return Err(ModelError::OutOfDomain(Param::Position));
        }
        let k = up.stretch2_minus_1;
        if !(0.0..=envelope::MAX_STRETCH2_MINUS_1).contains(&k) {
            return Err(ModelError::OutOfDomain(Param::Flattening));
        }
        let sqrt_k = libm::sqrt(k);
        let unit = ModelError::OutOfDomain(Param::Position);
        let mut m = [0; 3];
        let mut rho = [0; 3];
        let mut w = [0; 3];
        let mut v = [0; 3];
        for k in 0..3 {
            to_q(up.n_b[k], 30, envelope::MAX_UNIT, unit)?;
            m[k] = to_q(sqrt_k * up.n_b[k], 33, envelope::MAX_M, unit)?;
            rho[k] = to_q(
                up.rho_b_m[k] / r_m,
                30,
                envelope::MAX_UNIT + envelope::MAX_STRETCH2_MINUS_1,
                unit,
            )?;
            w[k] = to_q(
                up.w_b_rad_s[k],
                33,
                envelope::MAX_W_RAD_S,
                ModelError::OutOfDomain(Param::AngularVelocity),
            )?;
            // One unit short of 2^31 in Q40.
            v[k] = to_q(
                up.v_b_mps[k] / r_m,
                40,
                limit::V as f64 / (1u64 << 40) as f64,
                ModelError::OutOfDomain(Param::Velocity),
            )?;
        }
        Ok(EarthFixedUpdate::new(
            m,
            rho,
            to_uq(c, 32),
            to_uq(1.0 / c, 27),
            w,
            v,
        ))
    }
}

impl EarthFixedUpdate {
    /// The update of the same instant with the camera turned by a further yaw delta
    /// about its boresight, given by its sine and cosine in Q30: every B-frame vector
    /// turned by Rz(delta)^T, as [`crate::earth::GeneralUpdate::yawed`] does, in 32 x 32
    /// -> 64 products rounded once (half a unit of each format, with the sine's and
    /// cosine's own rounding of 2^-31 relative). A component the turn takes past the
    /// envelope (up to sqrt 2 of the largest before it) is
    /// [`ModelError::OutOfDomain`]. Integers only: the per-segment steered centre of a
    /// core without an FPU is then one [`Backend::motion`].
    pub fn yawed(&self, sin_q30: i32, cos_q30: i32) -> Result<EarthFixedUpdate, ModelError> {
        let mut out = EarthFixedUpdate::ZERO;
        self.yawed_into(sin_q30, cos_q30, &mut out)?;
        Ok(out)
    }

    /// [`EarthFixedUpdate::yawed`] written into `out` (left as it was on a refusal), for
    /// a caller that keeps the update in place.
    pub fn yawed_into(
        &self,
        sin_q30: i32,
        cos_q30: i32,
        out: &mut EarthFixedUpdate,
    ) -> Result<(), ModelError> {
        let turn = |x: [i32; 3], max: i64, p: Param| -> Result<[i32; 3], ModelError> {
            let (c, s) = (i64::from(cos_q30), i64::from(sin_q30));
            let (x0, x1) = (i64::from(x[0]), i64::from(x[1]));
            let mut out = [0i32; 3];
            for (o, v) in out.iter_mut().zip([c * x0 + s * x1, c * x1 - s * x0]) {
                let r = (v + (1 << 29)) >> 30;
                if r.abs() > max {
                    return Err(ModelError::OutOfDomain(p));
                }
                *o = r as i32;
            }
            out[2] = x[2];
            Ok(out)
        };
        let m = turn(self.m, limit::M, Param::Position)?;
        let rho = turn(self.rho, limit::RHO, Param::Position)?;
        let w = turn(self.w, limit::W, Param::AngularVelocity)?;
        let v = turn(self.v, limit::V, Param::Velocity)?;
        out.set(m, rho, self.c, self.inv_c, w, v);
        Ok(())
    }
}

impl EarthFixedUpdate {
    /// The image motion at the boresight (p1 = p2 = 0) over the focal length, (v1/f,
    /// v2/f) in Q63 (rad/s): [`Backend::motion`]'s integers at t1 = t2 = 0, where no
    /// pixel constant is left (the yaw request needs only its direction). The same
    /// refusals.
    pub fn boresight_over_focal(&self) -> Result<(i64, i64), ModelError> {
        // beta = -rho3 (Q30 -> Q31), m.u' = -m3.
        let rho3 = self.rho[2];
        if rho3 <= 0 {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let b31 = (rho3 as u32) << 1;
        let m3 = i64::from(self.m[2]);
        // (m.u')^2: Q66 -> Q30, < 0.026.
        let alpha = (1u32 << 30) + ((m3 * m3) >> 36) as u32;
        // Once per update: the root out of line.
        let ninv_s = i64::from(neg_inv_sigma(b31, alpha, self, sqrt_per_update)?);
        // -V_k / sigma: Q40 x Q24 = Q64, |.| < 2^61.2, to Q63.
        let [w1, w2, _] = self.w;
        let vf1 = (i64::from(w2) << 30) + ((i64::from(self.v[0]) * ninv_s) >> 1);
        let vf2 = -(i64::from(w1) << 30) + ((i64::from(self.v[1]) * ninv_s) >> 1);
        if vf1 == 0 {
            return Err(ModelError::NoAlongTrackMotion);
        }
        Ok((vf1, vf2))
    }
}

/// An ellipsoid's constants for [`EarthFixed::ground_f32_into`], in integers (made in
/// a const context: no soft f64 at run time).
#[derive(Clone, Copy, Debug)]
pub struct GroundConsts {
    /// The ellipsoid itself, for the f32 route where the integers do not reach.
    ellipsoid: crate::earth::Ellipsoid,
    /// A - B = a f, Q16.
    a_minus_b_q16: i64,
    /// a + b, Q8.
    a_plus_b_q8: i64,
    /// b, Q8.
    b_q8: i64,
    /// 2a, Q4.
    two_a_q4: i64,
}

impl GroundConsts {
    /// The constants of `e` (a and b below 2^22.9 m: the Earth's, rounded to nearest).
    pub const fn new(e: &crate::earth::Ellipsoid) -> GroundConsts {
        let b = e.a_m * (1.0 - e.flattening);
        GroundConsts {
            ellipsoid: *e,
            a_minus_b_q16: (e.a_m * e.flattening * 65_536.0 + 0.5) as i64,
            a_plus_b_q8: ((e.a_m + b) * 256.0 + 0.5) as i64,
            b_q8: (b * 256.0 + 0.5) as i64,
            two_a_q4: (2.0 * e.a_m * 16.0 + 0.5) as i64,
        }
    }
}

/// [`EarthFixed::ground_f32_into`] where the integers reach: the f32 ground and its
/// rounding.
#[cold]
#[inline(never)]
fn ground_cold(
    inst: &crate::earth::GeneralInstant<f32>,
    consts: &GroundConsts,
    ground_h_m: f32,
    out: &mut EarthFixedUpdate,
) -> Result<(), ModelError> {
    let up = General::<f32>::new().ground(inst, &consts.ellipsoid, ground_h_m)?;
    EarthFixed.from_general_f32_into(&up, inst.r2_m2, out)
}

/// The integer body of [`EarthFixed::ground_f32_into`]; None where it hands over to
/// the f32 route.
#[inline(never)]
fn ground_q(
    inst: &crate::earth::GeneralInstant<f32>,
    k: &GroundConsts,
    ground_h_m: f32,
    out: &mut EarthFixedUpdate,
) -> Option<Result<(), ModelError>> {
    let position = ModelError::OutOfDomain(Param::Position);
    let r2_m2 = inst.r2_m2;
    if !(r2_m2 > 0.0 && r2_m2.is_finite()) {
        return None;
    }
    // h in Q8 (|h| < 2^16 m), its mantissa for (2a + h) h.
    let (hm, he) = parts(ground_h_m);
    let h8 = round_shift_call(hm, he + 8)?;
    if h8.abs() >= 1 << 24 {
        return None;
    }
    // 1/|r| and its square as in `from_general_f32_into`.
    let (rm, re) = parts(r2_m2);
    let sh = if (re - 40) % 2 == 0 { 40 } else { 39 };
    let s = u64::from(sqrt_per_update((rm as u64) << sh));
    let hr = (re - sh) / 2;
    let inv = recip_63(s)?;
    let over_r = |x: f32, frac: i32| -> Option<i64> {
        let (m, e) = parts(x);
        round_shift_call(m * inv, e - 63 - hr + frac)
    };
    let inv2 = if inv >= 1 << 32 {
        1 << 32
    } else {
        ((inv as u64 * inv as u64) >> 32) as i64
    };
    // kappa^2 - 1 = (A - B)(A + B) / B^2, Q38: B in Q8 (about 2^30.6), B^2 in Q16 below
    // 2^62, its top 32 bits d (>= 2^31); (A - B)(A + B) in Q24, below d 2^31.
    let b8 = k.b_q8 + h8;
    let num = k.a_minus_b_q16 * (k.a_plus_b_q8 + 2 * h8);
    let b2 = (b8 * b8) as u64;
    let d = (b2 >> 30) as u32;
    if b8 <= 0 || d < 1 << 31 || num < 0 || (num as u64) >> 31 >= u64::from(d) {
        return None;
    }
    // num / (d 2^30) 2^-8 = q 2^-38.
    let q = i64::from(crate::wide::div_64_32((num >> 32) as u32, num as u32, d));
    // z / |r|, Q30, and its square.
    let zr = over_r(inst.r_z_m, 30)?;
    let zr2 = (zr * zr + (1 << 29)) >> 30;
    // |r|^2 - A^2 = (|r|^2 - a^2) - (2a + h) h, Q4: (2a + h) in Q4 times h's mantissa.
    let (nm, ne) = parts(inst.r2_minus_a2_m2);
    let lead = round_shift_call(nm, ne + 4)?;
    let tail = round_shift_call((k.two_a_q4 + (h8 >> 4)) * hm, he)?;
    let n4 = lead - tail;
    if n4 <= 0 {
        return None;
    }
    // n4 = n 2^t with n < 2^31 (truncated), then over |r|^2: Q60.
    let t = (33 - n4.leading_zeros() as i32).max(0);
    let term1 = round_shift_call((n4 >> t) * inv2, t - 4 - 94 - 2 * hr + 60)?;
    // (kappa^2 - 1)(z/|r|)^2: Q38 x Q30 = Q68, to Q60.
    let c60 = term1 + ((q * zr2 + (1 << 7)) >> 8);
    let c = (c60 + (1 << 27)) >> 28;
    use limit::{C_HI, C_LO, K2M1};
    if !(C_LO..=C_HI).contains(&c) {
        return Some(Err(position));
    }
    // r^2 / C, Q27 = 2^87 / c60: c60 = dc 2^tc + (less), dc in [2^31, 2^32).
    let tc = 32 - c60.leading_zeros() as i32;
    let dc = (c60 as u64).checked_shr(tc.max(0) as u32).unwrap_or(0);
    let inv_c = round_shift_call(recip_63(dc)?, 24 - tc)?;
    let Ok(inv_c) = u32::try_from(inv_c) else {
        return Some(Err(position));
    };
    if (q + 2) >> 2 > K2M1 {
        return Some(Err(ModelError::OutOfDomain(Param::Flattening)));
    }
    // sqrt(kappa^2 - 1): q 2^z in [2^62, 2^64), z even; its root in Q(19 + z/2).
    let z = (q as u64).leading_zeros() & !1;
    let sk = i64::from(sqrt_per_update((q as u64) << z));
    let sk_frac = 19 + (z / 2) as i32;
    // (kappa^2 - 1) z / |r|, Q40 (Q38 x Q30 = Q68).
    let kz40 = (q * zr + (1 << 27)) >> 28;
    let mut m = [0; 3];
    let mut rho = [0; 3];
    let mut w = [0; 3];
    let mut v = [0; 3];
    let scales = Scales {
        inv,
        hr,
        sk,
        sk_frac,
        kz40,
    };
    for kk in 0..3 {
        let f = ground_fields(inst, &scales, kk);
        match f {
            Ok(f) => (m[kk], rho[kk], w[kk], v[kk]) = f,
            Err(e) => return Some(Err(e)),
        }
    }
    out.set(m, rho, c as u32, inv_c, w, v);
    Some(Ok(()))
}

/// The per-instant scales of [`ground_fields`]: 1/|r| = inv 2^(-63 - hr), sqrt(kappa^2
/// - 1) = sk 2^-sk_frac, (kappa^2 - 1) z / |r| in Q40.
struct Scales {
    inv: i64,
    hr: i32,
    sk: i64,
    sk_frac: i32,
    kz40: i64,
}

/// One axis `kk` of [`ground_q`]'s fields (m, rho, W, V) in their formats, with their
/// checks. Out of line, one copy for the three axes (flash).
#[inline(never)]
fn ground_fields(
    inst: &crate::earth::GeneralInstant<f32>,
    sc: &Scales,
    kk: usize,
) -> Result<(i32, i32, i32, i32), ModelError> {
    let position = ModelError::OutOfDomain(Param::Position);
    let within = |q: Option<i64>, max: i64, err: ModelError| match q {
        Some(q) if q.abs() <= max => Ok(q as i32),
        _ => Err(err),
    };
    let at = |x: [f32; 3]| x.get(kk).copied().unwrap_or(f32::NAN);
    let over_r = |x: f32, frac: i32| -> Option<i64> {
        let (m, e) = parts(x);
        round_shift_call(m * sc.inv, e - 63 - sc.hr + frac)
    };
    let n = at(inst.n_b);
    let (nm, ne) = parts(n);
    within(round_shift_call(nm, ne + 30), limit::N, position)?;
    let m = within(
        round_shift_call(sc.sk * nm, ne - sc.sk_frac + 33),
        limit::M,
        position,
    )?;
    // rho0 / |r| + (kappa^2 - 1)(z / |r|) n, both in Q40, rounded once to Q30.
    let rho40 = over_r(at(inst.rho0_b_m), 40)
        .zip(round_shift_call(sc.kz40 * nm, ne))
        .and_then(|(a, b)| round_shift_call(a + b, -10));
    let rho = within(rho40, limit::RHO, position)?;
    let (wm, we) = parts(at(inst.w_b_rad_s));
    let w = within(
        round_shift_call(wm, we + 33),
        limit::W,
        ModelError::OutOfDomain(Param::AngularVelocity),
    )?;
    let v = within(
        over_r(at(inst.v_b_mps), 40),
        limit::V,
        ModelError::OutOfDomain(Param::Velocity),
    )?;
    Ok((m, rho, w, v))
}

/// [`round_shift`] out of line (a 64-bit shift by a variable is long on a 32-bit core:
/// one copy for [`ground_q`]).
#[inline(never)]
fn round_shift_call(m: i64, sh: i32) -> Option<i64> {
    round_shift(m, sh)
}

/// 2^63 / `d` truncated, for `d` in [2^31 - 2, 2^32]: the core's 32-bit divide twice
/// (`wide::div_64_32`), where a u64 division is a software call; 2^32 at and below 2^31
/// (within 1e-9 relative of the quotient there), None for 0.
#[inline(always)]
fn recip_63(d: u64) -> Option<i64> {
    match u32::try_from(d) {
        Ok(n) if n > 1 << 31 => Some(i64::from(crate::wide::div_64_32(1 << 31, 0, n))),
        Ok(0) => None,
        Ok(n) if n >= (1 << 31) - 2 => Some(1 << 32),
        _ => (1u64 << 63).checked_div(d).map(|q| q as i64),
    }
}

/// A finite f32 as m 2^e exactly (m signed, |m| < 2^24; zero as (0, 0)).
#[inline(always)]
fn parts(x: f32) -> (i64, i32) {
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32;
    let frac = i64::from(bits & 0x7f_ffff);
    let (m, e) = if e == 0 {
        (frac, -149)
    } else {
        (frac | 0x80_0000, e - 150)
    };
    (if bits >> 31 != 0 { -m } else { m }, e)
}

/// m 2^sh rounded to nearest (ties up), `None` past i64.
#[inline(always)]
fn round_shift(m: i64, sh: i32) -> Option<i64> {
    if sh >= 0 {
        let k = sh.unsigned_abs();
        if k >= 63 || m.unsigned_abs() >= 1u64 << (63 - k) {
            return (m == 0).then_some(0);
        }
        Some(m << k)
    } else {
        let k = sh.unsigned_abs();
        if k >= 63 {
            return Some(0);
        }
        Some((m + (1 << (k - 1))) >> k)
    }
}

impl Backend<Earth> for EarthFixed {
    type Real = I24F40;
    type Pixel = EarthFixedPixel;
    type Update = EarthFixedUpdate;

    /// The general form's checks of the optics, then the envelope's.
    fn pixel(&self, camera: &EarthCamera, n_px: f64) -> Result<EarthFixedPixel, ModelError> {
        let (p1, p2) = camera.focal_plane_m(n_px)?;
        let f = camera.focal_m;
        let (f_min, f_max) = envelope::FOCAL_M;
        if !(f >= f_min && f <= f_max) {
            return Err(ModelError::OutOfDomain(Param::FocalLength));
        }
        let (t1, t2) = (p1 / f, p2 / f);
        let tan = envelope::MAX_TAN_FIELD;
        let t1q = to_q(t1, 30, tan, ModelError::OutOfDomain(Param::FocalPlaneP1))?;
        let t2q = to_q(t2, 30, tan, ModelError::OutOfDomain(Param::PixelOffset))?;
        // f = f_mant 2^-e, f_mant in [2^31, 2^32): e = 31 - floor(log2 f).
        let (_, exp) = libm::frexp(f); // f = m 2^exp, m in [1/2, 1)
        let e = 32 - exp;
        let f_mant = libm::round(libm::ldexp(f, e));
        // Rounding up to 2^32 (f a hair below a power of two) takes the next exponent.
        let (f_mant, e) = if f_mant >= 4_294_967_296.0 {
            (2_147_483_648u32, e - 1)
        } else {
            (f_mant as u32, e)
        };
        Ok(EarthFixedPixel {
            t1: t1q,
            t2: t2q,
            t11: to_q(
                t1 * t1,
                30,
                1.0,
                ModelError::OutOfDomain(Param::FocalPlaneP1),
            )?,
            t12: to_q(
                t1 * t2,
                30,
                1.0,
                ModelError::OutOfDomain(Param::PixelOffset),
            )?,
            t22: to_q(
                t2 * t2,
                30,
                1.0,
                ModelError::OutOfDomain(Param::PixelOffset),
            )?,
            uu: to_uq(1.0 + t1 * t1 + t2 * t2, 30),
            f_mant,
            shift: (e - 9) as u32,
        })
    }

    /// The general form's update in f64 (every check of the contract, in its order), then
    /// the attitude rates against the envelope, then the rounding.
    fn update(&self, g: &EarthGeometry<I24F40>) -> Result<EarthFixedUpdate, ModelError> {
        let g = g.to_f64();
        let up = General::<f64>::new().update(&g)?;
        let max = envelope::MAX_ATTITUDE_RATE_RAD_S;
        let a = &g.attitude;
        for (x, p) in [
            (a.roll_rate_rad_s, Param::RollRate),
            (a.pitch_rate_rad_s, Param::PitchRate),
            (a.yaw_rate_rad_s, Param::YawRate),
        ] {
            if !(x.abs() <= max) {
                return Err(ModelError::OutOfDomain(p));
            }
        }
        let p = g.state.position_m;
        Self::round_update(&up, p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    }

    /// Per pixel, integers only. Each line gives the format and the bound over the
    /// envelope (`docs/fixed-point.md`). A v1 below the output's last bit (2^-40 m/s)
    /// is [`ModelError::NoAlongTrackMotion`], where the float forms refuse below 1e-30.
    #[inline]
    fn motion(
        &self,
        up: &EarthFixedUpdate,
        px: &EarthFixedPixel,
    ) -> Result<ImageMotion<I24F40>, ModelError> {
        let k = &up.k;
        let (t1, t2) = (px.t1, px.t2);
        // -beta = -rho.u' and half a unit of Q31, Q60, |.| <= 1.026 sqrt(3) < 1.78.
        let nbeta = mac(mac(k.beta0, k.nrho[0], t1), k.nrho[1], t2);
        // Both roots share the sign of -beta (C > 0): a ray with beta >= 0 looks away
        // (one with |beta| below half a unit, b31 = 0, misses on the discriminant).
        if nbeta < 0 {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        // |beta|, Q31 (rounded), < 2^31.9.
        let b31 = (nbeta >> 29) as u32;
        // m.u' = sqrt(kappa^2 - 1) n.u', Q63 (< 0.48), its high word Q31 (rounded).
        let s31 = (mac(mac(k.s0, up.m[0], t1), up.m[1], t2) >> 32) as i32;
        // alpha = |u'|^2 + (m.u')^2, Q30 (the square's high word), < 3.08.
        let alpha = px.uu + ((i64::from(s31) * i64::from(s31)) >> 32) as u32;
        // -1/sigma, Q24 (> -2^30.2).
        let ninv_s = neg_inv_sigma(b31, alpha, up, sqrt_u64)?;
        // V_k + t_k V3, Q70 -> Q39 (rounded), |.| < 2^-8: below 2^31 as V_k < 2^-9.
        let v3 = up.v[2];
        let p1 = (mac(k.v0[0], v3, t1) >> 31) as i32;
        let p2 = (mac(k.v0[1], v3, t2) >> 31) as i32;
        // v/f, Q63: W terms Q33 x Q30, each < 2^60, four of them < 2^62; the V term
        // Q39 x Q24, < 2^61.2; sum < 2^62.7.
        let [_, w2, w3] = up.w;
        let vf1 = mac(
            mac(mac(mac(k.w0[0], p1, ninv_s), w2, px.t11), w3, t2),
            k.nw[0],
            px.t12,
        );
        let vf2 = mac(
            mac(mac(mac(k.w0[1], p2, ninv_s), k.nw[0], px.t22), k.nw[1], t1),
            w2,
            px.t12,
        );
        let (v1, v2) = (times_focal(vf1, px), times_focal(vf2, px));
        if v1 == 0 {
            return Err(ModelError::NoAlongTrackMotion);
        }
        Ok(ImageMotion {
            v1_mps: I24F40::from_bits(v1),
            v2_mps: I24F40::from_bits(v2),
        })
    }
}

/// acc + a b: one multiply-accumulate (SMLAL).
#[inline(always)]
fn mac(acc: i64, a: i32, b: i32) -> i64 {
    acc + i64::from(a) * i64::from(b)
}

/// The high word of a 32 x 32 -> 64 product (UMULL).
#[inline(always)]
fn mulhi(a: u32, b: u32) -> u32 {
    ((u64::from(a) * u64::from(b)) >> 32) as u32
}

/// -1/sigma (1/sigma the near root's reciprocal) in Q24 from |beta| (Q31) and alpha
/// (Q30), with the update's C and |r|^2/C; a ray whose discriminant is negative misses.
/// Negative, so that its products are plainly signed ones (SMLAL). `sqrt` is
/// [`sqrt_u64`], inline per pixel or out of line per update.
#[inline(always)]
fn neg_inv_sigma(
    b31: u32,
    alpha: u32,
    up: &EarthFixedUpdate,
    sqrt: fn(u64) -> u32,
) -> Result<i32, ModelError> {
    // beta^2 and alpha C, Q62, < 2^63.7 and 2^62.7.
    let bb = u64::from(b31) * u64::from(b31);
    let ac = u64::from(alpha) * u64::from(up.c);
    let (disc, miss) = bb.overflowing_sub(ac);
    if miss {
        return Err(ModelError::LineOfSightMissesEarth);
    }
    // sqrt(disc), Q31.
    let root = sqrt(disc);
    // (sqrt(disc) + |beta|) / 2, Q30, the numerator of 1/sigma (< 3.56): the halving
    // add that needs no 33rd bit.
    let num = (root & b31) + ((root ^ b31) >> 1);
    // 1/sigma = num |r|^2/C: Q57 (< 71.2 = 2^63.2), rounded to Q24 (< 2^30.2) for
    // signed products: its high word (Q25) plus one, halved.
    Ok(-(((mulhi(num, up.inv_c) + 1) >> 1) as i32))
}

/// (v/f in Q63) x f as I24F40 bits: x f_mant 2^-e 2^-23 = (x f_mant 2^-32) >> (e - 9),
/// e - 9 in 13..29. Truncated toward -infinity twice: 2^-40 m/s at most each.
#[inline(always)]
fn times_focal(x: i64, px: &EarthFixedPixel) -> i64 {
    // x f_mant 2^-32 exactly, with f_mant = g + 2^32 (g its bits as i32, negative
    // since f_mant >= 2^31): hi g + hi 2^32 + (lo f_mant) 2^-32, one UMULL and one SMLAL.
    let (hi, lo) = ((x >> 32) as i32, x as u32);
    let m = px.f_mant;
    let top = i64::from(hi) * i64::from(m as i32) + (i64::from(hi) << 32) + i64::from(mulhi(lo, m));
    shr(top, px.shift)
}

/// [`sqrt_u64`] out of line, for the per-update code (one copy in flash; the
/// controller's integer instant takes it too).
#[inline(never)]
pub fn sqrt_per_update(x: u64) -> u32 {
    sqrt_u64(x)
}

/// sqrt(x), never above it and at most 2 units below (`sqrt_u64_within_two_units`),
/// integer only, no division (core's `isqrt` divides, a `__aeabi_uldivmod` call on a 32-bit
/// core), in 32-bit halves. The round Earth's scheme (`docs/fixed-point.md`): x
/// normalised by an even shift z to xn in [2^62, 2^64) (x below 2^32 first taken as
/// x 2^32), f = its high word in [2^30, 2^32); a seed r0 of 1/sqrt(f 2^-32) from f's top
/// 10 bits, one Newton step r1 = r0 (3 - f r0^2) / 2 with the product rounded up, so
/// that r1 <= 1/sqrt(f) (Newton's step for 1/sqrt never overshoots), s = f r1 <=
/// sqrt(xn), then Heron's correction (xn - s^2) r1 / 2 from xn's 64 bits (xn - s^2 >= 0
/// and below 2^47: its high word suffices); sqrt(x) = that 2^(-z/2).
#[inline(always)]
pub fn sqrt_u64(x: u64) -> u32 {
    let (hi, lo) = ((x >> 32) as u32, x as u32);
    let (hi, lo, extra) = if hi == 0 { (lo, 0, 16) } else { (hi, lo, 0) };
    // z even, 0..=30 (0 for x = 0, which then gives 0 throughout).
    let z = hi.leading_zeros() & 30;
    let f = (hi << z) | ((lo >> 1) >> (31 - z));
    let xn = (u64::from(f) << 32) | u64::from(lo << z);
    // r0, Q14, < 2.
    let r0 = u32::from(RSQRT_SEED[(f >> 22) as usize]);
    // 3 - f r0^2 rounded down, Q30 (about 2); r1 = r0 u / 2, Q30, < 2.
    let u = (3 << 30) - 1 - mulhi(f, (r0 * r0) << 2);
    let r1 = mulhi(r0 << 17, u);
    // sqrt(xn) from below: sqrt(f 2^-32) in Q30 (< 1), shifted to Q32.
    let s = mulhi(f, r1) << 2;
    let d = xn - u64::from(s) * u64::from(s);
    let y = s.saturating_add(mulhi((d >> 32) as u32, r1 << 1));
    y >> ((z >> 1) + extra)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `from_general_f32` (integers) against `from_general` on the same f32 update
    /// widened to f64 (exact there, rounded once): every field within one unit of its
    /// format plus 3e-9 of its value (1/|r|'s error, 50 times below the f32 update's own
    /// rounding), the same refusals, over altitudes 200-2 500 km, attitudes, rates and
    /// ground heights.
    #[test]
    fn from_general_f32_matches_the_f64_rounding() {
        extern crate std;
        use crate::earth::{circular_state, Ellipsoid, GeneralUpdate};
        let mut rng = crate::sample::SplitMix64(0xF32F_1CED_2026);
        let general = General::<f32>::new();
        let (mut worst, mut checked) = (0f64, 0);
        for _ in 0..20_000 {
            let radius = Ellipsoid::WGS84.a_m + rng.uniform(150e3, 2_700e3);
            let g = EarthGeometry {
                state: circular_state(radius, rng.uniform(0.0, 3.1), rng.uniform(-3.2, 3.2)),
                attitude: Attitude {
                    roll_rad: rng.uniform(-0.6, 0.6),
                    pitch_rad: rng.uniform(-0.5, 0.5),
                    yaw_rad: rng.uniform(-3.2, 3.2),
                    roll_rate_rad_s: rng.uniform(-0.05, 0.05),
                    pitch_rate_rad_s: rng.uniform(-0.05, 0.05),
                    yaw_rate_rad_s: rng.uniform(-0.05, 0.05),
                },
                ground_h_m: rng.uniform(-500.0, 9_000.0),
                ellipsoid: Ellipsoid::WGS84,
                earth_rate_rad_s: crate::EARTH_RATE_RAD_S,
            };
            let gf = EarthGeometry {
                state: g.state,
                attitude: Attitude {
                    roll_rad: g.attitude.roll_rad as f32,
                    pitch_rad: g.attitude.pitch_rad as f32,
                    yaw_rad: g.attitude.yaw_rad as f32,
                    roll_rate_rad_s: g.attitude.roll_rate_rad_s as f32,
                    pitch_rate_rad_s: g.attitude.pitch_rate_rad_s as f32,
                    yaw_rate_rad_s: g.attitude.yaw_rate_rad_s as f32,
                },
                ground_h_m: g.ground_h_m,
                ellipsoid: g.ellipsoid,
                earth_rate_rad_s: g.earth_rate_rad_s,
            };
            let Ok(up) = general.update(&gf) else {
                continue;
            };
            let p = g.state.position_m;
            let r2 = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) as f32;
            let w = |x: [f32; 3]| x.map(f64::from);
            let wide = GeneralUpdate {
                n_b: w(up.n_b),
                rho_b_m: w(up.rho_b_m),
                stretch2_minus_1: f64::from(up.stretch2_minus_1),
                c_m2: f64::from(up.c_m2),
                inv_c_per_m2: f64::from(up.inv_c_per_m2),
                w_b_rad_s: w(up.w_b_rad_s),
                v_b_mps: w(up.v_b_mps),
            };
            let want = EarthFixed.from_general(&wide, f64::from(r2));
            let got = EarthFixed.from_general_f32(&up, r2);
            match (want, got) {
                (Ok(a), Ok(b)) => {
                    // Units off beyond the last one, over the value: the relative error
                    // of 1/|r| (and of its square for C and 1/C).
                    for_each_field(&a, &b, |x, y| {
                        let excess = x.abs_diff(y).saturating_sub(1) as f64;
                        worst = worst.max(excess / (x.unsigned_abs().max(1) as f64));
                    });
                    checked += 1;
                }
                (a, b) => assert_eq!(a.is_ok(), b.is_ok(), "{a:?} vs {b:?}"),
            }
        }
        assert!(checked > 15_000, "{checked}");
        assert!(worst <= 3e-9, "{worst:e}");
        std::eprintln!(
            "from_general_f32: beyond one unit, worst {worst:.2e} relative over {checked} updates"
        );
    }

    /// `ground_f32_into` (integers, from the f32 instant) against `from_general` on the
    /// general form's f64 ground of the same instant widened to f64: every field within
    /// two units of its format plus 3e-9 of its value, the same refusals, over
    /// altitudes 150-2 700 km, attitudes, rates and ground heights from -500 to 9 000 m;
    /// heights past the integers' 2^16 m take the f32 route and agree with it.
    #[test]
    fn ground_f32_matches_the_f64_ground() {
        extern crate std;
        use crate::earth::{circular_state, Ellipsoid, GeneralInstant};
        let mut rng = crate::sample::SplitMix64(0x6_0D1D_2026_1127);
        let general = General::<f32>::new();
        let consts = GroundConsts::new(&Ellipsoid::WGS84);
        let (mut worst, mut worst_units, mut checked, mut refused) = (0f64, 0u64, 0, 0);
        for i in 0..20_000 {
            let radius = Ellipsoid::WGS84.a_m + rng.uniform(150e3, 2_700e3);
            let state = circular_state(radius, rng.uniform(0.0, 3.1), rng.uniform(-3.2, 3.2));
            let attitude = Attitude {
                roll_rad: rng.uniform(-0.6, 0.6) as f32,
                pitch_rad: rng.uniform(-0.5, 0.5) as f32,
                yaw_rad: rng.uniform(-3.2, 3.2) as f32,
                roll_rate_rad_s: rng.uniform(-0.05, 0.05) as f32,
                pitch_rate_rad_s: rng.uniform(-0.05, 0.05) as f32,
                yaw_rate_rad_s: rng.uniform(-0.05, 0.05) as f32,
            };
            let Ok(inst) = general.instant(
                &state,
                &attitude,
                &Ellipsoid::WGS84,
                crate::EARTH_RATE_RAD_S,
            ) else {
                continue;
            };
            let h = if i % 100 == 0 {
                rng.uniform(70e3, 400e3) as f32
            } else {
                rng.uniform(-500.0, 9_000.0) as f32
            };
            let w = |x: [f32; 3]| x.map(f64::from);
            let wide = GeneralInstant {
                n_b: w(inst.n_b),
                rho0_b_m: w(inst.rho0_b_m),
                r_z_m: f64::from(inst.r_z_m),
                r2_m2: f64::from(inst.r2_m2),
                r2_minus_a2_m2: f64::from(inst.r2_minus_a2_m2),
                w_b_rad_s: w(inst.w_b_rad_s),
                v_b_mps: w(inst.v_b_mps),
            };
            let want = General::<f64>::new()
                .ground(&wide, &Ellipsoid::WGS84, f64::from(h))
                .and_then(|up| EarthFixed.from_general(&up, f64::from(inst.r2_m2)));
            let mut got = EarthFixedUpdate::ZERO;
            let got = EarthFixed
                .ground_f32_into(&inst, &consts, h, &mut got)
                .map(|()| got);
            if h >= 65_536.0 {
                // The f32 route: the f32 ground rounded, as before.
                let float = general
                    .ground(&inst, &Ellipsoid::WGS84, h)
                    .and_then(|up| EarthFixed.from_general_f32(&up, inst.r2_m2));
                assert_eq!(got, float);
                continue;
            }
            match (want, got) {
                (Ok(a), Ok(b)) => {
                    for_each_field(&a, &b, |x, y| {
                        let units = x.abs_diff(y);
                        worst_units = worst_units.max(units);
                        let excess = units.saturating_sub(2) as f64;
                        worst = worst.max(excess / (x.unsigned_abs().max(1) as f64));
                    });
                    checked += 1;
                }
                (a, b) => {
                    assert_eq!(a.err(), b.err());
                    refused += 1;
                }
            }
        }
        assert!(checked > 15_000, "{checked}");
        assert!(worst <= 3e-9, "{worst:e}");
        std::eprintln!(
            "ground_f32_into: at most {worst_units} units, beyond two {worst:.2e} relative, \
             over {checked} updates ({refused} refused alike)"
        );
    }

    /// `d(x, y)` for each pair of like fields of two updates, as i64.
    fn for_each_field(a: &EarthFixedUpdate, b: &EarthFixedUpdate, mut d: impl FnMut(i64, i64)) {
        for k in 0..3 {
            d(a.m[k].into(), b.m[k].into());
            d(a.rho[k].into(), b.rho[k].into());
            d(a.w[k].into(), b.w[k].into());
            d(a.v[k].into(), b.v[k].into());
        }
        d(a.c.into(), b.c.into());
        d(a.inv_c.into(), b.inv_c.into());
    }

    /// `recip_63` against the u64 division over its domain's every edge and 10^6
    /// random divisors: exact (the truncated quotient) above 2^31, 2^32 at 2^31 and the
    /// two below it (within 1e-9 of the quotient there), None for 0.
    #[test]
    fn recip_63_is_the_truncated_quotient() {
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        let check = |d: u64| {
            let want = (1u64 << 63) / d;
            let got = recip_63(d).unwrap() as u64;
            if d > 1 << 31 {
                assert_eq!(got, want, "{d}");
            } else {
                assert_eq!(got, 1 << 32, "{d}");
                assert!((want - got) as f64 <= 1e-9 * want as f64, "{d}");
            }
        };
        for d in [
            (1 << 31) - 2,
            (1 << 31) - 1,
            1 << 31,
            (1 << 31) + 1,
            u32::MAX as u64,
            1 << 32,
        ] {
            check(d);
        }
        for _ in 0..1_000_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            check((1 << 31) + x % ((1 << 31) + 1));
        }
        assert_eq!(recip_63(0), None);
    }

    /// Against the exact square root (u128 arithmetic, independent of the scheme, in
    /// units of 2^-30) over every magnitude, the extremes and the top of every
    /// normalisation band included: never above it by a unit, at most two below it.
    #[test]
    fn sqrt_u64_within_two_units() {
        extern crate std;
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let (mut below, mut above) = (0i128, 0i128);
        let mut check = |v: u64| {
            // sqrt(v) 2^30, floored: the exact root to 2^-30.
            let exact = ((v as u128) << 60).isqrt() as i128;
            let got = i128::from(sqrt_u64(v)) << 30;
            below = below.max(exact - got);
            above = above.max(got - exact);
        };
        for i in 0..2_000_000u32 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            check(x >> (i % 64));
        }
        for v in [0, 1, 2, 3, 4, u64::MAX, u64::MAX - 1, 1 << 63] {
            check(v);
        }
        for j in 1..32 {
            let top = 1u64 << (2 * j);
            for v in [top - 1, top - 2, top - (top >> 20).max(1), top, top + 1] {
                check(v);
            }
        }
        let unit = 1i128 << 30;
        std::eprintln!(
            "sqrt_u64: at most {:.3} units below the root, {:.3} above",
            below as f64 / unit as f64,
            above as f64 / unit as f64
        );
        assert!(below <= 2 * unit && above < unit, "{below} {above}");
    }
}

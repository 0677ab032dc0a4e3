//! Image-motion mismatch MTF (Eqs. 17-19) and the TDI stage limit it implies.
//!
//! At the Nyquist frequency f_c = 1/(2A) a relative velocity mismatch dv/v over M TDI
//! stages smears the image by s = A M dv/v (Eq. 18), and
//! MTF_mismatch = |sinc(x)| = |sin(x)/x| with x = pi M (dv/v) / 2 (Eq. 19).
//!
//! The MTF is the modulus of the optical transfer function: a uniform smear's OTF is
//! sinc, and past its first zero (x = pi) the contrast comes back with its phase
//! reversed, weaker (|sinc| <= 0.2172 there), not negative and not gone. So both factors
//! here, mismatch and drift smear, are |sinc| (`../shared/EARTH-MODEL.md` defines the
//! drift's as |sinc(d/2)|, docs/derivation.md section 19). The stage limit
//! ([`StageRule`]) is the largest M whose MTF meets the floor at every count up to M:
//! floors are at least [`MIN_MTF_FLOOR`] (0.25), above every later lobe, so a count past
//! either factor's first zero never meets one, and the limit is also the largest count
//! that meets it at all.

use crate::error::{ModelError, Param};
use crate::real::Real;

const HALF_PI: f64 = core::f64::consts::FRAC_PI_2;
const PI: f64 = core::f64::consts::PI;

/// Taylor coefficients of sin(x)/x in x^2, (-1)^k / (2k+1)!, k = 0..=10. On |x| <= pi the
/// series truncated after k terms errs by less than its first omitted term,
/// pi^(2k)/(2k+1)!: after 11 terms 1.2e-11 (f64, with the largest term under 1.7: good to
/// ~1e-11). f32 takes [`SINC_MINIMAX_F32`] instead.
const SINC_TAYLOR: [f64; 11] = [
    1.0,
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5_040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
    -1.0 / 121_645_100_408_832_000.0,
    1.0 / 51_090_942_171_709_440_000.0,
];

/// sin(x)/x on |x| <= pi in f32: the least-largest-error polynomial of degree 6 in x^2,
/// its coefficients f32 values (`python3 tools/fit_sinc_f32.py` fits them; evaluated in
/// f32 it errs by 1.7e-7 at most, like 9 terms of [`SINC_TAYLOR`] in f32:
/// `core-math/tests/mtf_period.rs`). Two multiply-adds fewer than the series.
const SINC_MINIMAX_F32: [f64; 7] = [
    1.0,
    -0.1666666567325592,
    0.008333321660757065,
    -0.00019840536697302014,
    2.7535900244402e-06,
    -2.4729255088118407e-08,
    1.361460388871194e-10,
];

/// sin(x)/x, with sinc(0) = 1: a polynomial on |x| <= pi (no call, no 0/0), sin(x)/x beyond.
///
/// Inlined, the quotient's route out of line: the stage limit evaluates four of these
/// per segment and update (`cargo xtask bench --profile`). Out of line on the M3, whose
/// update takes the integer sincs (`int`): there the f32 ones are the cold routes'.
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
#[cfg_attr(
    not(all(target_arch = "arm", not(target_abi = "eabihf"))),
    inline(always)
)]
pub fn sinc<T: Real>(x: T) -> T {
    let pi = T::from_f64(PI);
    if x <= pi && -x <= pi {
        // A constant per type: the minimax polynomial in f32, the series in f64.
        let coefficients: &[f64] = if T::EPSILON.to_f64() > 1e-10 {
            &SINC_MINIMAX_F32
        } else {
            &SINC_TAYLOR
        };
        let x2 = x * x;
        let mut acc = T::ZERO;
        for &c in coefficients.iter().rev() {
            acc = acc * x2 + T::from_f64(c);
        }
        acc
    } else {
        sinc_beyond_pi(x)
    }
}

/// [`sinc`] as a call, for the cold routes (the bisection and the one-factor limits
/// that bracket it): inlined, their unrolled tests held six copies of it. (On the M3
/// [`sinc`] is a call already.)
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(always))]
#[cfg_attr(
    not(all(target_arch = "arm", not(target_abi = "eabihf"))),
    inline(never)
)]
fn sinc_cold<T: Real>(x: T) -> T {
    sinc(x)
}

/// sin(x)/x for |x| > pi, NaN and infinities included.
#[cold]
#[inline(never)]
fn sinc_beyond_pi<T: Real>(x: T) -> T {
    // |sinc x| <= 1/|x|: the limit at infinity is 0 (an overflowed argument, never NaN).
    // So is it from where the sine gives NaN on (`trig_f64`, no huge-argument
    // reduction): there |sinc x| is below 1/1 647 099 = 6.1e-7, and 0 is that close.
    if !x.is_finite() || x.abs() >= T::from_f64(crate::trig_f64::SIN_COS_LIMIT_RAD) {
        return T::ZERO;
    }
    x.sin() / x
}

/// The MTF of a uniform smear at `x` = pi/2 times its length in pixels: |sinc(x)|, the
/// modulus of its transfer function (past x = pi the contrast is reversed, and counted
/// by its size). In [0, 1] in f32 and f64 (sinc never exceeds 1: tested).
#[inline(always)]
pub fn smear_mtf<T: Real>(x: T) -> T {
    sinc(x).abs()
}

/// MTF_mismatch at Nyquist for `stages` TDI stages and a relative mismatch dv/v (Eq. 19):
/// |sinc(pi M dv/v / 2)|, the modulus (beyond x = pi the contrast is reversed, at most
/// 0.2172 of it left; the module's note).
pub fn mtf_mismatch<T: Real>(stages: u32, rel_mismatch: T) -> Result<T, ModelError> {
    if !rel_mismatch.is_finite() {
        return Err(ModelError::NonFinite(Param::RelativeMismatch));
    }
    Ok(smear_mtf(
        T::from_f64(HALF_PI) * T::from_u32(stages) * rel_mismatch,
    ))
}

/// MTF of the drift smear at Nyquist (`../shared/EARTH-MODEL.md`, derived outputs): over
/// `stages` TDI stages an image moving at `tan_drift` across the line smears by
/// d = M |tan drift| pixels, and MTF = |sinc(pi d / 2)| (sinc(x) = sin(x)/x). The same
/// function of M x as [`mtf_mismatch`].
pub fn mtf_drift<T: Real>(stages: u32, tan_drift: T) -> Result<T, ModelError> {
    if !tan_drift.is_finite() {
        return Err(ModelError::NonFinite(Param::Drift));
    }
    Ok(smear_mtf(
        T::from_f64(HALF_PI) * T::from_u32(stages) * tan_drift,
    ))
}

/// Smallest and largest MTF floor a [`StageRule`] accepts.
pub const MIN_MTF_FLOOR: f64 = 0.25;
pub const MAX_MTF_FLOOR: f64 = 0.9999;
/// Stage limits above this (2^23) are taken as this by [`StageRule::max_stages`]: f32
/// holds every count up to it exactly, and its search is proven there
/// (`core-math/tests/fuzz_regressions.rs`, F5). TDI sensors have at most a few hundred.
pub const MAX_STAGE_LIMIT: u32 = 1 << 23;

/// How far [`StageRule::max_stages_with_drift`] moves its guess before it falls back to
/// bisection: the guess is within 0.9 % (floors from 0.5) of the answer, so this covers
/// every count up to a few hundred stages.
const GUESS_STEPS: u32 = 3;

/// The stage limit from a guess `m` (at most `limit`): down to a count that `meets` the
/// floor (M = 0 always does: the product is 1), then up while the next count meets it
/// too, at most [`GUESS_STEPS`] each way; None when that does not settle it (the
/// bisection then answers). `meets_call` is the same test, for the steps.
#[inline(always)]
fn settle_guess(
    m: u32,
    limit: u32,
    meets: impl Fn(u32) -> bool,
    meets_call: impl Fn(u32) -> bool,
) -> Option<u32> {
    // The usual case inline: the guess meets the floor and one stage more does not.
    // The steps either way out of line: `meets` is inlined (two sincs), and unrolled
    // they were six more copies of it in the update; `meets_call`, a call, spares the
    // steps' loop a seventh (docs/target.md, flash).
    if (m == 0 || meets(m)) && (m == limit || !meets(m + 1)) {
        return Some(m);
    }
    settle_guess_by_steps(m, limit, meets_call)
}

/// [`settle_guess`] from the start, a step at a time.
#[inline(never)]
fn settle_guess_by_steps(mut m: u32, limit: u32, meets: impl Fn(u32) -> bool) -> Option<u32> {
    // Down while m fails, then up while m + 1 meets, in one loop with one call of
    // `meets`, which is inlined.
    let (mut down, mut steps) = (true, 0);
    loop {
        let probe = if down {
            m
        } else if m == limit {
            return Some(m);
        } else {
            m + 1
        };
        let ok = probe == 0 || meets(probe);
        if down {
            if ok {
                (down, steps) = (false, 0);
                continue;
            }
            if steps == GUESS_STEPS {
                return None;
            }
            m -= 1;
        } else {
            if !ok {
                return Some(m);
            }
            m += 1;
        }
        steps += 1;
        if !down && steps == GUESS_STEPS {
            return None;
        }
    }
}

/// The TDI stage limit for one MTF floor: computed once (per scene), used per update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StageRule<T> {
    mtf_floor: T,
    /// x_f / (pi/2) where sinc(x_f) = floor on [0, pi]: M |dv/v| may not exceed it.
    mismatch_budget: T,
    /// (x_f / x_2)^2 - 1, x_2 the root of sinc(x)^2 = floor: the combined limit's
    /// guess (see [`StageRule::max_stages_with_drift`]).
    pair_kappa: T,
}

/// |e| and |t| of the combined stage limit's inputs, each refused when not finite
/// (the drift first).
fn magnitudes<T: Real>(rel_mismatch: T, tan_drift: T) -> Result<(T, T), ModelError> {
    if !tan_drift.is_finite() {
        return Err(ModelError::NonFinite(Param::Drift));
    }
    if !rel_mismatch.is_finite() {
        return Err(ModelError::NonFinite(Param::RelativeMismatch));
    }
    Ok((rel_mismatch.abs(), tan_drift.abs()))
}

/// The root of sinc(x) = `level` on [0, pi] (sinc falls strictly there), by bisection
/// in f64.
fn sinc_root(level: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, PI);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        // `sin_cos`'s sine (the same value as `sin`): the flight binary links
        // `sin_cos` anyway, and a second reduction and kernel would cost flash.
        if crate::trig_f64::sin_cos(mid).0 / mid >= level {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

impl<T: Real> StageRule<T> {
    /// The rule of no scene: every count but 0 fails it (a budget of 0), so no stage
    /// count is promised. A placeholder until a real rule replaces it.
    pub fn none() -> Self {
        StageRule {
            mtf_floor: T::ONE,
            mismatch_budget: T::ZERO,
            pair_kappa: T::ZERO,
        }
    }

    /// The rule for `mtf_floor` in (0, 1): solves sinc(x_f) = floor by bisection in f64
    /// (sinc falls strictly on [0, pi]), so the per-update work is one division.
    pub fn new(mtf_floor: f64) -> Result<Self, ModelError> {
        if !mtf_floor.is_finite() {
            return Err(ModelError::NonFinite(Param::MtfFloor));
        }
        // Within the main lobe of sinc (its first side lobe peaks at 0.217), and far
        // enough below 1 that the budget is a normal number in f32.
        if !(MIN_MTF_FLOOR..=MAX_MTF_FLOOR).contains(&mtf_floor) {
            return Err(ModelError::OutOfDomain(Param::MtfFloor));
        }
        let x_f = sinc_root(mtf_floor);
        let x_2 = sinc_root(libm::sqrt(mtf_floor));
        Ok(StageRule {
            mtf_floor: T::from_f64(mtf_floor),
            mismatch_budget: T::from_f64(x_f / HALF_PI),
            pair_kappa: T::from_f64((x_f / x_2) * (x_f / x_2) - 1.0),
        })
    }

    /// The largest M in 0..=min(`stage_limit`, [`MAX_STAGE_LIMIT`]) with
    /// MTF_mismatch(M, dv/v) >= floor. The closed-form guess is checked against
    /// [`mtf_mismatch`] itself and moved by one stage where rounding put it on the wrong
    /// side of the floor. The returned M always meets the floor.
    pub fn max_stages(&self, rel_mismatch: T, stage_limit: u32) -> Result<u32, ModelError> {
        // Finding F5 (docs/fuzzing.md): beyond 2^23 an f32 guess is off by more than the
        // correction's two steps, and past 2^24 neighbouring counts round to one f32.
        // Capping keeps the answer meeting the floor; only its maximality is given up,
        // for counts no TDI sensor has.
        let stage_limit = stage_limit.min(MAX_STAGE_LIMIT);
        if !rel_mismatch.is_finite() {
            return Err(ModelError::NonFinite(Param::RelativeMismatch));
        }
        let d = if rel_mismatch < T::ZERO {
            -rel_mismatch
        } else {
            rel_mismatch
        };
        let limit = T::from_u32(stage_limit);
        let mut m = if d * limit <= self.mismatch_budget {
            stage_limit
        } else {
            // budget / d >= 0: truncation is the floor (and saturates as `floor` would),
            // without the software `floorf` this core would call.
            (self.mismatch_budget / d).to_u32().min(stage_limit)
        };
        let meets = |m: u32| sinc_cold(T::from_f64(HALF_PI) * T::from_u32(m) * d) >= self.mtf_floor;
        // The guess is off by at most one stage from rounding (the floor is kept away
        // from 1 and inside the main lobe), so the correction is bounded: at most two
        // steps each way, whatever the inputs.
        for _ in 0..2 {
            if m > 0 && !meets(m) {
                m -= 1;
            }
        }
        for _ in 0..2 {
            if m < stage_limit && meets(m + 1) {
                m += 1;
            }
        }
        Ok(m)
    }

    /// The largest M in 0..=min(`stage_limit`, [`MAX_STAGE_LIMIT`]) whose combined MTF,
    /// mismatch times drift smear, |sinc(pi/2 M e)| |sinc(pi/2 M t)|, meets the floor at
    /// every count up to M, for a relative mismatch e and a drift tangent t. (Past
    /// either factor's first zero the product is at most 0.2172, under every floor:
    /// the signed product the search evaluates meets the floor exactly where the
    /// modulus does, and no later lobe ever does.)
    ///
    /// Guessed, then checked: the continuous root of sinc(x e) sinc(x t) = floor is
    /// close to x_f / (d sqrt(1 + kappa r^2)), d = max(e, t), r = min/max, a form exact
    /// at r = 0 and r = 1 (kappa from the root of sinc^2) and within 0.9 % between for
    /// floors from 0.5 up (1.8 % at 0.25). The guess is then moved by at most
    /// `GUESS_STEPS` stages until the count meets the floor and the next one does not.
    /// That certifies it: on the main lobe the product falls strictly, and past either
    /// factor's first zero it stays under 0.22 < [`MIN_MTF_FLOOR`]. Should the guess
    /// be further off (counts of tens of thousands of stages), the bracket and
    /// bisection of [`StageRule::max_stages_with_drift_by_bisection`] answer instead.
    /// Typical cost: two products, four sincs (`cargo xtask bench`).
    pub fn max_stages_with_drift(
        &self,
        rel_mismatch: T,
        tan_drift: T,
        stage_limit: u32,
    ) -> Result<u32, ModelError> {
        let (e, t) = magnitudes(rel_mismatch, tan_drift)?;
        let limit = stage_limit.min(MAX_STAGE_LIMIT);
        let (larger, smaller) = if e > t { (e, t) } else { (t, e) };
        if larger == T::ZERO {
            return Ok(limit);
        }
        let r = smaller / larger;
        let guess = self.mismatch_budget / (larger * (T::ONE + self.pair_kappa * r * r).sqrt());
        let m = if guess >= T::from_u32(limit) {
            limit
        } else {
            // guess >= 0: truncation is the floor.
            guess.to_u32()
        };
        let steps = |m: u32| self.meets_pair_out_of_line(e, t, m);
        match settle_guess(m, limit, self.meets_pair(e, t), steps) {
            Some(m) => Ok(m),
            None => self.max_stages_with_drift_by_bisection(rel_mismatch, tan_drift, stage_limit),
        }
    }

    /// [`StageRule::meets_pair`] at `m`, as a call.
    #[inline(never)]
    fn meets_pair_out_of_line(&self, e: T, t: T, m: u32) -> bool {
        let x = T::from_f64(HALF_PI) * T::from_u32(m);
        sinc_cold(x * e) * sinc_cold(x * t) >= self.mtf_floor
    }

    /// Whether M stages meet the floor under mismatch e and drift tangent t (both >= 0).
    #[inline(always)]
    fn meets_pair(&self, e: T, t: T) -> impl Fn(u32) -> bool + '_ {
        let half_pi = T::from_f64(HALF_PI);
        move |m: u32| {
            let x = half_pi * T::from_u32(m);
            sinc(x * e) * sinc(x * t) >= self.mtf_floor
        }
    }

    /// [`StageRule::max_stages_with_drift`] by bracket and bisection, its fallback and
    /// its independent check (`core-math/tests/mtf_period.rs`).
    ///
    /// The product is at most either factor, so M is at most the one-factor limit of
    /// max(e, t); and sinc(x) sinc(y) >= sinc(sqrt(x^2 + y^2)) on the main lobe, so it is
    /// at least the one-factor limit of hypot(e, t). On that bracket both arguments stay
    /// inside the main lobe, where the product falls strictly, so bisection finds the
    /// largest M that meets the floor. Every M returned is checked against the product
    /// itself.
    // Out of line: the fallback, rarely taken, was inlined with its sincs into the
    // update (docs/target.md, flash).
    #[inline(never)]
    pub fn max_stages_with_drift_by_bisection(
        &self,
        rel_mismatch: T,
        tan_drift: T,
        stage_limit: u32,
    ) -> Result<u32, ModelError> {
        let (e, t) = magnitudes(rel_mismatch, tan_drift)?;
        let larger = if e > t { e } else { t };
        let mut hi = self.max_stages(larger, stage_limit)?;
        let mut lo = self
            .max_stages((e * e + t * t).sqrt(), stage_limit)?
            .min(hi);
        // Each test a call: inlined, the unrolled checks and the loop were six copies of
        // the two sincs (docs/target.md, flash).
        let meets = |m: u32| self.meets_pair_out_of_line(e, t, m);
        // The lower end's own check (rounding may put it a stage over); M = 0 always
        // meets (the product is 1), the fallback should the bound ever fail.
        for _ in 0..2 {
            if lo > 0 && !meets(lo) {
                lo -= 1;
            }
        }
        if !meets(lo) {
            lo = 0;
        }
        // Invariant: meets(lo), and nothing above hi meets.
        while lo < hi {
            let mid = lo + (hi - lo).div_ceil(2);
            if meets(mid) {
                lo = mid;
            } else {
                hi = mid - 1;
            }
        }
        Ok(lo)
    }

    pub fn mtf_floor(&self) -> T {
        self.mtf_floor
    }

    /// The largest M |dv/v| that keeps MTF_mismatch at or above the floor: a segment
    /// with M stages may be mismatched by at most this over M.
    pub fn mismatch_budget(&self) -> T {
        self.mismatch_budget
    }
}

/// The smear MTF and the stage limit in fixed point, for cores without an FPU: on the
/// main lobe every sinc in Q30 integers instead of soft float, within 5e-9 of
/// sin(x)/x (docs/fixed-point.md, "The update on the Cortex-M3").
pub mod int {
    use super::{settle_guess, smear_mtf, StageRule, HALF_PI, MAX_STAGE_LIMIT};
    use crate::error::{ModelError, Param};
    use crate::wide::{div_64_32, Wide};

    /// 1 in Q30.
    const ONE_Q30: u64 = 1 << 30;
    /// pi^2 / 6 in Q30, rounded up.
    const PI2_OVER_6_Q30: u64 = 1_766_234_506;

    /// sin(pi y)/(pi y) as a polynomial in y^2, (-1)^k pi^(2k) / (2k+1)!, k = 0..=9, in
    /// Q30 (every one below 2: Horner's rule on y^2 <= 1 never grows a partial sum past
    /// 1.7). Truncated after them the series errs by at most pi^20/21! = 1.7e-10 on
    /// |y| <= 1.
    const SINC_PI_Q30: [i32; 10] = [
        1_073_741_824,
        -1_766_234_505,
        871_601_792,
        -204_818_212,
        28_076_038,
        -2_519_085,
        159_374,
        -7_490,
        272,
        -8,
    ];

    /// A finite x >= 0 as `mant` 2^`exp2`: M x / 2, the smear argument of M stages over
    /// pi, is exact in integers from it (`mant` < 2^24, M <= 2^23).
    #[derive(Clone, Copy, Debug)]
    pub struct Smear {
        mant: u32,
        /// Q30 of M x / 2 is M `mant` 2^`exp2`.
        exp2: i32,
    }

    impl Smear {
        /// `None` for an infinite or NaN `x`; its sign is dropped.
        pub fn new(x: f32) -> Option<Self> {
            let bits = x.abs().to_bits();
            let e = (bits >> 23) as i32;
            if e == 255 {
                return None;
            }
            // Subnormals as 0: M x / 2 then stays below 2^-100.
            let mant = if e == 0 {
                0
            } else {
                (bits & 0x7f_ffff) | 0x80_0000
            };
            // x = mant 2^(e - 150); M x / 2 in Q30 is M mant 2^(e - 121).
            Some(Smear {
                mant,
                exp2: e - 121,
            })
        }

        /// y = M x / 2 in Q30, truncated (2^-30 at most), or `None` past 1, sinc's first
        /// zero at pi y = pi.
        #[inline(always)]
        pub fn y_q30(self, m: u32) -> Option<u32> {
            match self.y_wide_q30(m) {
                Some(y) if y <= ONE_Q30 => Some(y as u32),
                _ => None,
            }
        }

        /// y = M x / 2 in Q30, truncated, or `None` from 2^62 on.
        #[inline(always)]
        fn y_wide_q30(self, m: u32) -> Option<u64> {
            // < 2^47: exact.
            let prod = u64::from(m) * u64::from(self.mant);
            if self.exp2 >= 0 {
                let s = self.exp2 as u32;
                if prod >= (1u64 << 62).checked_shr(s).unwrap_or(0) {
                    return None;
                }
                Some(prod << s)
            } else {
                Some(prod.checked_shr(self.exp2.unsigned_abs()).unwrap_or(0))
            }
        }
    }

    /// sin(pi y)/(pi y) for y in Q30 on [0, 1], in Q30: `SINC_PI_Q30` by Horner's rule
    /// in 32 x 32 -> 64 products, within 5e-9 of the exact value (truncation 1.7e-10,
    /// ten roundings of 2^-31, the constants' 2^-31 each; measured:
    /// `core-math/tests/mtf_period.rs`).
    // Out of line on the M3, whose update it is for: two copies inlined there, against
    // a call per sinc, small beside the update (docs/target.md, flash).
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    pub fn sinc_pi_q30(y_q30: u32) -> i32 {
        let y2 = ((u64::from(y_q30) * u64::from(y_q30)) >> 30) as i32;
        let mut acc = SINC_PI_Q30[9];
        for &c in SINC_PI_Q30[..9].iter().rev() {
            acc = ((i64::from(acc) * i64::from(y2) + (1 << 29)) >> 30) as i32 + c;
        }
        acc
    }

    /// y = 1/4 in Q30: up to it [`sinc_pi_short_q30`] is within 1e-8 of [`sinc_pi_q30`].
    const SHORT_Y_MAX_Q30: u32 = 1 << 28;
    /// 2^-20 in Q60: the band about the floor where the short sincs do not decide.
    const SHORT_BAND_Q60: i64 = 1 << 40;

    /// [`sinc_pi_q30`]'s first five coefficients by the same Horner's rule, for y at
    /// most 1/4: it differs from that by the last five coefficients' Horner sum (below
    /// 2.6e-3) times y^10 (2.5e-9 at most) and nine roundings of 2^-31 (4.2e-9): by
    /// less than 1e-8.
    // Out of line on the M3, as [`sinc_pi_q30`]: one copy in flash.
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    fn sinc_pi_short_q30(y_q30: u32) -> i32 {
        let y2 = ((u64::from(y_q30) * u64::from(y_q30)) >> 30) as i32;
        let mut acc = SINC_PI_Q30[4];
        for &c in SINC_PI_Q30[..4].iter().rev() {
            acc = ((i64::from(acc) * i64::from(y2) + (1 << 29)) >> 30) as i32 + c;
        }
        acc
    }

    /// A value in [0, 1] as Q30, truncated (at most one unit, 9.3e-10, below it).
    fn unit_q30(x: f32) -> u32 {
        let bits = x.to_bits();
        let e = (bits >> 23) as i32;
        if bits >> 31 != 0 || e < 127 - 40 {
            return 0;
        }
        if e >= 127 {
            return 1 << 30;
        }
        let mant = (bits & 0x7f_ffff) | 0x80_0000;
        // x = mant 2^(e - 150); Q30: mant 2^(e - 120), a right shift of 120 - e.
        ((u64::from(mant) << 7) >> (127 - e)) as u32
    }

    /// |sinc(pi/2 M x)| in Q30 for M x / 2 below 2^32: on the main lobe as
    /// [`sinc_pi_q30`] of `y_q30`; past it, with y = k + f (f in [0, 1)), |sin(pi y)| = sin(pi f),
    /// so |sinc(pi y)| = f sinc(pi f) / y, one integer division.
    #[inline(always)]
    fn smear_q30(x: Smear, m: u32) -> Option<i32> {
        let y = x.y_wide_q30(m)?;
        if y <= ONE_Q30 {
            return Some(sinc_pi_q30(y as u32));
        }
        let f = y & (ONE_Q30 - 1);
        let s = sinc_pi_q30(f as u32).max(0) as u64;
        // f s in Q60 (< 2^60) over y in Q30: Q30, below 1/pi. For y below 2^32 (4),
        // both shifted until y's leading one is at bit 31, for the 64 / 32 division in
        // the core's divide (a 64-bit division is a software call): the exact floor.
        // Beyond, in [`Wide`]: a quotient below 2^28 within three truncations of 2^-31,
        // under one unit.
        let fs = f * s;
        match u32::try_from(y) {
            Ok(y32) => {
                let lz = y32.leading_zeros();
                let n = fs << lz;
                Some(div_64_32((n >> 32) as u32, n as u32, y32 << lz) as i32)
            }
            Err(_) => Some((Wide::from_u64(fs, 0) / Wide::from_u64(y, 0)).to_u64_scaled(0) as i32),
        }
    }

    /// The smear MTF of `stages` TDI stages under a relative mismatch `e` and a drift
    /// tangent `t`, |sinc(pi/2 M e)| |sinc(pi/2 M t)|, what
    /// `smear_mtf(pi/2 M e) * smear_mtf(pi/2 M t)` gives in f32: within 1e-8 of the
    /// exact product (then rounded to f32) while M x / 2 stays below 2^32; beyond, that
    /// f32 form.
    pub fn smear_mtf_pair(stages: u32, e: f32, t: f32) -> f32 {
        match (
            Smear::new(e).and_then(|x| smear_q30(x, stages)),
            Smear::new(t).and_then(|x| smear_q30(x, stages)),
        ) {
            (Some(a), Some(b)) => {
                let p = (i64::from(a) * i64::from(b)).max(0) >> 30;
                // Exact in Wide (p < 2^31), rounded once: what `p as f32 * 2^-30` gives.
                Wide::from_u64(p as u64, -30).to_f32()
            }
            _ => beyond_main_lobe(stages, e, t),
        }
    }

    /// floor(sqrt(x)), bit by bit (core's `isqrt` divides: a software call here).
    #[inline(always)]
    fn isqrt_u64(x: u64) -> u64 {
        if x == 0 {
            return 0;
        }
        let (mut x, mut r) = (x, 0u64);
        let mut bit = 1u64 << ((63 - x.leading_zeros()) & !1);
        while bit != 0 {
            if x >= r + bit {
                x -= r + bit;
                r = (r >> 1) + bit;
            } else {
                r >>= 1;
            }
            bit >>= 2;
        }
        r
    }

    /// The integer guess against the f32 form's formula in f64: the floor of the same
    /// quotient, except within 1e-6 of an integer (the Wide's truncations are 1e-9), over
    /// magnitudes 1e-7 to 3 and floors 0.25 to 0.99.
    #[test]
    fn guess_int_is_the_floor_of_the_guess() {
        extern crate std;
        let mut rng = crate::sample::SplitMix64(0x5EED_2026_1127_0005);
        for floor in [0.25, 0.5, 0.8, 0.9, 0.99] {
            let rule = StageRule::<f32>::new(floor).unwrap();
            for _ in 0..20_000 {
                let a = libm::pow(10.0, rng.uniform(-7.0, 0.5)) as f32;
                let b = (f64::from(a) * rng.uniform(0.0, 1.0)) as f32;
                let limit = 1 + (rng.next_u64() % (1 << 23)) as u32;
                let (l, s) = (f64::from(a), f64::from(b));
                let kappa = f64::from(rule.pair_kappa);
                let want = f64::from(rule.mismatch_budget) / libm::sqrt(l * l + kappa * s * s);
                let got = rule.guess_int(a, b, limit);
                if want >= f64::from(limit) * (1.0 + 1e-6) {
                    assert_eq!(got, limit);
                } else if libm::fabs(want - libm::round(want)) > 1e-6 * want.max(1.0) {
                    assert_eq!(
                        f64::from(got),
                        libm::floor(want).min(f64::from(limit)),
                        "{a} {b}"
                    );
                }
            }
        }
    }

    /// The short sincs' bound against the full polynomial at every y up to 1/4 (step 7),
    /// and `meets_q30` against the full sincs' decision at each count around the
    /// answer, with floors 0.5 to 0.99 and arguments that put the product within a
    /// few 2^-20 of the floor as well as across it.
    #[test]
    fn short_sincs_decide_as_the_full_ones() {
        extern crate std;
        let mut worst = 0i64;
        for y in (0..=SHORT_Y_MAX_Q30).step_by(7) {
            worst = worst.max((i64::from(sinc_pi_short_q30(y)) - i64::from(sinc_pi_q30(y))).abs());
        }
        // 1e-8 in Q30 is 10.7 units.
        assert!(worst <= 10, "{worst}");
        let full = |xe: Smear, xt: Smear, floor: i64, m: u32| match (
            xe.y_q30(m).map(sinc_pi_q30),
            xt.y_q30(m).map(sinc_pi_q30),
        ) {
            (Some(a), Some(b)) => i64::from(a) * i64::from(b) >= floor,
            _ => false,
        };
        let mut rng = crate::sample::SplitMix64(0x5EED_2026_1127_0024);
        let (mut checked, mut in_band) = (0u32, 0u32);
        for floor in [0.5f32, 0.8, 0.9, 0.95, 0.99] {
            let floor_q60 = (u64::from(unit_q30(floor)) << 30) as i64;
            for _ in 0..20_000 {
                let m = 1 + (rng.next_u64() % 4096) as u32;
                // y_e = m e / 2 where the product of sinc(pi y_e) and sinc(pi r y_e) is
                // the floor plus d, d within 3e-8, 4 x 2^-20 or 0.05 of 0 (by bisection
                // in f64), t = r e.
                let r = rng.uniform(0.0, 1.0);
                let d = [4.0 / f64::from(1u32 << 20), 0.05, 3e-8][(rng.next_u64() % 3) as usize]
                    * rng.uniform(-1.0, 1.0);
                let sinc = |x: f64| if x == 0.0 { 1.0 } else { libm::sin(x) / x };
                let pi = core::f64::consts::PI;
                let (mut lo, mut hi) = (0.0, 1.0);
                for _ in 0..60 {
                    let y = 0.5 * (lo + hi);
                    if sinc(pi * y) * sinc(pi * r * y) > f64::from(floor) + d {
                        lo = y;
                    } else {
                        hi = y;
                    }
                }
                let e = (2.0 * lo / f64::from(m)) as f32;
                let t = (f64::from(e) * r) as f32;
                let (xe, xt) = (Smear::new(e).unwrap(), Smear::new(t).unwrap());
                for k in m.saturating_sub(2)..=m + 2 {
                    let want = full(xe, xt, floor_q60, k);
                    assert_eq!(meets_q30(xe, xt, floor_q60, k), want, "{e} {t} {k}");
                    if let (Some(a), Some(b)) = (xe.y_q30(k), xt.y_q30(k)) {
                        let p = i64::from(sinc_pi_q30(a)) * i64::from(sinc_pi_q30(b));
                        if (p - floor_q60).abs() < 1 << 42 {
                            in_band += 1;
                        }
                    }
                    checked += 1;
                }
            }
        }
        assert!(in_band > 10_000, "{in_band} of {checked} near the floor");
        std::println!(
            "short sincs within {worst} units of the full; {in_band} of {checked} counts within 2^-18 of the floor"
        );
    }

    /// Against the exact root (u128's `isqrt`) at random magnitudes and around squares.
    #[test]
    fn isqrt_u64_is_the_floor_root() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for i in 0..1_000_000u32 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = x >> (i % 64);
            assert_eq!(isqrt_u64(v), (v as u128).isqrt() as u64, "{v}");
            let r = v >> 32;
            for sq in [r * r, (r * r).wrapping_sub(1), r * r + 1] {
                assert_eq!(isqrt_u64(sq), (sq as u128).isqrt() as u64, "{sq}");
            }
        }
        assert_eq!(isqrt_u64(u64::MAX), u64::from(u32::MAX));
    }

    /// Whether `m` stages keep the product of the two sincs at `floor` (Q60) or above.
    // Out of line on the M3: the search's usual case and its steps inlined a copy each
    // (docs/target.md, flash).
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    fn meets_q30(xe: Smear, xt: Smear, floor: i64, m: u32) -> bool {
        // Past either factor's first zero the product is under every floor.
        let (Some(ye), Some(yt)) = (xe.y_q30(m), xt.y_q30(m)) else {
            return false;
        };
        // Both arguments at most 1/4 (the usual case near the floors in use): the series'
        // first five terms first. Their product is within 2e-8 of the full polynomials'
        // (each factor within 1e-8, [`sinc_pi_short_q30`]), so outside a band of 2^-20
        // about the floor it decides as those would; inside the band, the full sincs.
        if ye.max(yt) <= SHORT_Y_MAX_Q30 {
            let p = i64::from(sinc_pi_short_q30(ye)) * i64::from(sinc_pi_short_q30(yt));
            if p >= floor + SHORT_BAND_Q60 {
                return true;
            }
            if p < floor - SHORT_BAND_Q60 {
                return false;
            }
        }
        i64::from(sinc_pi_q30(ye)) * i64::from(sinc_pi_q30(yt)) >= floor
    }

    #[cold]
    #[inline(never)]
    fn beyond_main_lobe(stages: u32, e: f32, t: f32) -> f32 {
        let h = HALF_PI as f32 * stages as f32;
        smear_mtf(h * e) * smear_mtf(h * t)
    }

    impl StageRule<f32> {
        /// [`StageRule::max_stages_with_drift`] with each count's product of sincs in
        /// Q30 integers (the same guess in f32, the same steps, the same fallback): a
        /// count may differ from the f32 form's only where the product lies within 1e-8
        /// of the floor, where the f32 form's own rounding decides too.
        pub fn max_stages_with_drift_int(
            &self,
            rel_mismatch: f32,
            tan_drift: f32,
            stage_limit: u32,
        ) -> Result<u32, ModelError> {
            // `magnitudes` on the bits: its checks, in its order, without the software
            // comparisons (for f32s >= 0 the bits order as the values).
            let (e_bits, t_bits) = (
                rel_mismatch.to_bits() & 0x7fff_ffff,
                tan_drift.to_bits() & 0x7fff_ffff,
            );
            if t_bits >= 0x7f80_0000 {
                return Err(ModelError::NonFinite(Param::Drift));
            }
            if e_bits >= 0x7f80_0000 {
                return Err(ModelError::NonFinite(Param::RelativeMismatch));
            }
            let (e, t) = (f32::from_bits(e_bits), f32::from_bits(t_bits));
            let limit = stage_limit.min(MAX_STAGE_LIMIT);
            let (larger, smaller) = if e_bits > t_bits { (e, t) } else { (t, e) };
            if e_bits.max(t_bits) == 0 {
                return Ok(limit);
            }
            // Both finite (`magnitudes`).
            let (Some(xe), Some(xt)) = (Smear::new(e), Smear::new(t)) else {
                return Ok(0);
            };
            let floor_q30 = unit_q30(self.mtf_floor);
            // The limit itself, where the product's lower bound (1 - x^2/6)(1 - y^2/6)
            // >= 1 - (x^2 + y^2)/6 (sinc(x) >= 1 - x^2/6 for every x) clears the floor by
            // 2^-25, more than the truncations of y and the floor and the polynomial's
            // error together (about 13 units of Q30): then `meets(limit)` holds and
            // every smaller count meets too, what the search below would return, without
            // its guess in soft float. The usual case of a nominal update.
            if let (Some(ye), Some(yt)) = (xe.y_q30(limit), xt.y_q30(limit)) {
                // x = pi y: (x^2 + y^2)/6 = pi^2/6 (y_e^2 + y_t^2); Q30 products.
                let s = ((u64::from(ye) * u64::from(ye)) >> 30)
                    + ((u64::from(yt) * u64::from(yt)) >> 30);
                let loss = (s * PI2_OVER_6_Q30) >> 30;
                if loss + (1 << 5) + u64::from(floor_q30) <= ONE_Q30 {
                    return Ok(limit);
                }
            }
            let m = self.guess_int(larger, smaller, limit);
            let floor = (u64::from(floor_q30) << 30) as i64;
            let meets = |m: u32| meets_q30(xe, xt, floor, m);
            match settle_guess(m, limit, meets, meets) {
                Some(m) => Ok(m),
                None => {
                    self.max_stages_with_drift_by_bisection(rel_mismatch, tan_drift, stage_limit)
                }
            }
        }

        /// The search's start, the f32 form's guess budget / (L sqrt(1 + kappa (S/L)^2))
        /// as floor(sqrt(budget^2 / (L^2 + kappa S^2))) in [`Wide`] (L > 0 the larger
        /// magnitude, S the smaller), at most `limit`. Within a count of the f32 guess:
        /// the search settles from either on the same count.
        #[inline(always)]
        fn guess_int(&self, larger: f32, smaller: f32, limit: u32) -> u32 {
            let w = |x: f32| Wide::from_f32(x).unwrap_or(Wide::ZERO);
            let (l, s) = (w(larger), w(smaller));
            let den = l * l + w(self.pair_kappa) * (s * s);
            if den.is_zero() {
                // L below f32's normals: the f32 guess is infinite.
                return limit;
            }
            let b = w(self.mismatch_budget);
            let q = (b * b / den).to_u64_scaled(0);
            let lim = u64::from(limit);
            if q >= lim * lim {
                limit
            } else {
                isqrt_u64(q) as u32
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{settle_guess, GUESS_STEPS};

    /// The guess settled for a floor met by the counts 0..=k exactly, every guess and
    /// limit up to 12, against the rule in words: the answer min(k, limit) when the
    /// guess is at most GUESS_STEPS above k or at most GUESS_STEPS - 1 below the
    /// answer, None otherwise. Both the inline usual case and the stepwise rest.
    #[test]
    fn settle_guess_follows_its_rule() {
        for k in 0..=12u32 {
            for limit in 0..=12u32 {
                for m in 0..=limit {
                    let answer = k.min(limit);
                    let expect = if m > k {
                        (m - k <= GUESS_STEPS).then_some(answer)
                    } else {
                        (answer - m < GUESS_STEPS).then_some(answer)
                    };
                    let meets = |n: u32| n <= k;
                    assert_eq!(
                        settle_guess(m, limit, meets, meets),
                        expect,
                        "k {k}, limit {limit}, guess {m}"
                    );
                }
            }
        }
    }
}

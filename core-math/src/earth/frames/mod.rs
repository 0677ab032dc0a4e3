//! The satellite bus's own frames (`shared/EARTH-MODEL.md`, Part II): GPS time to TT and
//! UT1, the celestial-to-terrestrial matrix C2T (GCRF to ITRF, polar motion zero), and
//! exact geodetic coordinates. Building blocks only: f64, `libm`, no allocation, every
//! refusal a [`crate::ModelError`].
//!
//! One file per family of functions, each following a SOFA routine (cited on each
//! function; SOFA's source is the authority for every coefficient):
//! - [`time`]: [`TimeScales`], GPS seconds to TT and UT1 as split days since J2000.0;
//! - [`fw`]: IAU 2006 bias-precession, Fukushima-Williams angles (`iauObl06`,
//!   `iauPfw06`, `iauFw2m`);
//! - [`nutation`]: IAU 2000B nutation, 77 luni-solar terms (`iauNut00b`);
//! - [`cio`]: the CIO locator s (`iauS06`, truncated below 1 microarcsecond);
//! - [`era`]: the Earth rotation angle (`iauEra00`) and the TIO locator s' (`iauSp00`);
//! - [`c2t`](mod@c2t): the matrix itself (`iauC2ixys`, `iauC2tcio`, as `iauC2t06a`), with its
//!   documented error [`C2T_TOLERANCE_RAD`] against `iauC2t06a`;
//! - [`geodetic`]: geodetic latitude, longitude and height from ITRF positions
//!   (Vermeille's closed form) and back (as `iauGd2gce`).

pub mod c2t;
pub mod cio;
pub mod era;
pub mod fw;
pub mod geodetic;
pub mod nutation;
mod rot;
pub mod time;

pub use c2t::{
    c2t, c2t_from_cio, c2t_from_dates, CelestialPole, C2T_TOLERANCE_RAD, POLE_MAX_AGE_S,
};
pub use geodetic::{geodetic_from_itrf, itrf_from_geodetic};
pub use rot::{mul as mat_mul, row_times, Mat3};
pub use time::{JulianDays, TimeScales};

/// Arcseconds to radians (SOFA's `DAS2R`, 4.848136811095359935899141e-6, to the nearest
/// f64).
pub const ARCSEC_TO_RAD: f64 = 4.848_136_811_095_36e-6;
/// 2 pi (SOFA's `D2PI`).
pub const TWO_PI: f64 = core::f64::consts::TAU;
/// Arcseconds in a full circle (SOFA's `TURNAS`).
pub const TURN_ARCSEC: f64 = 1_296_000.0;
/// Days in a Julian century (SOFA's `DJC`).
pub const DAYS_PER_JULIAN_CENTURY: f64 = 36_525.0;

/// c0 + (c1 + (c2 + (c3 + (c4 + c5 t) t) t) t) t: SOFA's nesting of its polynomials in
/// t, the same operations in the same order (so the same bits). Out of line: the
/// precession angles, the obliquity and s each held a copy of the soft-float chain
/// (docs/target.md, flash).
#[inline(never)]
pub(crate) fn poly5(t: f64, c: &[f64; 6]) -> f64 {
    let mut acc = c[5];
    for ck in c[..5].iter().rev() {
        acc = ck + acc * t;
    }
    acc
}

/// x mod y with the sign of x, as C's `fmod`, for finite x and finite y > 0 (NaN
/// otherwise): exact, so equal to `libm::fmod` wherever that is defined, but without
/// its panic paths (libm 0.2.16's generic `fmod` keeps a division-by-zero panic that
/// the flight binary's no-panic proof cannot remove, docs/no-panic.md) and without its
/// 2.9 KB of code.
///
/// Binary long division: with s = y 2^k the largest such multiple not above r, each
/// step r - s with s <= r < 2 s is exact (Sterbenz), and so is every halving of s
/// down to y. At most log2(x / y) + 1 steps (16 for the largest argument here,
/// 43 825 days against 1 day).
#[inline(always)]
pub(crate) fn fmod(x: f64, y: f64) -> f64 {
    rem_trunc(x, y).0
}

/// [`fmod`]'s remainder and whether the truncated quotient |x| / y is odd. Out of line:
/// soft-float f64 makes it long, and inlined it came to eight copies.
#[inline(never)]
fn rem_trunc(x: f64, y: f64) -> (f64, bool) {
    let mut r = libm::fabs(x);
    if !(r.is_finite() && y.is_finite() && y > 0.0) {
        return (f64::NAN, false);
    }
    let mut odd = false;
    if r >= y {
        let mut s = y;
        // s * 2 overflows to infinity before it could pass a finite r: the loop ends.
        while s * 2.0 <= r {
            s *= 2.0;
        }
        while s >= y {
            // The last step, s = y, is the quotient's lowest bit.
            (r, odd) = take_away(r, s);
            s *= 0.5;
        }
    }
    (libm::copysign(r, x), odd)
}

/// One step of [`rem_trunc`]'s long division: r - s and true if s <= r, else r and
/// false. Out of line: a call in the loop keeps LLVM from unrolling it (four soft-float
/// copies of the step before: docs/target.md, flash).
#[inline(never)]
fn take_away(r: f64, s: f64) -> (f64, bool) {
    if r >= s {
        (r - s, true)
    } else {
        (r, false)
    }
}

/// x - n y with n the integer nearest x / y, ties to even, as IEEE 754's (and C's)
/// `remainder`, for finite x and finite y > 0 (NaN otherwise): exact, so equal to
/// `libm::remainder` wherever that is defined, without its 712 bytes of code. From
/// `fmod`'s r: |r| - y when |r| > y / 2, or |r| = y / 2 and the truncated quotient is
/// odd (exact: y / 2 < |r| < y), with the sign of x.
pub fn remainder(x: f64, y: f64) -> f64 {
    let (r, odd) = rem_trunc(x, y);
    let a = libm::fabs(r);
    let half = 0.5 * y;
    if a > half || (a == half && odd) {
        let m = a - y;
        if x < 0.0 {
            -m
        } else {
            m
        }
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    /// The exact remainders (truncated and nearest) against libm's over the arguments
    /// the frames reduce and random ones: bit for bit.
    #[test]
    fn fmod_and_remainder_match_libm_bit_for_bit() {
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let ys = [
            86_400.0,
            1.0,
            super::TWO_PI,
            super::TURN_ARCSEC,
            0.3,
            7.0e-3,
        ];
        for _ in 0..200_000 {
            let bits = next();
            let mag = (bits >> 11) as f64 / (1u64 << 53) as f64;
            let exp = (next() % 80) as i32 - 20;
            let x = mag * libm::pow(2.0, f64::from(exp)) * if bits & 1 == 0 { 1.0 } else { -1.0 };
            for y in ys {
                let (a, b) = (super::fmod(x, y), libm::fmod(x, y));
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "fmod({x:e}, {y:e}): {a:e} vs {b:e}"
                );
                let (a, b) = (super::remainder(x, y), libm::remainder(x, y));
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "remainder({x:e}, {y:e}): {a:e} vs {b:e}"
                );
            }
        }
        // Halfway cases (ties to the even quotient) and the f32 yaws of every size the
        // controller wraps.
        for y in [1.0, 2.0, 0.75] {
            for k in -50..50 {
                let x = (f64::from(k) + 0.5) * y;
                let (a, b) = (super::remainder(x, y), libm::remainder(x, y));
                assert_eq!(a.to_bits(), b.to_bits(), "remainder({x:e}, {y:e})");
            }
        }
        let mut x = f32::MIN_POSITIVE;
        while x < f32::MAX {
            for v in [f64::from(x), -f64::from(x)] {
                let (a, b) = (
                    super::remainder(v, super::TWO_PI),
                    libm::remainder(v, super::TWO_PI),
                );
                assert_eq!(a.to_bits(), b.to_bits(), "remainder({v:e}, 2 pi)");
            }
            x = f32::from_bits(x.to_bits() + 1_009);
        }
        assert!(super::fmod(1.0, 0.0).is_nan());
        assert!(super::remainder(1.0, 0.0).is_nan());
        assert!(super::remainder(f64::NAN, 1.0).is_nan());
        assert!(super::fmod(f64::INFINITY, 1.0).is_nan());
        assert_eq!(super::fmod(-0.0, 1.0).to_bits(), (-0.0f64).to_bits());
    }
}

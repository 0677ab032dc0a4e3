//! The CIO locator s, IAU 2006/2000A (Capitaine, Wallace & Chapront 2003; IERS
//! Conventions 2003), as SOFA's `iauS06`, truncated for 2000-2050.
//!
//! `iauS06` sums a series for s + XY/2 (a polynomial and 66 periodic terms in t^0..t^4)
//! and subtracts XY/2. Kept here: the whole polynomial and the 17 periodic terms whose
//! size over 2000-2050 (|coefficient| (t/century)^k, t <= 0.51) is at least
//! 1 microarcsecond. Dropped: the other 49 terms, together at most
//! [`S06_TRUNCATION_BOUND_RAD`]. The terms kept depend on the five Delaunay arguments
//! only, taken as in [`super::nutation::delaunay`] (Simon et al. 1994, linear in t)
//! rather than `iauS06`'s IERS 2003 polynomials: their quadratic and higher parts move
//! the largest term (2640.73 microarcsecond) by below 1e-12 rad by 2050.

use super::nutation::{argument, delaunay};
use super::ARCSEC_TO_RAD;

/// Bound (rad) on the dropped part of the series over 2000-2050: the sum of the
/// amplitudes of the 49 terms dropped, each at t = 0.51 century, 10.65 microarcseconds.
pub const S06_TRUNCATION_BOUND_RAD: f64 = 10.65e-6 * ARCSEC_TO_RAD;

/// A periodic term: multipliers of l, l', F, D, Om; sine and cosine coefficients
/// (microarcseconds).
type Term = ([i8; 5], f64, f64);

/// The polynomial part of s + XY/2 (microarcseconds, t^0..t^5), all of `iauS06`'s.
const SP: [f64; 6] = [94.00, 3808.65, -122.68, -72574.11, 27.98, 15.62];

/// Terms of order t^0: `iauS06`'s 1-10 (of 33).
#[rustfmt::skip]
const S0: [Term; 10] = [
    ([0, 0, 0, 0, 1], -2640.73, 0.39),
    ([0, 0, 0, 0, 2], -63.53, 0.02),
    ([0, 0, 2, -2, 3], -11.75, -0.01),
    ([0, 0, 2, -2, 1], -11.21, -0.01),
    ([0, 0, 2, -2, 2], 4.57, 0.00),
    ([0, 0, 2, 0, 3], -2.02, 0.00),
    ([0, 0, 2, 0, 1], -1.98, 0.00),
    ([0, 0, 0, 0, 3], 1.72, 0.00),
    ([0, 1, 0, 0, 1], 1.41, 0.01),
    ([0, 1, 0, 0, -1], 1.26, 0.01),
];

/// Terms of order t^1: `iauS06`'s 1 (of 3).
const S1: [Term; 1] = [([0, 0, 0, 0, 2], -0.07, 3.57)];

/// Terms of order t^2: `iauS06`'s 1-5 (of 25).
#[rustfmt::skip]
const S2: [Term; 5] = [
    ([0, 0, 0, 0, 1], 743.52, -0.17),
    ([0, 0, 2, -2, 2], 56.91, 0.06),
    ([0, 0, 2, 0, 2], 9.84, -0.01),
    ([0, 0, 0, 0, 2], -8.85, 0.01),
    ([0, 1, 0, 0, 0], -6.38, -0.05),
];

/// Terms of order t^3: `iauS06`'s 1 (of 4). (t^4: none of the one term is kept.)
const S3: [Term; 1] = [([0, 0, 0, 0, 1], 0.30, -23.42)];

fn sum(terms: &[Term], fa: &[f64; 5]) -> f64 {
    let mut w = 0.0;
    for (n, s, c) in terms.iter().rev() {
        let (sa, ca) = crate::trig_f64::sin_cos(argument(n, fa));
        w += s * sa + c * ca;
    }
    w
}

/// The CIO locator s (rad) at `t` Julian centuries TT since J2000.0, given the CIP's
/// X, Y at that date (SOFA `iauS06`, truncated as the module says).
pub fn s06(t: f64, x: f64, y: f64) -> f64 {
    let fa = delaunay(t);
    let w0 = SP[0] + sum(&S0, &fa);
    let w1 = SP[1] + sum(&S1, &fa);
    let w2 = SP[2] + sum(&S2, &fa);
    let w3 = SP[3] + sum(&S3, &fa);
    let (w4, w5) = (SP[4], SP[5]);
    (w0 + (w1 + (w2 + (w3 + (w4 + w5 * t) * t) * t) * t) * t) * (ARCSEC_TO_RAD * 1.0e-6)
        - x * y / 2.0
}

//! The CIO locator s, IAU 2006/2000A (Capitaine, Wallace & Chapront 2003; IERS
//! Conventions 2003), as SOFA's `iauS06`, truncated for 2000-2050.
//!
//! `iauS06` sums a series for s + XY/2 (a polynomial and 66 periodic terms in t^0..t^4)
//! and subtracts XY/2. Kept here: the whole polynomial and the three periodic terms
//! whose size over 2000-2050 (|coefficient| (t/century)^k, t <= 0.51) exceeds 60
//! microarcseconds, all three in the Moon's node Om alone (sin Om and cos Om at t^0 and
//! t^2, sin 2 Om at t^0): one sine and cosine for the whole series. Dropped: the other
//! 63 terms, together at most [`S06_TRUNCATION_BOUND_RAD`], 3.5e-10 rad, 1/140 of the
//! issue's 1e-7 rad for C2T (docs/target.md, flash: the 17-term form took 2 KB more).
//! Om is taken as in [`super::nutation::delaunay`] (Simon et al. 1994, linear in t)
//! rather than `iauS06`'s IERS 2003 polynomial: its quadratic and higher parts move the
//! largest term (2640.73 microarcsecond) by below 1e-12 rad by 2050.

use super::nutation::delaunay;
use super::ARCSEC_TO_RAD;

/// Bound (rad) on the dropped part of the series over 2000-2050, the sum of the
/// amplitudes (|sine| + |cosine| coefficient) of the 63 terms dropped, each at t = 0.51
/// century: 72.97 microarcseconds. Of it, the 49 smallest terms 10.65; `iauS06`'s t^0
/// terms 3-10 35.96 ((0,0,2,-2,3) -11.75, (0,0,2,-2,1) -11.21, (0,0,2,-2,2) 4.57,
/// (0,0,2,0,3) -2.02, (0,0,2,0,1) -1.98, (0,0,0,0,3) 1.72, (0,1,0,0,1) 1.41,
/// (0,1,0,0,-1) 1.26, with their cosines); t^1 term 1, 3.64 x 0.51; t^2 terms 2-5,
/// 82.11 x 0.51^2; t^3 term 1, 23.72 x 0.51^3.
pub const S06_TRUNCATION_BOUND_RAD: f64 = 72.97e-6 * ARCSEC_TO_RAD;

/// The polynomial part of s + XY/2 (microarcseconds, t^0..t^5), all of `iauS06`'s.
const SP: [f64; 6] = [94.00, 3808.65, -122.68, -72574.11, 27.98, 15.62];

/// The CIO locator s (rad) at `t` Julian centuries TT since J2000.0, given the CIP's
/// X, Y at that date (SOFA `iauS06`, truncated as the module says).
pub fn s06(t: f64, x: f64, y: f64) -> f64 {
    let om = delaunay(t)[4];
    let (s1, c1) = crate::trig_f64::sin_cos(om);
    // sin 2 Om and cos 2 Om by the double angle: one sine and cosine for all three terms.
    let (s2, c2) = (2.0 * s1 * c1, (c1 - s1) * (c1 + s1));
    // `iauS06`'s t^0 terms 1 and 2 and its t^2 term 1 (microarcseconds).
    let w0 = SP[0] + (-2640.73 * s1 + 0.39 * c1) + (-63.53 * s2 + 0.02 * c2);
    let w2 = SP[2] + (743.52 * s1 - 0.17 * c1);
    let w = [w0, SP[1], w2, SP[3], SP[4], SP[5]];
    super::poly5(t, &w) * (ARCSEC_TO_RAD * 1.0e-6) - x * y / 2.0
}

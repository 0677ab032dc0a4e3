//! The Earth rotation angle and the TIO locator, as SOFA's `iauEra00` and `iauSp00`.

use super::time::JulianDays;
use super::{ARCSEC_TO_RAD, TWO_PI};

/// The Earth rotation angle (rad, in [0, 2 pi)) at UT1 (IAU 2000, Capitaine et al. 2000;
/// IERS Conventions 2003, Chap. 5, Eq. 14), as SOFA `iauEra00`:
/// ERA = 2 pi (f + 0.7790572732640 + 0.00273781191135448 Tu), Tu the days since J2000.0
/// UT1 and f its fractional part, taken from each half of the split date so that the
/// integer turns never enter.
pub fn era00(ut1: &JulianDays) -> f64 {
    let tu = ut1.days();
    let f = super::fmod(ut1.whole_d, 1.0) + super::fmod(ut1.frac_d, 1.0);
    let theta = super::fmod(
        TWO_PI * (f + 0.779_057_273_264_0 + 0.002_737_811_911_354_48 * tu),
        TWO_PI,
    );
    if theta < 0.0 {
        theta + TWO_PI
    } else {
        theta
    }
}

/// The TIO locator s' (rad) at `t` Julian centuries TT since J2000.0, as SOFA `iauSp00`:
/// -47 microarcseconds per century (its secular part, IERS Conventions 2003).
pub fn sp00(t: f64) -> f64 {
    -47.0e-6 * t * ARCSEC_TO_RAD
}

//! IAU 2006 bias-precession in the Fukushima-Williams four-angle form (Hilton et al.
//! 2006, Celest. Mech. Dyn. Astron. 94, 351), as SOFA's `iauObl06`, `iauPfw06` and
//! `iauFw2m`.

use super::rot::{rx, rz, Mat3, IDENTITY};
use super::ARCSEC_TO_RAD;

/// The four Fukushima-Williams angles (rad): with e the J2000.0 ecliptic pole, p the
/// GCRS pole, E the mean ecliptic pole of date and P the mean pole of date,
/// gamma_bar = epE, phi_bar = pE, psi_bar = pEP, epsilon_A = EP.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FwAngles {
    pub gamb_rad: f64,
    pub phib_rad: f64,
    pub psib_rad: f64,
    pub epsa_rad: f64,
}

/// The angles' polynomials in t (arcseconds, t^0..t^5), as `iauObl06` and `iauPfw06`
/// state them.
const OBL06: [f64; 6] = [
    84_381.406,
    -46.836_769,
    -0.000_183_1,
    0.002_003_40,
    -0.000_000_576,
    -0.000_000_043_4,
];
const GAMB: [f64; 6] = [
    -0.052_928,
    10.556_378,
    0.493_204_4,
    -0.000_312_38,
    -0.000_002_788,
    0.000_000_026_0,
];
const PHIB: [f64; 6] = [
    84_381.412_819,
    -46.811_016,
    0.051_126_8,
    0.000_532_89,
    -0.000_000_440,
    -0.000_000_017_6,
];
const PSIB: [f64; 6] = [
    -0.041_775,
    5_038.481_484,
    1.558_417_5,
    -0.000_185_22,
    -0.000_026_452,
    -0.000_000_014_8,
];

/// Mean obliquity of the ecliptic, IAU 2006 (rad), at `t` Julian centuries TT since
/// J2000.0 (SOFA `iauObl06`).
pub fn obl06(t: f64) -> f64 {
    super::poly5(t, &OBL06) * ARCSEC_TO_RAD
}

/// The P03 bias-precession angles at `t` Julian centuries TT since J2000.0 (SOFA
/// `iauPfw06`).
pub fn pfw06(t: f64) -> FwAngles {
    FwAngles {
        gamb_rad: super::poly5(t, &GAMB) * ARCSEC_TO_RAD,
        phib_rad: super::poly5(t, &PHIB) * ARCSEC_TO_RAD,
        psib_rad: super::poly5(t, &PSIB) * ARCSEC_TO_RAD,
        epsa_rad: obl06(t),
    }
}

/// The rotation matrix R1(-eps) R3(-psi) R1(phib) R3(gamb) of Fukushima-Williams angles
/// (SOFA `iauFw2m`). With psi = psib + dpsi and eps = epsa + deps it is the
/// bias-precession-nutation matrix NPB (GCRS to true equator and equinox of date).
pub fn fw2m(gamb: f64, phib: f64, psi: f64, eps: f64) -> Mat3 {
    let r = rz(gamb, &IDENTITY);
    let r = rx(phib, &r);
    let r = rz(-psi, &r);
    rx(-eps, &r)
}

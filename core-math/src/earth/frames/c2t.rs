//! The celestial-to-terrestrial matrix C2T (GCRS to ITRS, polar motion zero) of
//! `shared/EARTH-MODEL.md`, Part II: SOFA's `iauC2t06a(TT, UT1, 0, 0)` rebuilt from IAU
//! 2006 precession, IAU 2000B nutation and a truncated s, CIO based:
//!
//! C2T = R3(s') R3(ERA) C2I(X, Y, s)  (SOFA's R3(a) turns the frame by a about z)
//!
//! with X, Y the CIP from NPB = `iauFw2m`(`iauPfw06` + `iauNut00b` with `iauNut06a`'s
//! P03 adjustments), s from `iauS06` (truncated), ERA from `iauEra00` and s' from
//! `iauSp00`. Against `iauC2t06a` (IAU 2000A nutation, full s) its error, the angle of
//! the rotation C2T^T C2T_sofa, stays below [`C2T_TOLERANCE_RAD`] over 2000-2050:
//! IAU 2000B's 1 mas (5e-9 rad) dominates, the truncation of s adds 3.5e-10 rad at
//! most.

use super::cio::s06;
use super::era::{era00, sp00};
use super::fw::{fw2m, pfw06};
use super::nutation::nut06b;
use super::rot::{rz, Mat3};
use super::time::{tt_from_gps_s, ut1_from_gps_s, JulianDays, TimeScales};
use crate::error::ModelError;

/// Documented error of [`c2t`] against SOFA's `iauC2t06a(TT, UT1, 0, 0)` over
/// 2000-2050: the rotation angle of C2T^T C2T_sofa (rad). Measured maximum over the
/// ERFA goldens (`core-math/tests/data/erfa_c2t.csv`, 314 instants), printed by
/// `cargo test --release -p core-math --test frames -- --nocapture`: see
/// `docs/earth-model.md`, "Earth orientation (Part II)".
pub const C2T_TOLERANCE_RAD: f64 = 1.0e-8;

/// The celestial-to-intermediate matrix from the CIP's X, Y and the CIO locator s (SOFA
/// `iauC2ixys`): R3(-(E + s)) R2(d) R3(E), E = atan2(Y, X), d = atan(sqrt(r2 / (1 - r2))),
/// r2 = X^2 + Y^2. Formed, as IERS Conventions (2010) Eq. 5.10 writes it, without the
/// angles: R3(-E) R2(d) R3(E) has rows (1 - a X^2, -a X Y, -X), (-a X Y, 1 - a Y^2, -Y),
/// (X, Y, Z) with Z = cos d = sqrt(1 - r2) and a = 1 / (1 + Z). The same matrix to
/// rounding, and no arctangent in the flight binary for it (docs/target.md, flash).
pub fn c2ixys(x: f64, y: f64, s: f64) -> Mat3 {
    let z = libm::sqrt(1.0 - (x * x + y * y));
    let a = 1.0 / (1.0 + z);
    let (ax, ay) = (a * x, a * y);
    let m = [
        [1.0 - ax * x, -ax * y, -x],
        [-ax * y, 1.0 - ay * y, -y],
        [x, y, z],
    ];
    rz(-s, &m)
}

/// C2T at the given TT and UT1 (days since J2000.0 in each scale), polar motion zero,
/// following `iauC2t06a` with the substitutions of the module. No checks (any finite
/// dates give a finite rotation); [`c2t`] is the checked entry.
pub fn c2t_from_dates(tt: &JulianDays, ut1: &JulianDays) -> Mat3 {
    let t = tt.centuries();
    let (x, y) = cip(t);
    c2t_from_cio(x, y, s06(t, x, y), era00(ut1), sp00(t))
}

/// The CIP's X, Y at `t` Julian centuries TT since J2000.0: bias-precession-nutation
/// (`iauPnm06a` with `iauNut00b` for `iauNut00a`), then `iauBpn2xy`.
fn cip(t: f64) -> (f64, f64) {
    let fw = pfw06(t);
    let (dpsi, deps) = nut06b(t);
    let npb = fw2m(
        fw.gamb_rad,
        fw.phib_rad,
        fw.psib_rad + dpsi,
        fw.epsa_rad + deps,
    );
    (npb[2][0], npb[2][1])
}

/// C2T = R3(s') R3(ERA) C2I(X, Y, s) from the CIP's X, Y, the CIO locator s, the Earth
/// rotation angle and the TIO locator s' (rad): SOFA `iauC2ixys`, then `iauC2tcio` with
/// rpom = `iauPom00`(0, 0, s') = R3(s').
pub fn c2t_from_cio(x: f64, y: f64, s: f64, era: f64, sp: f64) -> Mat3 {
    let r = rz(era, &c2ixys(x, y, s));
    rz(sp, &r)
}

/// The celestial-to-terrestrial matrix at `gps_s` (seconds since 1980-01-06T00:00:00
/// GPS): r_ITRF = C2T r_GCRF. TT and UT1 from [`super::time`]. Refusals: `gps_s` not
/// finite or outside 0..=[`super::time::GPS_S_MAX`] (`GpsTime`), and those of
/// [`TimeScales::validate`].
pub fn c2t(gps_s: f64, scales: &TimeScales) -> Result<Mat3, ModelError> {
    let tt = tt_from_gps_s(gps_s)?;
    let ut1 = ut1_from_gps_s(gps_s, scales)?;
    Ok(c2t_from_dates(&tt, &ut1))
}

/// How long the slowly moving part of C2T ([`CelestialPole`]) may be reused (s): its
/// motion (precession 7.7e-12 rad/s, nutation's fastest terms 5e-12 rad/s) moves it by
/// 5.1e-10 rad at most in that time (measured over the ERFA goldens), so that C2T from
/// it stays within [`C2T_TOLERANCE_RAD`] of `iauC2t06a` (4.2e-9 rad with IAU 2000B's
/// 3.9e-9; `cargo test --release -p core-math --test frames -- --nocapture`).
pub const POLE_MAX_AGE_S: f64 = 60.0;

/// The part of C2T that moves slowly: the celestial-to-intermediate matrix C2I(X, Y, s)
/// and the TIO locator s' at one instant. C2T at a later instant within
/// [`POLE_MAX_AGE_S`] is R3(s') R3(ERA(t)) C2I: the Earth rotation angle alone, a
/// handful of f64 operations, instead of the nutation series' 77 terms. What a
/// controller computes once a minute and per update respectively.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CelestialPole {
    /// The instant it was computed for (s of GPS time).
    pub gps_s: f64,
    pub c2i: Mat3,
    pub sp_rad: f64,
}

impl CelestialPole {
    /// The pole at `gps_s`; the refusals of [`c2t`].
    pub fn at(gps_s: f64, scales: &TimeScales) -> Result<Self, ModelError> {
        let tt = tt_from_gps_s(gps_s)?;
        scales.validate()?;
        let t = tt.centuries();
        let (x, y) = cip(t);
        Ok(CelestialPole {
            gps_s,
            c2i: c2ixys(x, y, s06(t, x, y)),
            sp_rad: sp00(t),
        })
    }

    /// C2T at `gps_s` from this pole and the Earth rotation angle at `gps_s`. Refusals:
    /// those of [`ut1_from_gps_s`]. The caller keeps |gps_s - self.gps_s| within
    /// [`POLE_MAX_AGE_S`]; further away the error grows by about 2e-11 rad a second.
    pub fn c2t(&self, gps_s: f64, scales: &TimeScales) -> Result<Mat3, ModelError> {
        let ut1 = ut1_from_gps_s(gps_s, scales)?;
        Ok(rz(self.sp_rad, &rz(era00(&ut1), &self.c2i)))
    }
}

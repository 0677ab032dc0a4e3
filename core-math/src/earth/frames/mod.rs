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
pub use rot::Mat3;
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

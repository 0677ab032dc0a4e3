//! Time scales of Part II (`shared/EARTH-MODEL.md`, "Time"): `gps_s`, seconds of GPS time
//! since 1980-01-06T00:00:00 GPS; TT = GPS + 51.184 s; UTC = GPS - `gps_utc_s`;
//! UT1 = UTC + `dut1_s`.
//!
//! Dates leave this module as [`JulianDays`], days since J2000.0 (JD 2451545.0 in the
//! date's own scale) split into whole days and a fraction, so that no step adds a
//! fraction of a day to 2.45e6 in one f64 (which would round it to 4e-5 s). What is
//! left is `gps_s`'s own resolution as an f64: 1.2e-7 s up to 2014, 2.4e-7 s up to
//! 2048 (half an ulp of 1.1e9 and 2.1e9), 1.7e-11 rad of Earth rotation.

use crate::error::{ModelError, Param};

/// Seconds in a day.
pub const DAY_S: f64 = 86_400.0;
/// TT - GPS (s): TT - TAI = 32.184 s, TAI - GPS = 19 s.
pub const TT_MINUS_GPS_S: f64 = 51.184;
/// J2000.0 (2000-01-01T12:00:00 in its scale) is 7300.5 days after the GPS epoch
/// 1980-01-06T00:00:00: the whole days, the half day being added to the fraction.
pub const J2000_WHOLE_DAYS_FROM_GPS_EPOCH: f64 = 7_300.0;
/// The Julian date of J2000.0 (SOFA's `DJ00`).
pub const JD_J2000: f64 = 2_451_545.0;
/// Largest `gps_s` accepted: 2100-01-01T00:00:00 GPS (43 825 days after the GPS
/// epoch). The series are meant for 1900-2100; [`super::C2T_TOLERANCE_RAD`] is measured
/// over 2000-2050 only.
pub const GPS_S_MAX: f64 = 43_825.0 * DAY_S;
/// Largest |`dut1_s`| (s): UTC is kept within 0.9 s of UT1 by definition.
pub const MAX_ABS_DUT1_S: f64 = 0.9;
/// Largest `gps_utc_s` accepted (s): 18 since 2017, 0 at the GPS epoch; 60 leaves room
/// for every leap second the current rate of one per 1.5 years could add before 2100.
pub const MAX_GPS_UTC_S: f64 = 60.0;

/// Days since J2000.0 in some time scale, split for precision: `whole_d` an integer
/// number of days, `frac_d` the rest (|frac_d| < 1.5). The date is whole_d + frac_d.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JulianDays {
    pub whole_d: f64,
    pub frac_d: f64,
}

impl JulianDays {
    /// The date as SOFA's two-part Julian date (date1, date2) = (2451545 + whole, frac).
    pub fn jd(&self) -> (f64, f64) {
        (JD_J2000 + self.whole_d, self.frac_d)
    }

    /// Days since J2000.0 in one f64 (rounded to about 4e-12 days near 2050).
    pub fn days(&self) -> f64 {
        self.whole_d + self.frac_d
    }

    /// Julian centuries since J2000.0 (SOFA's `t = ((date1 - DJ00) + date2) / DJC`).
    pub fn centuries(&self) -> f64 {
        self.days() / super::DAYS_PER_JULIAN_CENTURY
    }
}

/// GPS - UTC and UT1 - UTC, the two numbers besides GPS time that fix TT and UT1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeScales {
    /// GPS - UTC (s): the leap seconds since 1980, an integer (18 since 2017-01-01).
    pub gps_utc_s: f64,
    /// UT1 - UTC (s), |dut1_s| < 0.9 (IERS Bulletin A).
    pub dut1_s: f64,
}

impl Default for TimeScales {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl TimeScales {
    /// The contract's defaults: 18 leap seconds, DUT1 = 0.
    pub const DEFAULT: TimeScales = TimeScales {
        gps_utc_s: 18.0,
        dut1_s: 0.0,
    };

    /// Checks both numbers. Refusals: [`ModelError::NonFinite`] for NaN or an infinity;
    /// `gps_utc_s` not an integer, [`ModelError::InvalidInput`]`(LeapSeconds)` (leap
    /// seconds are whole seconds; a fraction is a DUT1 put in the wrong column);
    /// `gps_utc_s` outside 0..=[`MAX_GPS_UTC_S`], [`ModelError::OutOfDomain`]`(LeapSeconds)`;
    /// |`dut1_s`| >= 0.9 s, [`ModelError::InvalidInput`]`(Dut1)` (UTC is defined within
    /// 0.9 s of UT1).
    // Out of line: a cold check inlined into four callers (docs/target.md, flash).
    #[inline(never)]
    pub fn validate(&self) -> Result<(), ModelError> {
        if !self.gps_utc_s.is_finite() {
            return Err(ModelError::NonFinite(Param::LeapSeconds));
        }
        if !self.dut1_s.is_finite() {
            return Err(ModelError::NonFinite(Param::Dut1));
        }
        if libm::trunc(self.gps_utc_s) != self.gps_utc_s {
            return Err(ModelError::InvalidInput(Param::LeapSeconds));
        }
        if !(0.0..=MAX_GPS_UTC_S).contains(&self.gps_utc_s) {
            return Err(ModelError::OutOfDomain(Param::LeapSeconds));
        }
        if !(libm::fabs(self.dut1_s) < MAX_ABS_DUT1_S) {
            return Err(ModelError::InvalidInput(Param::Dut1));
        }
        Ok(())
    }
}

/// Checks `gps_s`: finite ([`ModelError::NonFinite`]`(GpsTime)`) and within
/// 0..=[`GPS_S_MAX`] ([`ModelError::OutOfDomain`]`(GpsTime)`).
pub fn check_gps_s(gps_s: f64) -> Result<(), ModelError> {
    if !gps_s.is_finite() {
        return Err(ModelError::NonFinite(Param::GpsTime));
    }
    if !(0.0..=GPS_S_MAX).contains(&gps_s) {
        return Err(ModelError::OutOfDomain(Param::GpsTime));
    }
    Ok(())
}

/// Days since J2000.0 of the instant `offset_s` seconds after `gps_s` (in the scale in
/// which the offset makes the date: 51.184 s for TT, UT1 - GPS for UT1). `gps_s` is split
/// exactly into whole days and seconds of the day (fmod is exact, and so is the
/// subtraction), so the offset and the half day move the small part only.
// Out of line: the pole's TT and the ATTITUDE frame's UT1 each inlined it
// (docs/target.md, flash).
#[inline(never)]
fn split_days(gps_s: f64, offset_s: f64) -> JulianDays {
    let sec_of_day = super::fmod(gps_s, DAY_S);
    let whole = (gps_s - sec_of_day) / DAY_S;
    JulianDays {
        whole_d: whole - J2000_WHOLE_DAYS_FROM_GPS_EPOCH,
        frac_d: (sec_of_day + offset_s - 0.5 * DAY_S) / DAY_S,
    }
}

/// TT of `gps_s` as days since J2000.0 TT: TT = GPS + 51.184 s.
pub fn tt_from_gps_s(gps_s: f64) -> Result<JulianDays, ModelError> {
    check_gps_s(gps_s)?;
    Ok(split_days(gps_s, TT_MINUS_GPS_S))
}

/// UT1 of `gps_s` as days since J2000.0 UT1: UT1 = GPS - gps_utc_s + dut1_s.
pub fn ut1_from_gps_s(gps_s: f64, scales: &TimeScales) -> Result<JulianDays, ModelError> {
    check_gps_s(gps_s)?;
    scales.validate()?;
    Ok(split_days(gps_s, scales.dut1_s - scales.gps_utc_s))
}

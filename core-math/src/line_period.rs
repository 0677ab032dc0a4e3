//! TDI line period: the time the image takes to cross one pixel along the transfer
//! direction, in seconds and in ticks of the line-clock counter.

use crate::error::{ModelError, Param};
use crate::model::ImageMotion;
use crate::real::Real;

/// Line period (s) from the image motion: the charge moves along P1, so the line rate
/// follows v1 (EARTH-MODEL.md, derived outputs): `pixel_m / |v1|`. The period the
/// controller clocks; the caller has checked that |v1| is not 0.
pub fn line_period_s<T: Real>(pixel_m: T, motion: &ImageMotion<T>) -> T {
    pixel_m / motion.v1_mps.abs()
}

/// A line period as a whole number of clock ticks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ticks<T> {
    pub ticks: u32,
    /// ticks / f_clk - period (s): what rounding to whole ticks changed.
    pub rounding_error_s: T,
}

/// The period rounded to the nearest whole tick of a `clock_hz` counter.
/// Refused unless 1 <= ticks <= `u32::MAX`.
pub fn line_period_ticks<T: Real>(period_s: T, clock_hz: T) -> Result<Ticks<T>, ModelError> {
    if !clock_hz.is_finite() {
        return Err(ModelError::NonFinite(Param::ClockFrequency));
    }
    if !(clock_hz > T::ZERO) {
        return Err(ModelError::OutOfDomain(Param::ClockFrequency));
    }
    if !(period_s > T::ZERO) || !period_s.is_finite() {
        return Err(ModelError::LinePeriodOutOfRange);
    }
    let exact = period_s * clock_hz;
    let ticks = nearest_ticks(exact)?;
    Ok(Ticks {
        ticks,
        rounding_error_s: (T::from_u32(ticks) - exact) / clock_hz,
    })
}

/// A count of `exact_ticks` (period x clock) rounded half up to a whole number of ticks:
/// the rounding of [`line_period_ticks`], for a caller whose period and clock are
/// checked already (the controller: its clock when the scene arrives, each period
/// against the physical bounds). Refused unless 1 <= ticks <= `u32::MAX`; any input,
/// NaN and infinities included, gives a count in that range or the error.
#[inline]
pub fn nearest_ticks<T: Real>(exact_ticks: T) -> Result<u32, ModelError> {
    let exact = exact_ticks;
    // Half up, from the exact fraction: `floor(exact + 0.5)` would round the sum first
    // (0.5 - 1 ulp + 0.5 gives 1.0; in f32 an odd integer above 2^23 plus 0.5 ties to
    // the even one above).
    // Truncation is the floor for exact >= 0 (saturating at u32::MAX, which the range
    // check below then refuses; NaN and negatives give 0, refused too), without the
    // software `floorf` of this core.
    let whole = T::from_u32(exact.to_u32());
    let nearest = if exact - whole >= T::from_f64(0.5) {
        whole + T::ONE
    } else {
        whole
    };
    // Compared as reals before converting, since `as u32` would saturate silently; 2^32
    // is exact in f32 and f64, where u32::MAX rounds to 2^32 in f32.
    if !(nearest >= T::ONE && nearest < T::from_f64(4_294_967_296.0)) {
        return Err(ModelError::LinePeriodOutOfRange);
    }
    Ok(nearest.to_u32())
}

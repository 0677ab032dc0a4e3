//! The round-Earth model's line period, from the image speed.

use crate::error::{ModelError, Param};
use crate::real::Real;

/// The paper's line period A / |v_P| (s, Eq. 16: the whole image speed, v2 included),
/// checked: what the round-Earth backends are compared on. The flown period follows v1
/// alone ([`crate::line_period_s`]).
pub fn speed_line_period_s<T: Real>(pixel_m: T, speed_mps: T) -> Result<T, ModelError> {
    if !pixel_m.is_finite() {
        return Err(ModelError::NonFinite(Param::PixelPitch));
    }
    if !(pixel_m > T::ZERO) {
        return Err(ModelError::NonPositivePixelPitch);
    }
    if !(speed_mps > T::ZERO) {
        return Err(ModelError::NoImageMotion);
    }
    let t = pixel_m / speed_mps;
    if !t.is_finite() {
        return Err(ModelError::NoImageMotion);
    }
    // An infinite speed, or one so large the quotient underflows: no period to clock.
    if !(t > T::ZERO) {
        return Err(ModelError::LinePeriodOutOfRange);
    }
    Ok(t)
}

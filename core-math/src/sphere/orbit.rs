//! From the navigation state vector to the round-Earth model's orbit quantities.
//!
//! The on-board navigation gives the ECI position r (m) and velocity v (m/s), with z the
//! Earth's spin axis. The model needs the altitude, the orbit's angular rate, the
//! inclination i0 and the argument of latitude gamma0 of the sub-satellite point.
//! They come from cross and dot products only, combined by `atan2`, so nothing divides
//! by sin(i0) or by the node vector's length: an equatorial orbit (node undefined) gives
//! gamma0 = atan2(0, 0) = 0, which is harmless because gamma0 enters the model only
//! multiplied by sin(i0) = 0.

use crate::error::{ModelError, Param};
use crate::orbit::StateVector;
use crate::vector::{cross, dot};

/// What the image-motion model needs from the orbit at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitState {
    /// |r| - R (m).
    pub altitude_m: f64,
    /// Angular rate of the radius vector, |r x v| / |r|^2 (rad/s): the rate at which the
    /// orbital frame turns, which is what moves the image (equal to the mean motion on a
    /// circular orbit).
    pub orbit_rate_rad_s: f64,
    /// Inclination in [0, pi] (rad).
    pub inclination_rad: f64,
    /// Argument of latitude in (-pi, pi] (rad), from the ascending node in the direction
    /// of motion.
    pub arg_latitude_rad: f64,
    /// Radial velocity over radius, (r . v) / |r|^2 (1/s): zero on a circular orbit; the
    /// round-Earth model of a circular orbit ignores it, so callers can bound it.
    pub radial_rate_per_s: f64,
}

/// Largest |r| accepted, m (beyond the Moon: nothing real, and no overflow in |r|^2 |v|).
const MAX_POSITION_M: f64 = 1.0e9;
/// Largest |v| accepted, m/s.
const MAX_VELOCITY_MPS: f64 = 1.0e5;

impl OrbitState {
    /// The orbit quantities of a state vector over a round Earth of radius `earth_radius_m`.
    pub fn from_state(sv: &StateVector, earth_radius_m: f64) -> Result<OrbitState, ModelError> {
        let (r, v) = (sv.position_m, sv.velocity_mps);
        if !r.iter().all(|x| x.is_finite()) {
            return Err(ModelError::NonFinite(Param::Position));
        }
        if !v.iter().all(|x| x.is_finite()) {
            return Err(ModelError::NonFinite(Param::Velocity));
        }
        if !earth_radius_m.is_finite() {
            return Err(ModelError::NonFinite(Param::EarthRadius));
        }
        if earth_radius_m <= 0.0 {
            return Err(ModelError::NonPositiveEarthRadius);
        }
        let r2 = dot(r, r);
        let r_norm = libm::sqrt(r2);
        if !(r_norm <= MAX_POSITION_M) {
            return Err(ModelError::OutOfDomain(Param::Position));
        }
        if !(libm::sqrt(dot(v, v)) <= MAX_VELOCITY_MPS) {
            return Err(ModelError::OutOfDomain(Param::Velocity));
        }
        let altitude_m = r_norm - earth_radius_m;
        if !(altitude_m > 0.0) {
            return Err(ModelError::NonPositiveAltitude);
        }
        let h = cross(r, v);
        let h_norm = libm::sqrt(dot(h, h));
        // No transverse motion: no orbital plane, no ground track.
        if !(h_norm > 0.0) {
            return Err(ModelError::OutOfDomain(Param::Velocity));
        }
        // cos i0 = h_z / |h|, sin i0 = |h_xy| / |h|: atan2 of the two, both unnormalised.
        let h_xy = libm::sqrt(h[0] * h[0] + h[1] * h[1]);
        let inclination_rad = libm::atan2(h_xy, h[2]);
        // Node vector n = z x h = (-h_y, h_x, 0), |n| = |h| sin i0; m = h x n lies in the
        // plane 90 deg ahead of the node, |m| = |h|^2 sin i0. gamma0 = atan2(r.m/|h|, r.n):
        // both arguments carry the same factor |h| sin i0 |r|, which atan2 ignores.
        let n = [-h[1], h[0], 0.0];
        let m = cross(h, n);
        let arg_latitude_rad = libm::atan2(dot(r, m) / h_norm, dot(r, n));
        Ok(OrbitState {
            altitude_m,
            orbit_rate_rad_s: h_norm / r2,
            inclination_rad,
            arg_latitude_rad,
            radial_rate_per_s: dot(r, v) / r2,
        })
    }
}

//! Geodetic latitude, longitude and height on an ellipsoid of revolution, exact (to
//! rounding) both ways:
//! - [`itrf_from_geodetic`], as SOFA's `iauGd2gce`;
//! - [`geodetic_from_itrf`], Vermeille's closed form (H. Vermeille, "Direct
//!   transformation from geocentric coordinates to geodetic coordinates", J. Geodesy 76,
//!   451-454, 2002; the rationalised k of Vermeille 2004, J. Geodesy 78, 94-95): the
//!   root of the quartic in closed form, no iteration. (SOFA's `iauGc2gde` is
//!   Fukushima's single Halley step, a different method: the goldens compare the two.)
//!
//! The closed form holds outside the ellipsoid's evolute (the astroid within a e^2 of the
//! centre, 43 km for WGS 84), where every point has one nearest point on the ellipsoid's
//! upper or lower half. The domain keeps well clear of it: flattening at most
//! [`GEODETIC_MAX_FLATTENING`] (the evolute then lies within 0.19 a of the centre) and
//! points with x^2 + y^2 + (1 - e^2) z^2 >= (a/2)^2, that is, no deeper than about a/2
//! below the surface; the centre itself, where latitude has no meaning, is refused
//! with the rest of that inner region.

use crate::earth::{Ellipsoid, MAX_POSITION_M};
use crate::error::{ModelError, Param};
use crate::model::domain;
use crate::real::Real;
use crate::vector::dot;

/// Largest flattening the geodetic conversions accept (WGS 84's is 0.0034).
pub const GEODETIC_MAX_FLATTENING: f64 = 0.1;
/// Smallest (x^2 + y^2 + (1 - e^2) z^2) / a^2 [`geodetic_from_itrf`] accepts.
pub const GEODETIC_MIN_RADIUS2_OVER_A2: f64 = 0.25;
/// Smallest height / a [`itrf_from_geodetic`] accepts: every point of
/// h >= -a/4 lies in [`geodetic_from_itrf`]'s domain.
pub const GEODETIC_MIN_H_OVER_A: f64 = -0.25;
/// Largest |longitude| (rad) [`itrf_from_geodetic`] accepts.
pub const GEODETIC_MAX_ABS_LON_RAD: f64 = 2.0 * core::f64::consts::PI;

/// The ellipsoid's checks: a and f finite ([`ModelError::NonFinite`]), a > 0 and
/// 0 <= f < 1 ([`ModelError::InvalidInput`]), a within the crate's Earth radii and
/// f <= [`GEODETIC_MAX_FLATTENING`] ([`ModelError::OutOfDomain`]). Returns e^2 = f (2 - f).
fn check_ellipsoid(e: &Ellipsoid) -> Result<f64, ModelError> {
    let (a, f) = (e.a_m, e.flattening);
    if !a.is_finite() {
        return Err(ModelError::NonFinite(Param::SemiMajorAxis));
    }
    if !f.is_finite() {
        return Err(ModelError::NonFinite(Param::Flattening));
    }
    if !(a > 0.0) {
        return Err(ModelError::InvalidInput(Param::SemiMajorAxis));
    }
    if !(0.0..1.0).contains(&f) {
        return Err(ModelError::InvalidInput(Param::Flattening));
    }
    let (a_min, a_max) = domain::EARTH_RADIUS_M;
    if !(a >= a_min && a <= a_max) {
        return Err(ModelError::OutOfDomain(Param::SemiMajorAxis));
    }
    if f > GEODETIC_MAX_FLATTENING {
        return Err(ModelError::OutOfDomain(Param::Flattening));
    }
    Ok(f * (2.0 - f))
}

/// The ITRF position (m) of geodetic latitude `lat_rad`, longitude `lon_rad` (east
/// positive) and height `h_m` above the ellipsoid, as SOFA `iauGd2gce`:
/// ((N + h) cos lat cos lon, (N + h) cos lat sin lon, (N (1 - f)^2 + h) sin lat),
/// N = a / sqrt(cos^2 lat + (1 - f)^2 sin^2 lat).
///
/// Refusals: non-finite inputs; |lat| > pi/2 (`InvalidInput(Latitude)`);
/// |lon| > 2 pi (`OutOfDomain(Longitude)`); h below [`GEODETIC_MIN_H_OVER_A`] a or above
/// [`MAX_POSITION_M`] (`OutOfDomain(Height)`); the ellipsoid's (see the module).
pub fn itrf_from_geodetic(
    lat_rad: f64,
    lon_rad: f64,
    h_m: f64,
    ellipsoid: &Ellipsoid,
) -> Result<[f64; 3], ModelError> {
    for (x, p) in [
        (lat_rad, Param::Latitude),
        (lon_rad, Param::Longitude),
        (h_m, Param::Height),
    ] {
        if !x.is_finite() {
            return Err(ModelError::NonFinite(p));
        }
    }
    check_ellipsoid(ellipsoid)?;
    if !(libm::fabs(lat_rad) <= core::f64::consts::FRAC_PI_2) {
        return Err(ModelError::InvalidInput(Param::Latitude));
    }
    if !(libm::fabs(lon_rad) <= GEODETIC_MAX_ABS_LON_RAD) {
        return Err(ModelError::OutOfDomain(Param::Longitude));
    }
    let a = ellipsoid.a_m;
    if !(h_m >= GEODETIC_MIN_H_OVER_A * a && h_m <= MAX_POSITION_M) {
        return Err(ModelError::OutOfDomain(Param::Height));
    }
    let (sp, cp) = crate::trig_f64::sin_cos(lat_rad);
    let (sl, cl) = crate::trig_f64::sin_cos(lon_rad);
    let w = (1.0 - ellipsoid.flattening) * (1.0 - ellipsoid.flattening);
    let ac = a / libm::sqrt(cp * cp + w * sp * sp);
    let r = (ac + h_m) * cp;
    Ok([r * cl, r * sl, (w * ac + h_m) * sp])
}

/// Geodetic (latitude, longitude, height) = (rad, rad, m) of the ITRF position `r_m`:
/// latitude in [-pi/2, pi/2], longitude in [-pi, pi] (atan2(y, x); 0 on the axis), height above the
/// ellipsoid along its normal. Vermeille's closed form (see the module), with
/// p = (x^2 + y^2)/a^2, q = (1 - e^2) z^2/a^2, r = (p + q - e^4)/6,
/// s = e^4 p q / (4 r^3), t = cbrt(1 + s + sqrt(s (2 + s))), u = r (1 + t + 1/t),
/// v = sqrt(u^2 + e^4 q), w = e^2 (u + v - q) / (2 v),
/// k = (u + v) / (sqrt(u + v + w^2) + w), D = k rho / (k + e^2):
/// lat = 2 atan2(z, D + sqrt(D^2 + z^2)), h = (k + e^2 - 1)/k sqrt(D^2 + z^2).
///
/// Refusals: a non-finite or too distant position (`Position`, beyond
/// [`MAX_POSITION_M`]); a position in the inner region about the centre (see the
/// module; `OutOfDomain(Position)`); the ellipsoid's.
pub fn geodetic_from_itrf(
    r_m: [f64; 3],
    ellipsoid: &Ellipsoid,
) -> Result<(f64, f64, f64), ModelError> {
    if !r_m.iter().all(|c| c.is_finite()) {
        return Err(ModelError::NonFinite(Param::Position));
    }
    let e2 = check_ellipsoid(ellipsoid)?;
    if !(dot(r_m, r_m) <= MAX_POSITION_M * MAX_POSITION_M) {
        return Err(ModelError::OutOfDomain(Param::Position));
    }
    let a = ellipsoid.a_m;
    let (x, y, z) = (r_m[0] / a, r_m[1] / a, r_m[2] / a);
    if !(x * x + y * y + (1.0 - e2) * z * z >= GEODETIC_MIN_RADIUS2_OVER_A2) {
        return Err(ModelError::OutOfDomain(Param::Position));
    }
    Ok(geodetic_in(r_m, a, e2))
}

/// [`geodetic_from_itrf`]'s closed form in any [`Real`], without its checks: `a` the
/// semi-major axis (m), `e2` = f (2 - f). The caller keeps the point in the domain (see
/// the module): the DEM search ([`crate::earth::dem`]) evaluates it only in the band of
/// the tile's heights. In f32 the height carries about 1e-7 a (0.6 m) of rounding, from
/// k + e^2 - 1, a difference of terms near 1.
#[inline]
pub fn geodetic_in<T: Real>(r_m: [T; 3], a: T, e2: T) -> (T, T, T) {
    let (one, two) = (T::ONE, T::ONE + T::ONE);
    let (x, y, z) = (r_m[0] / a, r_m[1] / a, r_m[2] / a);
    let rho = x.hypot(y);
    let e4 = e2 * e2;
    let p = rho * rho;
    let q = (one - e2) * z * z;
    // r > 0 in the domain (p + q >= 1/4 > e^4), so s >= 0 and every root is real.
    let r = (p + q - e4) / T::from_f64(6.0);
    let s = e4 * p * q / (T::from_f64(4.0) * r * r * r);
    let t = (one + s + (s * (two + s)).sqrt()).cbrt();
    let u = r * (one + t + one / t);
    let v = (u * u + e4 * q).sqrt();
    let w = e2 * (u + v - q) / (two * v);
    let k = (u + v) / ((u + v + w * w).sqrt() + w);
    let d = k * rho / (k + e2);
    let dz = d.hypot(z);
    let lat = two * z.atan2(d + dz);
    let h = (k + e2 - one) / k * dz * a;
    let lon = if rho > T::ZERO {
        r_m[1].atan2(r_m[0])
    } else {
        T::ZERO
    };
    (lat, lon, h)
}

//! The paper's round-Earth model's inputs: [`Geometry`] (roll, circular orbit, round
//! Earth at one instant) and the model marker [`Sphere`].

use crate::earth::{circular_state, Attitude, EarthGeometry, Ellipsoid};
use crate::error::{ModelError, Param};
use crate::model::{domain, Camera, Model, EARTH_RATE_RAD_S, GM_M3_S2};
use crate::real::{Real, Scalar};

/// Orbit and attitude at one instant. Angles in radians, lengths in metres.
///
/// Conventions (those of the paper's P = M9 ... M1 G): positive roll points the camera
/// to the left of the flight direction, toward the orbit normal; `arg_latitude_rad` is
/// the geocentric angle from the ascending node to the sub-satellite point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry<T> {
    pub roll_rad: T,
    pub inclination_rad: T,
    pub arg_latitude_rad: T,
    pub altitude_m: T,
    pub earth_radius_m: T,
    pub earth_rate_rad_s: T,
    pub orbit_rate_rad_s: T,
}

impl Geometry<f64> {
    /// A geometry with the project's Earth rate and the circular-orbit mean motion
    /// Omega = sqrt(GM / (R + H)^3).
    pub fn circular(
        roll_rad: f64,
        inclination_rad: f64,
        arg_latitude_rad: f64,
        altitude_m: f64,
        earth_radius_m: f64,
    ) -> Self {
        Geometry {
            roll_rad,
            inclination_rad,
            arg_latitude_rad,
            altitude_m,
            earth_radius_m,
            earth_rate_rad_s: EARTH_RATE_RAD_S,
            orbit_rate_rad_s: orbital_rate_rad_s(earth_radius_m, altitude_m),
        }
    }

    /// The same geometry rounded to another scalar type.
    pub fn to<T: Real>(&self) -> Geometry<T> {
        Geometry {
            roll_rad: T::from_f64(self.roll_rad),
            inclination_rad: T::from_f64(self.inclination_rad),
            arg_latitude_rad: T::from_f64(self.arg_latitude_rad),
            altitude_m: T::from_f64(self.altitude_m),
            earth_radius_m: T::from_f64(self.earth_radius_m),
            earth_rate_rad_s: T::from_f64(self.earth_rate_rad_s),
            orbit_rate_rad_s: T::from_f64(self.orbit_rate_rad_s),
        }
    }
}

impl Geometry<f64> {
    /// The real-Earth geometry that is exactly this round-Earth one: a sphere of radius
    /// R (flattening 0), ground height 0, the circular orbit of radius R + H, the roll,
    /// no pitch, yaw or rates. (The orbit rate must be the circular one, as
    /// [`Geometry::circular`] makes it.)
    pub fn to_earth(&self) -> EarthGeometry<f64> {
        EarthGeometry {
            state: circular_state(
                self.earth_radius_m + self.altitude_m,
                self.inclination_rad,
                self.arg_latitude_rad,
            ),
            attitude: Attitude {
                roll_rad: self.roll_rad,
                ..Attitude::default()
            },
            ground_h_m: 0.0,
            ellipsoid: Ellipsoid {
                a_m: self.earth_radius_m,
                flattening: 0.0,
            },
            earth_rate_rad_s: self.earth_rate_rad_s,
        }
    }
}

impl<T: Scalar> Geometry<T> {
    /// The geometry with every field widened to f64 (exact for f32; I24F40 rounded to
    /// nearest, 53 of its 64 bits).
    pub fn to_f64(&self) -> Geometry<f64> {
        Geometry {
            roll_rad: self.roll_rad.to_f64(),
            inclination_rad: self.inclination_rad.to_f64(),
            arg_latitude_rad: self.arg_latitude_rad.to_f64(),
            altitude_m: self.altitude_m.to_f64(),
            earth_radius_m: self.earth_radius_m.to_f64(),
            earth_rate_rad_s: self.earth_rate_rad_s.to_f64(),
            orbit_rate_rad_s: self.orbit_rate_rad_s.to_f64(),
        }
    }
}

impl<T: Real> Geometry<T> {
    /// Checks every field against the model's domain; the backends call it first.
    /// Works in `T` so that the f32 path does no soft-f64 work per update.
    pub fn validate(&self) -> Result<(), ModelError> {
        let angles = [
            (self.roll_rad, Param::Roll),
            (self.inclination_rad, Param::Inclination),
            (self.arg_latitude_rad, Param::ArgLatitude),
        ];
        let max_angle = T::from_f64(domain::MAX_ANGLE_RAD);
        for (x, p) in angles {
            if !x.is_finite() {
                return Err(ModelError::NonFinite(p));
            }
            // Written so that it holds for both signs without an `abs` in the trait.
            if !(x <= max_angle && -x <= max_angle) {
                return Err(ModelError::OutOfDomain(p));
            }
        }
        let max_rate = T::from_f64(domain::MAX_RATE_RAD_S);
        for (x, p) in [
            (self.altitude_m, Param::Altitude),
            (self.earth_radius_m, Param::EarthRadius),
            (self.earth_rate_rad_s, Param::EarthRate),
            (self.orbit_rate_rad_s, Param::OrbitRate),
        ] {
            if !x.is_finite() {
                return Err(ModelError::NonFinite(p));
            }
        }
        for (x, p) in [
            (self.earth_rate_rad_s, Param::EarthRate),
            (self.orbit_rate_rad_s, Param::OrbitRate),
        ] {
            if !(x <= max_rate && -x <= max_rate) {
                return Err(ModelError::OutOfDomain(p));
            }
        }
        if !(self.earth_radius_m > T::ZERO) {
            return Err(ModelError::NonPositiveEarthRadius);
        }
        let (r_min, r_max) = domain::EARTH_RADIUS_M;
        if !(self.earth_radius_m >= T::from_f64(r_min) && self.earth_radius_m <= T::from_f64(r_max))
        {
            return Err(ModelError::OutOfDomain(Param::EarthRadius));
        }
        if !(self.altitude_m > T::ZERO) {
            return Err(ModelError::NonPositiveAltitude);
        }
        // Compared without dividing, so that no radius can overflow or underflow the
        // test; the lower bound keeps h(2+h) a normal number in f32.
        let r = self.earth_radius_m;
        if !(self.altitude_m <= T::from_f64(domain::MAX_ALTITUDE_OVER_RADIUS) * r)
            || self.altitude_m < T::from_f64(domain::MIN_ALTITUDE_OVER_RADIUS) * r
        {
            return Err(ModelError::OutOfDomain(Param::Altitude));
        }
        Ok(())
    }
}

/// Circular-orbit mean motion sqrt(GM / (R + H)^3) in rad/s.
pub fn orbital_rate_rad_s(earth_radius_m: f64, altitude_m: f64) -> f64 {
    let r = earth_radius_m + altitude_m;
    libm::sqrt(GM_M3_S2 / (r * r * r))
}

/// The paper's round-Earth model (a [`crate::Model`]; feature `sphere`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Sphere;

impl Model for Sphere {
    type Camera = Camera;
    type Geometry<T: Scalar> = Geometry<T>;
}

impl Camera {
    /// tan(alpha) = n A / f for a pixel `n_px` pixels from the array centre (Eq. 2),
    /// checked against the domain.
    pub fn tan_field(&self, n_px: f64) -> Result<f64, ModelError> {
        self.validate()?;
        if !n_px.is_finite() {
            return Err(ModelError::NonFinite(Param::PixelOffset));
        }
        let t = n_px * self.pixel_m / self.focal_m;
        if !(t.abs() <= domain::MAX_TAN_FIELD) {
            return Err(ModelError::OutOfDomain(Param::PixelOffset));
        }
        Ok(t)
    }
}

//! The inputs, the output and the one interface every numeric backend implements.

use crate::error::{ModelError, Param};
use crate::real::{Real, Scalar};

/// Earth rotation rate (rad/s), the value the project uses everywhere.
pub const EARTH_RATE_RAD_S: f64 = 7.292_115_9e-5;
/// Earth's gravitational parameter (m^3/s^2).
pub const GM_M3_S2: f64 = 3.986_004_418e14;

/// Limits of the model's domain. Inputs outside are refused with
/// [`ModelError::OutOfDomain`] rather than evaluated: the formulas stay finite inside.
pub mod domain {
    /// Largest altitude as a multiple of the Earth radius (beyond GEO).
    pub const MAX_ALTITUDE_OVER_RADIUS: f64 = 16.0;
    /// Smallest altitude as a multiple of the Earth radius (6 mm for the Earth).
    pub const MIN_ALTITUDE_OVER_RADIUS: f64 = 1.0e-9;
    /// Accepted Earth (body) radius (m): any planet or moon, no absurd scale that
    /// could overflow (R + H)^3 or underflow the ratios.
    pub const EARTH_RADIUS_M: (f64, f64) = (1.0e3, 1.0e8);
    /// Largest focal length (m) and pixel pitch (m): well past any real instrument,
    /// small enough that f (1 + tan^2 alpha) stays finite in f32.
    pub const MAX_FOCAL_M: f64 = 1.0e3;
    pub const MAX_PIXEL_M: f64 = 1.0;
    /// Largest |rate| accepted for the Earth and orbit rates (rad/s).
    pub const MAX_RATE_RAD_S: f64 = 1.0;
    /// Largest |tan(field angle)| = |n A / f| (field angle just under 90 deg).
    pub const MAX_TAN_FIELD: f64 = 1.0e4;
    /// Largest |angle| accepted for roll, inclination, argument of latitude (rad);
    /// beyond it the f32 argument has lost its fractional part.
    pub const MAX_ANGLE_RAD: f64 = 1.0e5;
}

/// The optics: focal length and detector pixel pitch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub focal_m: f64,
    pub pixel_m: f64,
}

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

impl Camera {
    /// Checks the optics; the backends call it before building pixel constants.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !self.focal_m.is_finite() {
            return Err(ModelError::NonFinite(Param::FocalLength));
        }
        if !self.pixel_m.is_finite() {
            return Err(ModelError::NonFinite(Param::PixelPitch));
        }
        if self.focal_m <= 0.0 {
            return Err(ModelError::NonPositiveFocalLength);
        }
        if self.pixel_m <= 0.0 {
            return Err(ModelError::NonPositivePixelPitch);
        }
        if self.focal_m > domain::MAX_FOCAL_M {
            return Err(ModelError::OutOfDomain(Param::FocalLength));
        }
        if self.pixel_m > domain::MAX_PIXEL_M {
            return Err(ModelError::OutOfDomain(Param::PixelPitch));
        }
        Ok(())
    }

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

/// Image-motion velocity on the focal plane, (dP1/dt, dP2/dt) of Eq. 13 at t = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageMotion<T> {
    /// Along P1 (the TDI transfer direction: the image of the along-track motion).
    pub v1_mps: T,
    /// Along P2 (along the line array: the drift).
    pub v2_mps: T,
}

impl<T: Real> ImageMotion<T> {
    /// |v_P| = sqrt(v1^2 + v2^2) (Eq. 16); v2 is at most a few percent of v1, so no
    /// scaling is needed against overflow for any velocity this model produces.
    pub fn speed_mps(&self) -> T {
        (self.v1_mps * self.v1_mps + self.v2_mps * self.v2_mps).sqrt()
    }

    /// The drift angle atan(v2/v1) between the image motion and the TDI transfer
    /// direction (rad; EARTH-MODEL.md, derived outputs). Callers ensure v1 != 0.
    pub fn drift_rad(&self) -> T {
        (self.v2_mps / self.v1_mps).atan()
    }
}

/// What a model is evaluated on: the optics fixed at boot and the geometry of one instant.
///
/// Two models share the one [`Backend`] interface: [`Sphere`], the paper's round Earth
/// (roll only, circular orbit, sea level), and [`crate::earth::Earth`], the real Earth
/// (`../shared/EARTH-MODEL.md`).
pub trait Model {
    /// The optics (known at boot or scene upload).
    type Camera;
    /// Orbit, attitude and Earth at one instant, in a backend's scalar `T`.
    type Geometry<T: Scalar>;
}

/// The paper's round-Earth model (the default of [`Backend`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Sphere;

impl Model for Sphere {
    type Camera = Camera;
    type Geometry<T: Scalar> = Geometry<T>;
}

/// One numeric backend of an image-motion model `M` (the round Earth by default).
///
/// The work is split by how often it must be done: [`Backend::pixel`] once per field
/// point at boot or scene upload, [`Backend::update`] once per telemetry update,
/// [`Backend::motion`] per field point per update (no transcendental calls there).
pub trait Backend<M: Model = Sphere> {
    /// The scalar of the per-update input and of the output: a [`Real`] (f64, f32) for
    /// the float backends, I24F40 for [`crate::Fixed`]. Only [`Scalar`] is required.
    type Real: Scalar;
    /// Constants of one field point (depend only on the optics and the pixel).
    type Pixel: Copy;
    /// Constants of one instant (depend only on orbit and attitude).
    type Update: Copy;

    fn pixel(&self, camera: &M::Camera, n_px: f64) -> Result<Self::Pixel, ModelError>;
    fn update(&self, geometry: &M::Geometry<Self::Real>) -> Result<Self::Update, ModelError>;
    fn motion(
        &self,
        update: &Self::Update,
        pixel: &Self::Pixel,
    ) -> Result<ImageMotion<Self::Real>, ModelError>;

    /// All three steps for one pixel at one instant (convenience for tools and tests).
    fn evaluate(
        &self,
        camera: &M::Camera,
        geometry: &M::Geometry<Self::Real>,
        n_px: f64,
    ) -> Result<ImageMotion<Self::Real>, ModelError> {
        let p = self.pixel(camera, n_px)?;
        let u = self.update(geometry)?;
        self.motion(&u, &p)
    }
}

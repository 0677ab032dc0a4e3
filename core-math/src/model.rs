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

/// The optics: focal length and detector pixel pitch (the scene's optics; the real-Earth
/// model's [`crate::earth::EarthCamera`] adds the detector line's focal-plane position).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub focal_m: f64,
    pub pixel_m: f64,
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
/// Two models share the one [`Backend`] interface: [`crate::earth::Earth`], the real
/// Earth of `../shared/EARTH-MODEL.md` (the model the firmware flies), and, with the
/// feature `sphere`, `sphere::Sphere`, the paper's round Earth (roll only, circular
/// orbit, sea level).
pub trait Model {
    /// The optics (known at boot or scene upload).
    type Camera;
    /// Orbit, attitude and Earth at one instant, in a backend's scalar `T`.
    type Geometry<T: Scalar>;
}

/// One numeric backend of an image-motion model `M`.
///
/// The work is split by how often it must be done: [`Backend::pixel`] once per field
/// point at boot or scene upload, [`Backend::update`] once per telemetry update,
/// [`Backend::motion`] per field point per update (no transcendental calls there).
pub trait Backend<M: Model> {
    /// The scalar of the per-update input and of the output: a [`Real`] (f64, f32) for
    /// the float backends, I24F40 for the round Earth's fixed-point backend. Only
    /// [`Scalar`] is required.
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

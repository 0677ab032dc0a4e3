//! The real-Earth image-motion model (`../shared/EARTH-MODEL.md`, the contract):
//! a satellite on a two-body orbit given by its inertial state vector, a camera turned by
//! roll, pitch and yaw (each moving at its own rate) from the local orbital frame, a
//! pixel anywhere on the focal plane, and the ground as an ellipsoid of revolution raised
//! by the terrain height. The image motion is d/dt of where the Earth-fixed ground point
//! projects on the focal plane, at t = 0.
//!
//! Frames (as in the contract):
//! - **I**, inertial, Earth-centred, z the spin axis; the Earth turns about +z at
//!   `earth_rate_rad_s`.
//! - **L**, local orbital: z_L = r/|r| (zenith), y_L = (r x v)/|r x v| (orbit normal, to
//!   the left of the flight direction), x_L = y_L x z_L (forward).
//! - **B**, camera: the columns of A = Rx(roll) Ry(pitch) Rz(yaw) are B's axes in L.
//!   Boresight -z_B; pixel (p1, p2) has line of sight (p1, p2, -f) in B; P = -f (c1, c2)/c3.
//!
//! Backends, each one implementation of [`crate::Backend`]`<`[`Earth`]`>`:
//! - [`EarthReference`] (feature `reference`): the construction evaluated literally on
//!   dual numbers in f64, the golden source;
//! - [`General<f64>`] and [`General<f32>`]: the closed general form (`docs/derivation.md`,
//!   "The general model"), split into a per-update and a per-pixel part;
//! - `fixed::EarthFixed` (feature `earth-fixed`): the same form with an integer-only
//!   per-pixel part, for cores without an FPU.

use crate::error::{ModelError, Param};
use crate::model::{domain, Model};
use crate::orbit::StateVector;
use crate::real::{Real, Scalar};
use crate::vector::{cross, dot, unit};

pub mod bus;
pub mod dem;
#[cfg(feature = "earth-fixed")]
pub mod fixed;
pub mod frames;
pub mod general;
#[cfg(feature = "reference")]
pub mod kepler;
#[cfg(feature = "reference")]
pub mod reference;

pub use general::{
    General, GeneralInstant, GeneralPixel, GeneralRow, GeneralRowMotion, GeneralUpdate,
};
#[cfg(feature = "reference")]
pub use reference::EarthReference;

/// The real-Earth model: camera [`EarthCamera`], geometry [`EarthGeometry`].
#[derive(Clone, Copy, Debug, Default)]
pub struct Earth;

impl Model for Earth {
    type Camera = EarthCamera;
    type Geometry<T: Scalar> = EarthGeometry<T>;
}

/// An ellipsoid of revolution about the spin axis: semi-major axis a, flattening
/// (b = a (1 - flattening)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid {
    pub a_m: f64,
    pub flattening: f64,
}

impl Ellipsoid {
    /// WGS 84: a = 6 378 137 m, f = 1 / 298.257223563.
    pub const WGS84: Ellipsoid = Ellipsoid {
        a_m: 6_378_137.0,
        flattening: 1.0 / 298.257_223_563,
    };

    /// Semi-minor (polar) axis b = a (1 - f), m.
    pub fn b_m(&self) -> f64 {
        self.a_m * (1.0 - self.flattening)
    }

    /// Distance from the centre to the surface along a direction of geocentric latitude
    /// `lat_rad`: a b / sqrt(b^2 cos^2 + a^2 sin^2).
    pub fn geocentric_radius_m(&self, lat_rad: f64) -> f64 {
        let (s, c) = libm::sincos(lat_rad);
        let (a, b) = (self.a_m, self.b_m());
        a * b / libm::sqrt((b * c) * (b * c) + (a * s) * (a * s))
    }
}

/// The optics of the real-Earth model: focal length, pixel pitch, and the P1 position of
/// the detector line on the focal plane (0 when the line crosses the optical axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthCamera {
    pub focal_m: f64,
    pub pixel_m: f64,
    pub p1_m: f64,
}

/// Attitude of the camera frame B relative to the local orbital frame L: the angles of
/// A = Rx(roll) Ry(pitch) Rz(yaw) and their time derivatives (not body rates).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Attitude<T> {
    pub roll_rad: T,
    pub pitch_rad: T,
    pub yaw_rad: T,
    pub roll_rate_rad_s: T,
    pub pitch_rate_rad_s: T,
    pub yaw_rate_rad_s: T,
}

impl Attitude<f64> {
    /// The same attitude rounded to another scalar type.
    pub fn to<T: Real>(&self) -> Attitude<T> {
        Attitude {
            roll_rad: T::from_f64(self.roll_rad),
            pitch_rad: T::from_f64(self.pitch_rad),
            yaw_rad: T::from_f64(self.yaw_rad),
            roll_rate_rad_s: T::from_f64(self.roll_rate_rad_s),
            pitch_rate_rad_s: T::from_f64(self.pitch_rate_rad_s),
            yaw_rate_rad_s: T::from_f64(self.yaw_rate_rad_s),
        }
    }
}

impl<T: Scalar> Attitude<T> {
    /// The attitude widened to f64 (exact for f32).
    pub fn to_f64(&self) -> Attitude<f64> {
        Attitude {
            roll_rad: self.roll_rad.to_f64(),
            pitch_rad: self.pitch_rad.to_f64(),
            yaw_rad: self.yaw_rad.to_f64(),
            roll_rate_rad_s: self.roll_rate_rad_s.to_f64(),
            pitch_rate_rad_s: self.pitch_rate_rad_s.to_f64(),
            yaw_rate_rad_s: self.yaw_rate_rad_s.to_f64(),
        }
    }

    /// The six values with the parameter each one is: angles, then rates.
    pub fn values(&self) -> [(T, Param); 6] {
        [
            (self.roll_rad, Param::Roll),
            (self.pitch_rad, Param::Pitch),
            (self.yaw_rad, Param::Yaw),
            (self.roll_rate_rad_s, Param::RollRate),
            (self.pitch_rate_rad_s, Param::PitchRate),
            (self.yaw_rate_rad_s, Param::YawRate),
        ]
    }
}

/// Attitude of the camera frame B given directly in I (Part II): B's axes and its
/// angular velocity relative to I. B(t) = B0 (I + \[Omega\]x t + ...), so
/// dB/dt = B0 \[Omega\]x at t = 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InertialAttitude<T> {
    /// B0, row-major: its columns are x_B, y_B, z_B in I (x_I = B0 x_B). Orthonormal and
    /// right-handed within [`MAX_AXES_ERROR`].
    pub camera_to_inertial: [[T; 3]; 3],
    /// Omega (rad/s): the camera's angular velocity relative to I, in B.
    pub omega_rad_s: [T; 3],
}

/// Largest |B^T B - 1| (any entry) and |det B - 1| accepted for an [`InertialAttitude`]:
/// f32 rounding of a rotation leaves about 2e-7; anything beyond 1e-5 is not a rotation.
pub const MAX_AXES_ERROR: f64 = 1.0e-5;

impl InertialAttitude<f64> {
    /// The same attitude rounded to another scalar type.
    pub fn to<T: Real>(&self) -> InertialAttitude<T> {
        InertialAttitude {
            camera_to_inertial: self.camera_to_inertial.map(|row| row.map(T::from_f64)),
            omega_rad_s: self.omega_rad_s.map(T::from_f64),
        }
    }
}

impl<T: Scalar> InertialAttitude<T> {
    /// The attitude widened to f64 (exact for f32).
    pub fn to_f64(&self) -> InertialAttitude<f64> {
        InertialAttitude {
            camera_to_inertial: self.camera_to_inertial.map(|row| row.map(|x| x.to_f64())),
            omega_rad_s: self.omega_rad_s.map(|x| x.to_f64()),
        }
    }
}

/// The checks of one kind of attitude, in its own scalar: what
/// [`EarthGeometry::check_inputs`] asks of it (finiteness first, with the other inputs'
/// finiteness; the domain after the Earth's).
pub trait AttitudeChecks {
    /// Every value finite, else [`ModelError::NonFinite`] naming it.
    fn check_finite(&self) -> Result<(), ModelError>;
    /// Within the model's domain (and, for axes, a rotation).
    fn check_domain(&self) -> Result<(), ModelError>;
}

impl<T: Real> AttitudeChecks for Attitude<T> {
    fn check_finite(&self) -> Result<(), ModelError> {
        for (x, p) in self.values() {
            if !x.is_finite() {
                return Err(ModelError::NonFinite(p));
            }
        }
        Ok(())
    }

    fn check_domain(&self) -> Result<(), ModelError> {
        let max_angle = T::from_f64(domain::MAX_ANGLE_RAD);
        let max_rate = T::from_f64(domain::MAX_RATE_RAD_S);
        for (i, (x, p)) in self.values().into_iter().enumerate() {
            let max = if i < 3 { max_angle } else { max_rate };
            if !(x.abs() <= max) {
                return Err(ModelError::OutOfDomain(p));
            }
        }
        Ok(())
    }
}

impl<T: Real> AttitudeChecks for InertialAttitude<T> {
    fn check_finite(&self) -> Result<(), ModelError> {
        if !self
            .camera_to_inertial
            .iter()
            .flatten()
            .all(|x| x.is_finite())
        {
            return Err(ModelError::NonFinite(Param::CameraAxes));
        }
        if !self.omega_rad_s.iter().all(|x| x.is_finite()) {
            return Err(ModelError::NonFinite(Param::AngularVelocity));
        }
        Ok(())
    }

    /// |Omega| components within the domain's rate; B orthonormal and right-handed
    /// within [`MAX_AXES_ERROR`] ([`ModelError::InvalidInput`]`(CameraAxes)` otherwise).
    fn check_domain(&self) -> Result<(), ModelError> {
        let max_rate = T::from_f64(domain::MAX_RATE_RAD_S);
        if !self.omega_rad_s.iter().all(|x| x.abs() <= max_rate) {
            return Err(ModelError::OutOfDomain(Param::AngularVelocity));
        }
        let m = &self.camera_to_inertial;
        let col = |j: usize| [m[0][j], m[1][j], m[2][j]];
        let cols = [col(0), col(1), col(2)];
        let tol = T::from_f64(MAX_AXES_ERROR);
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { T::ONE } else { T::ZERO };
                if !((dot(cols[i], cols[j]) - want).abs() <= tol) {
                    return Err(ModelError::InvalidInput(Param::CameraAxes));
                }
            }
        }
        if !((dot(cols[0], cross(cols[1], cols[2])) - T::ONE).abs() <= tol) {
            return Err(ModelError::InvalidInput(Param::CameraAxes));
        }
        Ok(())
    }
}

/// Everything of one instant: the satellite's inertial state (f64 whatever the backend:
/// a position in f32 would carry 0.5 m of rounding, 2.5e-6 of a 200 km altitude), the
/// attitude in the backend's scalar, the ground and the Earth's rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthGeometry<T> {
    pub state: StateVector,
    pub attitude: Attitude<T>,
    /// Height of the imaged ground above the ellipsoid (m).
    pub ground_h_m: f64,
    pub ellipsoid: Ellipsoid,
    pub earth_rate_rad_s: f64,
}

impl EarthGeometry<f64> {
    /// The same geometry with the attitude rounded to another scalar type.
    pub fn to<T: Real>(&self) -> EarthGeometry<T> {
        EarthGeometry {
            state: self.state,
            attitude: self.attitude.to(),
            ground_h_m: self.ground_h_m,
            ellipsoid: self.ellipsoid,
            earth_rate_rad_s: self.earth_rate_rad_s,
        }
    }

    /// The same instant with Part I's attitude re-expressed as Part II's: the camera's
    /// axes in I, M = [x_L y_L z_L] A, and its angular velocity relative to I in B,
    /// Omega = W_B + omega n_B (W_B, n_B of [`General::instant`], in f64). What a DEM
    /// needs of a Part I attitude: each line of sight in I. Refusals: the state's
    /// ([`check_state`]).
    pub fn to_inertial(&self) -> Result<InertialGeometry<f64>, ModelError> {
        let inst = General::<f64>::new().instant(
            &self.state,
            &self.attitude,
            &self.ellipsoid,
            self.earth_rate_rad_s,
        )?;
        let (r, v) = (self.state.position_m, self.state.velocity_mps);
        let z_l = unit(r);
        let y_l = unit(cross(r, v));
        let x_l = cross(y_l, z_l);
        let at = &self.attitude;
        let (sp, cp) = crate::trig_f64::sin_cos(at.roll_rad);
        let (st, ct) = crate::trig_f64::sin_cos(at.pitch_rad);
        let (sy, cy) = crate::trig_f64::sin_cos(at.yaw_rad);
        // A = Rx(roll) Ry(pitch) Rz(yaw), row-major.
        let a = [
            [ct * cy, -ct * sy, st],
            [cp * sy + sp * st * cy, cp * cy - sp * st * sy, -sp * ct],
            [sp * sy - cp * st * cy, sp * cy + cp * st * sy, cp * ct],
        ];
        let m = core::array::from_fn(|i| {
            core::array::from_fn(|j| x_l[i] * a[0][j] + y_l[i] * a[1][j] + z_l[i] * a[2][j])
        });
        let w = self.earth_rate_rad_s;
        Ok(InertialGeometry {
            state: self.state,
            attitude: InertialAttitude {
                camera_to_inertial: m,
                omega_rad_s: core::array::from_fn(|k| inst.w_b_rad_s[k] + w * inst.n_b[k]),
            },
            ground_h_m: self.ground_h_m,
            ellipsoid: self.ellipsoid,
            earth_rate_rad_s: self.earth_rate_rad_s,
        })
    }
}

/// [`EarthGeometry`] with Part II's attitude: the camera's axes in I and its angular
/// velocity ([`InertialAttitude`], from the bus's quaternion and gyro rates by
/// [`bus::bus_geometry`]). Everything else as in Part I. The backends take it through
/// their own entry points (`EarthReference::chain` and `motion_of`,
/// `General::update_inertial`), whose update is the same type as Part I's: the
/// per-pixel work does not change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InertialGeometry<T> {
    pub state: StateVector,
    pub attitude: InertialAttitude<T>,
    /// Height of the imaged ground above the ellipsoid (m).
    pub ground_h_m: f64,
    pub ellipsoid: Ellipsoid,
    pub earth_rate_rad_s: f64,
}

impl InertialGeometry<f64> {
    /// The same geometry with the attitude rounded to another scalar type.
    pub fn to<T: Real>(&self) -> InertialGeometry<T> {
        InertialGeometry {
            state: self.state,
            attitude: self.attitude.to(),
            ground_h_m: self.ground_h_m,
            ellipsoid: self.ellipsoid,
            earth_rate_rad_s: self.earth_rate_rad_s,
        }
    }
}

impl<T: Scalar> InertialGeometry<T> {
    /// The geometry with the attitude widened to f64.
    pub fn to_f64(&self) -> InertialGeometry<f64> {
        InertialGeometry {
            state: self.state,
            attitude: self.attitude.to_f64(),
            ground_h_m: self.ground_h_m,
            ellipsoid: self.ellipsoid,
            earth_rate_rad_s: self.earth_rate_rad_s,
        }
    }
}

/// The ground ellipsoid (semi-axes A = a + h, A, B = b + h) and where the satellite is
/// relative to it, as [`EarthGeometry::validate`] finds them in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    /// Equatorial semi-axis A = a + h (m).
    pub eq_m: f64,
    /// Polar semi-axis B = b + h (m).
    pub polar_m: f64,
    /// kappa^2 - 1, kappa = A/B the stretch of z that makes the ground a sphere of
    /// radius A: (A - B)(A + B)/B^2, A - B = a f (no cancellation).
    pub stretch2_minus_1: f64,
    /// C = |K r|^2 - A^2 = (|r|^2 - A^2) + (kappa^2 - 1) z^2 (m^2), K = diag(1, 1, kappa):
    /// positive outside the ground ellipsoid.
    pub c_m2: f64,
}

/// Smallest focal length and pixel pitch accepted (m): a pitch below 1 nm would round to
/// a subnormal or to 0 in f32 and give a zero line period (fuzz finding F6,
/// docs/fuzzing.md); nothing real comes near either bound.
pub const MIN_FOCAL_M: f64 = 1.0e-6;
pub const MIN_PIXEL_M: f64 = 1.0e-9;
/// Largest |r| accepted (m): beyond the Moon, and no overflow anywhere in f32.
pub const MAX_POSITION_M: f64 = 1.0e9;
/// Largest |v| accepted (m/s).
pub const MAX_VELOCITY_MPS: f64 = 1.0e5;
/// Largest flattening accepted (the definition allows [0, 1); beyond 0.5 the stretch
/// kappa^2 exceeds 4 and nothing real is that flat).
pub const MAX_FLATTENING: f64 = 0.5;
/// Ground heights accepted: within [-b/2, a] (m, as fractions of the axes).
pub const MIN_GROUND_H_OVER_B: f64 = -0.5;
pub const MAX_GROUND_H_OVER_A: f64 = 1.0;
/// Smallest "altitude" accepted: C / A^2 = |K r|^2 / A^2 - 1 (about 2 H / A) at least
/// this, 1e-6 (about 3 m on the Earth). Below it f32's rounding of C (a relative 1e-7 of
/// |r|^2) could not tell the satellite from the ground.
pub const MIN_ALTITUDE_RATIO: f64 = 1.0e-6;
/// Smallest |r x v|^2 / (|r|^2 |v|^2), the squared sine of the angle between r and v.
pub const MIN_SIN2_FLIGHT_PATH: f64 = 1.0e-12;
/// Largest |r| / (a + h): the sphere model's 16 R altitude limit.
pub const MAX_RADIUS_RATIO: f64 = 17.0;
/// Smallest |v1| (m/s) with a finite line period for any pixel pitch of the domain:
/// below it the motion along the TDI direction is taken as zero.
pub const MIN_V1_MPS: f64 = 1.0e-30;

fn finite3(x: [f64; 3]) -> bool {
    x.iter().all(|c| c.is_finite())
}

impl EarthCamera {
    /// Checks the optics and returns the pixel's focal-plane position (p1, p2) (m).
    // Out of line: inlined into the plan build and the pixel beside this copy
    // (docs/target.md, flash).
    #[inline(never)]
    pub fn focal_plane_m(&self, n_px: f64) -> Result<(f64, f64), ModelError> {
        for (x, p) in [
            (self.focal_m, Param::FocalLength),
            (self.pixel_m, Param::PixelPitch),
            (self.p1_m, Param::FocalPlaneP1),
            (n_px, Param::PixelOffset),
        ] {
            if !x.is_finite() {
                return Err(ModelError::NonFinite(p));
            }
        }
        if !(self.focal_m > 0.0) {
            return Err(ModelError::InvalidInput(Param::FocalLength));
        }
        if !(self.pixel_m > 0.0) {
            return Err(ModelError::InvalidInput(Param::PixelPitch));
        }
        if !(MIN_FOCAL_M..=domain::MAX_FOCAL_M).contains(&self.focal_m) {
            return Err(ModelError::OutOfDomain(Param::FocalLength));
        }
        if !(MIN_PIXEL_M..=domain::MAX_PIXEL_M).contains(&self.pixel_m) {
            return Err(ModelError::OutOfDomain(Param::PixelPitch));
        }
        let p2 = n_px * self.pixel_m;
        let limit = domain::MAX_TAN_FIELD * self.focal_m;
        if !(self.p1_m.abs() <= limit) {
            return Err(ModelError::OutOfDomain(Param::FocalPlaneP1));
        }
        if !(p2.abs() <= limit) {
            return Err(ModelError::OutOfDomain(Param::PixelOffset));
        }
        Ok((self.p1_m, p2))
    }
}

impl<T: Scalar> EarthGeometry<T> {
    /// The geometry with the attitude widened to f64.
    pub fn to_f64(&self) -> EarthGeometry<f64> {
        EarthGeometry {
            state: self.state,
            attitude: self.attitude.to_f64(),
            ground_h_m: self.ground_h_m,
            ellipsoid: self.ellipsoid,
            earth_rate_rad_s: self.earth_rate_rad_s,
        }
    }
}

impl<T: Real> EarthGeometry<T> {
    /// The checks that need no arithmetic on the state vector: finiteness, the Earth and
    /// the ground (definition and domain), the Earth's rate, the attitude (in `T`: no
    /// soft-f64 work for it on the target). Returns (A, B) = (a + h, b + h).
    pub fn check_inputs(&self) -> Result<(f64, f64), ModelError> {
        self.parts().check_inputs()
    }

    /// Every check of the definition's error table and the model's domain, all in f64,
    /// and the ground ellipsoid. The reference and the host tools use it; the general
    /// form makes the same state checks in its own scalar ([`check_state`]).
    pub fn validate(&self) -> Result<Ground, ModelError> {
        self.parts().validate()
    }

    fn parts(&self) -> GeometryParts<'_, Attitude<T>> {
        GeometryParts {
            state: &self.state,
            attitude: &self.attitude,
            ground_h_m: self.ground_h_m,
            ellipsoid: &self.ellipsoid,
            earth_rate_rad_s: self.earth_rate_rad_s,
        }
    }
}

impl<T: Real> InertialGeometry<T> {
    /// [`EarthGeometry::check_inputs`] with Part II's attitude ([`AttitudeChecks`]).
    pub fn check_inputs(&self) -> Result<(f64, f64), ModelError> {
        self.parts().check_inputs()
    }

    /// [`EarthGeometry::validate`] with Part II's attitude.
    pub fn validate(&self) -> Result<Ground, ModelError> {
        self.parts().validate()
    }

    fn parts(&self) -> GeometryParts<'_, InertialAttitude<T>> {
        GeometryParts {
            state: &self.state,
            attitude: &self.attitude,
            ground_h_m: self.ground_h_m,
            ellipsoid: &self.ellipsoid,
            earth_rate_rad_s: self.earth_rate_rad_s,
        }
    }
}

/// The fields both geometries share, with either attitude: the checks written once.
struct GeometryParts<'a, A> {
    state: &'a StateVector,
    attitude: &'a A,
    ground_h_m: f64,
    ellipsoid: &'a Ellipsoid,
    earth_rate_rad_s: f64,
}

impl<A: AttitudeChecks> GeometryParts<'_, A> {
    fn check_inputs(&self) -> Result<(f64, f64), ModelError> {
        let (r, v) = (self.state.position_m, self.state.velocity_mps);
        if !finite3(r) {
            return Err(ModelError::NonFinite(Param::Position));
        }
        if !finite3(v) {
            return Err(ModelError::NonFinite(Param::Velocity));
        }
        for (x, p) in [
            (self.ground_h_m, Param::GroundHeight),
            (self.ellipsoid.a_m, Param::SemiMajorAxis),
            (self.ellipsoid.flattening, Param::Flattening),
            (self.earth_rate_rad_s, Param::EarthRate),
        ] {
            if !x.is_finite() {
                return Err(ModelError::NonFinite(p));
            }
        }
        self.attitude.check_finite()?;
        let a = self.ellipsoid.a_m;
        let fl = self.ellipsoid.flattening;
        if !(a > 0.0) {
            return Err(ModelError::InvalidInput(Param::SemiMajorAxis));
        }
        if !(0.0..1.0).contains(&fl) {
            return Err(ModelError::InvalidInput(Param::Flattening));
        }
        let b = self.ellipsoid.b_m();
        if !(self.ground_h_m > -b) {
            return Err(ModelError::InvalidInput(Param::GroundHeight));
        }
        let (a_min, a_max) = domain::EARTH_RADIUS_M;
        if !(a >= a_min && a <= a_max) {
            return Err(ModelError::OutOfDomain(Param::SemiMajorAxis));
        }
        if fl > MAX_FLATTENING {
            return Err(ModelError::OutOfDomain(Param::Flattening));
        }
        if !(self.ground_h_m >= MIN_GROUND_H_OVER_B * b
            && self.ground_h_m <= MAX_GROUND_H_OVER_A * a)
        {
            return Err(ModelError::OutOfDomain(Param::GroundHeight));
        }
        if !(self.earth_rate_rad_s.abs() <= domain::MAX_RATE_RAD_S) {
            return Err(ModelError::OutOfDomain(Param::EarthRate));
        }
        self.attitude.check_domain()?;
        Ok((a + self.ground_h_m, b + self.ground_h_m))
    }

    fn validate(&self) -> Result<Ground, ModelError> {
        let (eq_m, polar_m) = self.check_inputs()?;
        let (r, v) = (self.state.position_m, self.state.velocity_mps);
        let (r2, _) = check_state(r, v)?;
        let a = self.ellipsoid.a_m;
        let k2m1 = (a * self.ellipsoid.flattening) * (eq_m + polar_m) / (polar_m * polar_m);
        let c_m2 = (r2 - eq_m * eq_m) + k2m1 * r[2] * r[2];
        check_altitude(c_m2, r2, eq_m)?;
        Ok(Ground {
            eq_m,
            polar_m,
            stretch2_minus_1: k2m1,
            c_m2,
        })
    }
}

/// The state-vector checks, in any scalar: |r| and |v| within the domain, an orbital
/// plane (r x v not below 1e-6 |r| |v|: a flight path within a microradian of the
/// vertical is degenerate for every scalar, so f32 and f64 agree on it). Returns |r|^2
/// and the angular momentum r x v (never zero after the check).
// Out of line on a core without an FPU only: on the M4F inlined it measured smaller
// and faster (docs/target.md, flash).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
pub fn check_state<S: Real>(r: [S; 3], v: [S; 3]) -> Result<(S, [S; 3]), ModelError> {
    let (r2, v2) = (dot(r, r), dot(v, v));
    // Squared bounds: no square root.
    if !(r2 <= S::from_f64(MAX_POSITION_M * MAX_POSITION_M)) {
        return Err(ModelError::OutOfDomain(Param::Position));
    }
    if !(v2 <= S::from_f64(MAX_VELOCITY_MPS * MAX_VELOCITY_MPS)) {
        return Err(ModelError::OutOfDomain(Param::Velocity));
    }
    let h = cross(r, v);
    if !(dot(h, h) > S::from_f64(MIN_SIN2_FLIGHT_PATH) * (r2 * v2)) {
        return Err(ModelError::DegenerateState);
    }
    Ok((r2, h))
}

/// The satellite against the ground ellipsoid from C = |K r|^2 - A^2, in any scalar:
/// inside or on it, refused as such; within [`MIN_ALTITUDE_RATIO`] A^2 above it or
/// beyond [`MAX_RADIUS_RATIO`] A, out of the domain.
pub fn check_altitude<S: Real>(c_m2: S, r2: S, eq_m: S) -> Result<(), ModelError> {
    if !(c_m2 > S::ZERO) {
        return Err(ModelError::SatelliteNotAboveGround);
    }
    let a2 = eq_m * eq_m;
    if c_m2 < S::from_f64(MIN_ALTITUDE_RATIO) * a2
        || r2 > S::from_f64(MAX_RADIUS_RATIO * MAX_RADIUS_RATIO) * a2
    {
        return Err(ModelError::OutOfDomain(Param::Position));
    }
    Ok(())
}

/// The inertial state of a circular orbit of radius `radius_m` (two-body speed
/// sqrt(GM/r)), inclination `inclination_rad`, at argument of latitude `arg_latitude_rad`
/// from the ascending node, the node on +x. With it the real-Earth model reduces to the
/// round-Earth geometry of the same i0 and gamma0.
pub fn circular_state(radius_m: f64, inclination_rad: f64, arg_latitude_rad: f64) -> StateVector {
    let (si, ci) = crate::trig_f64::sin_cos(inclination_rad);
    let (su, cu) = crate::trig_f64::sin_cos(arg_latitude_rad);
    let speed = crate::sqrt::sqrt_f64(crate::model::GM_M3_S2 / radius_m);
    StateVector {
        position_m: [radius_m * cu, radius_m * su * ci, radius_m * su * si],
        velocity_mps: [-speed * su, speed * cu * ci, speed * cu * si],
    }
}

/// Angular distance (rad) from a pixel's line of sight to the limb, positive when the
/// ray meets the ground: L - eta in the coordinates where the ground ellipsoid is the
/// sphere of radius A (z stretched by kappa = A/B), eta the angle between the ray and
/// the nadir there, L = asin(A/|K r|). The stretch changes angles by at most
/// kappa - 1 (3.4e-3 for WGS 84), so this is the true margin to within 0.4 %: enough to
/// sort cases into limb bands. Host tools and tests only (f64, libm).
#[cfg(feature = "reference")]
pub fn limb_margin_rad(
    g: &EarthGeometry<f64>,
    camera: &EarthCamera,
    n_px: f64,
) -> Result<f64, ModelError> {
    let ground = g.validate()?;
    let (p1, p2) = camera.focal_plane_m(n_px)?;
    let pixel = reference::EarthReference::line_of_sight(g, p1, p2, camera.focal_m);
    let kappa = ground.eq_m / ground.polar_m;
    let r = g.state.position_m;
    let rs = [r[0], r[1], r[2] * kappa];
    let ds = [pixel[0], pixel[1], pixel[2] * kappa];
    let rn = libm::sqrt(dot(rs, rs));
    // Angle between -r' and d' by atan2 (accurate at every angle).
    let cr = cross(rs, ds);
    let eta = libm::atan2(libm::sqrt(dot(cr, cr)), -dot(rs, ds));
    let limb = libm::asin(ground.eq_m / rn);
    Ok(limb - eta)
}

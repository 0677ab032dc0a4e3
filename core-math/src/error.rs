//! Typed errors: every rejected input or impossible geometry has its own variant,
//! so that no function in this crate ever answers with NaN, an infinity or a panic.

/// The input a [`ModelError::NonFinite`] or [`ModelError::OutOfDomain`] names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Param {
    Roll,
    Inclination,
    ArgLatitude,
    Altitude,
    EarthRadius,
    EarthRate,
    OrbitRate,
    FocalLength,
    PixelPitch,
    PixelOffset,
    ClockFrequency,
    RelativeMismatch,
    MtfFloor,
    Position,
    Velocity,
    Pitch,
    Yaw,
    RollRate,
    PitchRate,
    YawRate,
    GroundHeight,
    SemiMajorAxis,
    Flattening,
    FocalPlaneP1,
    /// The drift tangent v2 / v1 of the drift-smear MTF.
    Drift,
    /// GPS time `gps_s` (Part II).
    GpsTime,
    /// GPS - UTC, the leap seconds `gps_utc_s`.
    LeapSeconds,
    /// UT1 - UTC, `dut1_s`.
    Dut1,
    /// A geodetic latitude.
    Latitude,
    /// A geodetic longitude.
    Longitude,
    /// A geodetic height above the ellipsoid.
    Height,
    /// The camera's axes in I (the matrix B of an [`crate::earth::InertialAttitude`]).
    CameraAxes,
    /// The camera's angular velocity relative to I, in camera coordinates.
    AngularVelocity,
    /// The bus's attitude quaternion `q` (Part II).
    Quaternion,
    /// The camera's mounting quaternion `cam_q` (Part II).
    CameraQuaternion,
    /// The body rates measured by the gyros (Part II).
    BodyRate,
    /// A DEM tile's grid: its origin, spacings and node counts (Part II).
    DemGrid,
    /// A DEM tile's node heights (Part II).
    DemHeight,
}

impl Param {
    pub const fn name(self) -> &'static str {
        match self {
            Param::Roll => "roll",
            Param::Inclination => "inclination",
            Param::ArgLatitude => "arg_latitude",
            Param::Altitude => "altitude",
            Param::EarthRadius => "earth_radius",
            Param::EarthRate => "earth_rate",
            Param::OrbitRate => "orbit_rate",
            Param::FocalLength => "focal_length",
            Param::PixelPitch => "pixel_pitch",
            Param::PixelOffset => "pixel_offset",
            Param::ClockFrequency => "clock_frequency",
            Param::RelativeMismatch => "relative_mismatch",
            Param::MtfFloor => "mtf_floor",
            Param::Position => "position",
            Param::Velocity => "velocity",
            Param::Pitch => "pitch",
            Param::Yaw => "yaw",
            Param::RollRate => "roll_rate",
            Param::PitchRate => "pitch_rate",
            Param::YawRate => "yaw_rate",
            Param::GroundHeight => "ground_height",
            Param::SemiMajorAxis => "semi_major_axis",
            Param::Flattening => "flattening",
            Param::FocalPlaneP1 => "p1",
            Param::Drift => "drift",
            Param::GpsTime => "gps_time",
            Param::LeapSeconds => "leap_seconds",
            Param::Dut1 => "dut1",
            Param::Latitude => "latitude",
            Param::Longitude => "longitude",
            Param::Height => "height",
            Param::CameraAxes => "camera_axes",
            Param::AngularVelocity => "angular_velocity",
            Param::Quaternion => "quaternion",
            Param::CameraQuaternion => "camera_quaternion",
            Param::BodyRate => "body_rate",
            Param::DemGrid => "dem_grid",
            Param::DemHeight => "dem_height",
        }
    }
}

/// Why a computation was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ModelError {
    /// An input was NaN or infinite.
    NonFinite(Param),
    /// Altitude above the Earth's surface was zero or negative.
    NonPositiveAltitude,
    /// The Earth radius was zero or negative.
    NonPositiveEarthRadius,
    /// The focal length was zero or negative.
    NonPositiveFocalLength,
    /// The pixel pitch was zero or negative.
    NonPositivePixelPitch,
    /// A finite input beyond the model's documented domain (see [`crate::domain`]).
    OutOfDomain(Param),
    /// The line of sight does not meet the Earth: at or beyond the limb, or above the horizon.
    LineOfSightMissesEarth,
    /// The image does not move (|v_P| too small for a finite line period).
    NoImageMotion,
    /// The line period does not fit the tick counter (zero ticks or more than `u32::MAX`).
    LinePeriodOutOfRange,
    /// Real-Earth model: an input outside its physical meaning (f, pixel or a <= 0,
    /// flattening outside [0, 1), ground height <= -b).
    InvalidInput(Param),
    /// Real-Earth model: |r| = 0 or r x v = 0, so the local orbital frame is undefined.
    DegenerateState,
    /// Real-Earth model: the satellite is on or inside the ground ellipsoid.
    SatelliteNotAboveGround,
    /// Real-Earth model: v1 = 0 (no motion along the TDI direction: no line period, no
    /// drift angle).
    NoAlongTrackMotion,
    /// Part II: a quaternion (the attitude `q` or the mounting `cam_q`, named by the
    /// parameter) whose norm is not within 1e-3 of 1.
    InvalidQuaternion(Param),
    /// Part II: the line of sight reaches the ground (some point of it is as low as the
    /// DEM tile's lowest node) but crosses the tile's surface nowhere inside the tile.
    OutsideDem,
}

impl ModelError {
    /// A stable, machine-readable name (used in the `eval` CSV `error` column).
    pub const fn name(self) -> &'static str {
        match self {
            ModelError::NonFinite(_) => "non_finite_input",
            ModelError::NonPositiveAltitude => "non_positive_altitude",
            ModelError::NonPositiveEarthRadius => "non_positive_earth_radius",
            ModelError::NonPositiveFocalLength => "non_positive_focal_length",
            ModelError::NonPositivePixelPitch => "non_positive_pixel_pitch",
            ModelError::OutOfDomain(_) => "out_of_domain",
            ModelError::LineOfSightMissesEarth => "line_of_sight_misses_earth",
            ModelError::NoImageMotion => "no_image_motion",
            ModelError::LinePeriodOutOfRange => "line_period_out_of_range",
            ModelError::InvalidInput(_) => "invalid_input",
            ModelError::DegenerateState => "degenerate_state",
            ModelError::SatelliteNotAboveGround => "satellite_not_above_ground",
            ModelError::NoAlongTrackMotion => "no_along_track_motion",
            ModelError::InvalidQuaternion(_) => "invalid_quaternion",
            ModelError::OutsideDem => "outside_dem",
        }
    }

    /// The parameter concerned, where there is one.
    pub const fn param(self) -> Option<Param> {
        match self {
            ModelError::NonFinite(p)
            | ModelError::OutOfDomain(p)
            | ModelError::InvalidInput(p)
            | ModelError::InvalidQuaternion(p) => Some(p),
            _ => None,
        }
    }
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.param() {
            Some(p) => write!(f, "{}({})", self.name(), p.name()),
            None => f.write_str(self.name()),
        }
    }
}

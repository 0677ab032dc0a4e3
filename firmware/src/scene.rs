//! Where the scene comes from: camera, orbit and attitude, detector layout, line clock.
//!
//! Today there is no telemetry link, so [`NoTelemetry`] hands out the built-in
//! [`Scene::paper_default`]. A later UART telemetry controller implements
//! [`SceneSource`] and the rest of the firmware does not change.

use core_math::{Camera, Geometry};

use crate::FirmwareError;

/// How the detector line is cut into segments, each with its own line clock.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectorLayout {
    /// Pixel offset (from the optical axis) of the first segment's first edge.
    pub first_px: i32,
    /// Number of segments (at most [`crate::pipeline::MAX_SEGMENTS`]).
    pub segments: u32,
    /// Width of one segment in pixels.
    pub segment_px: u32,
}

/// Everything the pipeline needs for one evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scene {
    pub camera: Camera,
    /// Orbit and attitude at the instant, already in the shipped scalar (f32).
    pub geometry: Geometry<f32>,
    pub layout: DetectorLayout,
    /// Frequency of the counter that times the TDI lines (Hz).
    pub line_clock_hz: f32,
}

/// The paper's camera (Li, Kong, Liu 2013): H 645 km, f 0.555 m, pixel 13 um,
/// pixels -30 000..=+30 000 in 10 segments of 6 000, i0 97.98 deg, roll 25 deg,
/// R 6 370 km, argument of latitude 0, a 10 MHz line clock.
pub mod default_scene {
    pub const ALTITUDE_M: f64 = 645.0e3;
    pub const EARTH_RADIUS_M: f64 = 6_370.0e3;
    pub const FOCAL_M: f64 = 0.555;
    pub const PIXEL_M: f64 = 13.0e-6;
    pub const INCLINATION_DEG: f64 = 97.98;
    pub const ROLL_DEG: f64 = 25.0;
    pub const ARG_LATITUDE_DEG: f64 = 0.0;
    pub const FIRST_PX: i32 = -30_000;
    pub const SEGMENTS: u32 = 10;
    pub const SEGMENT_PX: u32 = 6_000;
    pub const LINE_CLOCK_HZ: f32 = 10.0e6;
}

impl Scene {
    /// The built-in default scene (see [`default_scene`]), circular orbit.
    pub fn paper_default() -> Scene {
        use default_scene as d;
        let geometry = Geometry::circular(
            d::ROLL_DEG.to_radians(),
            d::INCLINATION_DEG.to_radians(),
            d::ARG_LATITUDE_DEG.to_radians(),
            d::ALTITUDE_M,
            d::EARTH_RADIUS_M,
        );
        Scene {
            camera: Camera {
                focal_m: d::FOCAL_M,
                pixel_m: d::PIXEL_M,
            },
            geometry: geometry.to::<f32>(),
            layout: DetectorLayout {
                first_px: d::FIRST_PX,
                segments: d::SEGMENTS,
                segment_px: d::SEGMENT_PX,
            },
            line_clock_hz: d::LINE_CLOCK_HZ,
        }
    }
}

/// A source of scenes: the telemetry link, or the built-in default without one.
pub trait SceneSource {
    /// The scene to evaluate now.
    fn scene(&mut self) -> Result<Scene, FirmwareError>;
}

/// No telemetry link: always the built-in default scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoTelemetry;

impl SceneSource for NoTelemetry {
    fn scene(&mut self) -> Result<Scene, FirmwareError> {
        Ok(Scene::paper_default())
    }
}

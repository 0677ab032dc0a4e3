//! The math: per-pixel constants once per scene, then per update the image-motion
//! velocity and the TDI line period at each segment's sample points, with the shipped
//! backend [`core_math::CLOSED_F32`].

use core_math::closed_form::{PixelConst, UpdateConst};
use core_math::{line_period_s, line_period_ticks, Backend, Geometry, CLOSED_F32};

use crate::scene::Scene;
use crate::FirmwareError;

/// Capacity of the segment table (the paper's camera has 10).
pub const MAX_SEGMENTS: usize = 16;
/// Sample points per segment: its first edge, its centre, its last edge.
pub const SAMPLES_PER_SEGMENT: usize = 3;
/// Names of the sample points, in order.
pub const SAMPLE_NAMES: [&str; SAMPLES_PER_SEGMENT] = ["start", "centre", "end"];

/// One field point and its boot-time constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplePoint {
    /// Pixel offset from the optical axis.
    pub n_px: i32,
    pub pixel: PixelConst<f32>,
}

/// One detector segment and its sample points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub index: u8,
    pub samples: [SamplePoint; SAMPLES_PER_SEGMENT],
}

/// Result at one sample point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointReport {
    pub n_px: i32,
    /// Image-motion velocity along the TDI direction (m/s on the focal plane).
    pub v1_mps: f32,
    /// Drift along the line (m/s on the focal plane).
    pub v2_mps: f32,
    /// |v| (m/s).
    pub speed_mps: f32,
    /// Line period pixel / |v| (s).
    pub period_s: f32,
    /// The line period in ticks of the line clock.
    pub ticks: u32,
}

/// Results of one segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentReport {
    pub index: u8,
    pub points: [PointReport; SAMPLES_PER_SEGMENT],
}

const EMPTY_POINT: PointReport = PointReport {
    n_px: 0,
    v1_mps: 0.0,
    v2_mps: 0.0,
    speed_mps: 0.0,
    period_s: 0.0,
    ticks: 0,
};

/// The boot-time part: sample points and their pixel constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    segments: [Segment; MAX_SEGMENTS],
    len: usize,
    pixel_m: f32,
    clock_hz: f32,
}

/// The pixel offsets of segment `k`'s sample points: first edge, centre, last edge
/// (edges are shared with the neighbours).
fn sample_offsets(first_px: i32, segment_px: u32, k: u32) -> Option<[i32; SAMPLES_PER_SEGMENT]> {
    let width = i64::from(segment_px);
    let start = i64::from(first_px).checked_add(width.checked_mul(i64::from(k))?)?;
    let centre = start.checked_add(width / 2)?;
    let end = start.checked_add(width)?;
    Some([
        i32::try_from(start).ok()?,
        i32::try_from(centre).ok()?,
        i32::try_from(end).ok()?,
    ])
}

impl Plan {
    /// Checks the layout and computes every sample point's pixel constants (f64 work,
    /// done once per scene).
    pub fn new(scene: &Scene) -> Result<Plan, FirmwareError> {
        let layout = scene.layout;
        let count = usize::try_from(layout.segments).map_err(|_| FirmwareError::Layout)?;
        if count == 0 || count > MAX_SEGMENTS || layout.segment_px == 0 {
            return Err(FirmwareError::Layout);
        }
        // Unused slots hold the axis pixel's constants (never read past `len`).
        let blank = SamplePoint {
            n_px: 0,
            pixel: CLOSED_F32.pixel(&scene.camera, 0.0)?,
        };
        let mut segments = [Segment {
            index: 0,
            samples: [blank; SAMPLES_PER_SEGMENT],
        }; MAX_SEGMENTS];
        for (k, seg) in (0..layout.segments).zip(segments.iter_mut().take(count)) {
            let offsets = sample_offsets(layout.first_px, layout.segment_px, k)
                .ok_or(FirmwareError::Layout)?;
            seg.index = u8::try_from(k).map_err(|_| FirmwareError::Layout)?;
            for (sample, n) in seg.samples.iter_mut().zip(offsets) {
                sample.n_px = n;
                sample.pixel = CLOSED_F32.pixel(&scene.camera, f64::from(n))?;
            }
        }
        Ok(Plan {
            segments,
            len: count,
            // Rounded once; the line period is pixel / |v| in f32.
            pixel_m: scene.camera.pixel_m as f32,
            clock_hz: scene.line_clock_hz,
        })
    }

    /// The segments of the scene, in order.
    pub fn segments(&self) -> impl Iterator<Item = &Segment> {
        self.segments.iter().take(self.len)
    }

    /// Per-update constants (one call per telemetry update).
    pub fn update(&self, geometry: &Geometry<f32>) -> Result<UpdateConst<f32>, FirmwareError> {
        Ok(CLOSED_F32.update(geometry)?)
    }

    /// Velocity and line period at one sample point.
    #[inline]
    pub fn point(
        &self,
        update: &UpdateConst<f32>,
        sample: &SamplePoint,
    ) -> Result<PointReport, FirmwareError> {
        let motion = CLOSED_F32.motion(update, &sample.pixel)?;
        let speed = motion.speed_mps();
        let period = line_period_s(self.pixel_m, speed)?;
        let ticks = line_period_ticks(period, self.clock_hz)?;
        Ok(PointReport {
            n_px: sample.n_px,
            v1_mps: motion.v1_mps,
            v2_mps: motion.v2_mps,
            speed_mps: speed,
            period_s: period,
            ticks: ticks.ticks,
        })
    }

    /// Velocity and line period at every sample point of one segment.
    pub fn segment_report(
        &self,
        update: &UpdateConst<f32>,
        segment: &Segment,
    ) -> Result<SegmentReport, FirmwareError> {
        let mut report = SegmentReport {
            index: segment.index,
            points: [EMPTY_POINT; SAMPLES_PER_SEGMENT],
        };
        for (out, sample) in report.points.iter_mut().zip(segment.samples.iter()) {
            *out = self.point(update, sample)?;
        }
        Ok(report)
    }
}

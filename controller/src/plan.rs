//! The scene plan: built once when a scene arrives, so that per update only what the
//! scene needs is evaluated. Inactive segments have no entry at all; each active one
//! has its sample points' constants ready.

use core_math::closed_form::PixelConst;
use core_math::{Backend, StageRule, CLOSED_F32};

use crate::fault::Fault;
use crate::scene::{Scene, MAX_SEGMENTS};

/// Most field points one segment may be sampled at.
pub const MAX_SAMPLES: usize = 5;

/// One active segment, ready to evaluate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentPlan {
    /// Index in the scene's segment table.
    pub index: u8,
    pub tdi_stages: u16,
    pub samples: [PixelConst<f32>; MAX_SAMPLES],
    pub n_samples: u8,
    /// Pixel offsets of the samples (for reports and tests).
    pub sample_px: [i32; MAX_SAMPLES],
}

impl SegmentPlan {
    pub fn samples(&self) -> &[PixelConst<f32>] {
        &self.samples[..usize::from(self.n_samples)]
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    pub segments: [SegmentPlan; MAX_SEGMENTS],
    /// Number of active segments (entries in `segments`).
    pub count: u8,
    pub pixel_m: f32,
    pub line_clock_hz: f32,
    pub stage_rule: StageRule<f32>,
    pub max_stages: u16,
    pub max_roll_rad: f32,
}

impl Plan {
    /// The plan of a validated scene. Samples: both ends and the centre of each segment.
    pub fn new(scene: &Scene) -> Result<Plan, Fault> {
        scene.validate()?;
        let blank_pixel = CLOSED_F32
            .pixel(&scene.camera, 0.0)
            .map_err(|_| Fault::InvalidScene)?;
        let blank = SegmentPlan {
            index: 0,
            tdi_stages: 1,
            samples: [blank_pixel; MAX_SAMPLES],
            n_samples: 0,
            sample_px: [0; MAX_SAMPLES],
        };
        let mut segments = [blank; MAX_SEGMENTS];
        let mut count = 0usize;
        for (index, spec) in scene.active() {
            let slot = segments.get_mut(count).ok_or(Fault::InvalidScene)?;
            let centre = ((i64::from(spec.first_px) + i64::from(spec.last_px)) / 2) as i32;
            let points = [spec.first_px, centre, spec.last_px];
            slot.index = index as u8;
            slot.tdi_stages = spec.tdi_stages;
            for (k, n) in points.iter().enumerate() {
                slot.samples[k] = CLOSED_F32
                    .pixel(&scene.camera, f64::from(*n))
                    .map_err(|_| Fault::InvalidScene)?;
                slot.sample_px[k] = *n;
            }
            slot.n_samples = points.len() as u8;
            count += 1;
        }
        Ok(Plan {
            segments,
            count: count as u8,
            pixel_m: scene.camera.pixel_m as f32,
            line_clock_hz: scene.line_clock_hz as f32,
            stage_rule: StageRule::new(f64::from(scene.mtf_floor))
                .map_err(|_| Fault::InvalidScene)?,
            max_stages: scene.max_stages,
            max_roll_rad: scene.max_roll_rad,
        })
    }

    pub fn active(&self) -> &[SegmentPlan] {
        &self.segments[..usize::from(self.count)]
    }
}

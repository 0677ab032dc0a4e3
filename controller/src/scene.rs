//! The imaging scene: focal plane, detector segments, TDI stages, MTF floor, line clock.
//! Uploaded by a SCENE frame; a default (the paper's camera) is in force from boot.

use core_math::{Camera, StageRule};

use crate::bytes::{Reader, Writer};
use crate::fault::Fault;

/// Capacity of the segment table.
pub const MAX_SEGMENTS: usize = 16;
/// Largest TDI stage count a scene may configure. TDI sensors stop at 256 stages, and
/// beyond it a segment's mismatch budget (0.35 / M at MTF 0.95) falls below the drift
/// one update period allows during a manoeuvre (docs/controller.md, "The update rate"),
/// so no scene could hold its MTF floor with more.
pub const MAX_TDI_STAGES: u16 = 256;
/// Fixed part of the SCENE payload, then [`SEGMENT_LEN`] bytes per segment.
pub const SCENE_HEADER_LEN: usize = 36;
pub const SEGMENT_LEN: usize = 12;

/// One detector segment (a chip of the mosaic): pixels `first_px..=last_px` counted from
/// the array centre, as in the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct SegmentSpec {
    pub first_px: i32,
    pub last_px: i32,
    pub tdi_stages: u16,
    pub active: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scene {
    pub camera: Camera,
    /// Frequency of the counter the period registers count (Hz).
    pub line_clock_hz: f64,
    /// Smallest acceptable MTF_mismatch at Nyquist (default 0.95).
    pub mtf_floor: f32,
    /// Largest |roll| the scene will be imaged at (rad): the planner's envelope.
    pub max_roll_rad: f32,
    /// Largest TDI stage count the sensor can select.
    pub max_stages: u16,
    pub segments: [SegmentSpec; MAX_SEGMENTS],
    pub count: u8,
}

impl Scene {
    /// The paper's camera: f 555 mm, 13 um pixels, 60 000 pixels as 10 chips of 6 000,
    /// all active, 16 TDI stages, MTF floor 0.95, a 10 MHz line clock, roll up to 25 deg.
    pub fn paper_default() -> Scene {
        let mut segments = [SegmentSpec::default(); MAX_SEGMENTS];
        for (k, s) in segments.iter_mut().take(10).enumerate() {
            let first = -30_000 + 6_000 * k as i32;
            *s = SegmentSpec {
                first_px: first,
                last_px: first + 5_999,
                tdi_stages: 16,
                active: true,
            };
        }
        Scene {
            camera: Camera {
                focal_m: 0.555,
                pixel_m: 13e-6,
            },
            line_clock_hz: 10e6,
            mtf_floor: 0.95,
            max_roll_rad: 25f32.to_radians(),
            max_stages: 96,
            segments,
            count: 10,
        }
    }

    pub fn active(&self) -> impl Iterator<Item = (usize, &SegmentSpec)> {
        self.segments
            .iter()
            .take(usize::from(self.count))
            .enumerate()
            .filter(|(_, s)| s.active)
    }

    /// Everything a plan needs to hold: the optics, the clock, the floor, each segment.
    pub fn validate(&self) -> Result<(), Fault> {
        self.camera.validate().map_err(|_| Fault::InvalidScene)?;
        let clock_ok = self.line_clock_hz.is_finite()
            && self.line_clock_hz >= 1.0
            && self.line_clock_hz <= 1e9;
        let roll_ok = self.max_roll_rad.is_finite() && (0.0..=1.2).contains(&self.max_roll_rad);
        if !clock_ok || !roll_ok || StageRule::<f32>::new(f64::from(self.mtf_floor)).is_err() {
            return Err(Fault::InvalidScene);
        }
        if self.count == 0
            || usize::from(self.count) > MAX_SEGMENTS
            || self.max_stages == 0
            || self.max_stages > MAX_TDI_STAGES
            || self.active().next().is_none()
        {
            return Err(Fault::InvalidScene);
        }
        // Segments are chips of one array: in order along it, none overlapping another.
        let mut previous_last: Option<i32> = None;
        for s in self.segments.iter().take(usize::from(self.count)) {
            if s.first_px > s.last_px
                || previous_last.is_some_and(|p| s.first_px <= p)
                || s.tdi_stages == 0
                || s.tdi_stages > self.max_stages
            {
                return Err(Fault::InvalidScene);
            }
            previous_last = Some(s.last_px);
            for n in [s.first_px, s.last_px] {
                self.camera
                    .tan_field(f64::from(n))
                    .map_err(|_| Fault::InvalidScene)?;
            }
        }
        Ok(())
    }

    pub fn decode(payload: &[u8]) -> Result<Scene, Fault> {
        let mut r = Reader::new(payload);
        let bad = Fault::BadLength;
        let focal_m = r.f64().ok_or(bad)?;
        let pixel_m = r.f64().ok_or(bad)?;
        let line_clock_hz = r.f64().ok_or(bad)?;
        let mtf_floor = r.f32().ok_or(bad)?;
        let max_roll_rad = r.f32().ok_or(bad)?;
        let max_stages = r.u16().ok_or(bad)?;
        let count = r.u8().ok_or(bad)?;
        let _reserved = r.u8().ok_or(bad)?;
        // A length that matches its own count is well formed, even when the count is
        // more than the table holds: that is a scene the camera cannot use.
        if payload.len() != SCENE_HEADER_LEN + usize::from(count) * SEGMENT_LEN {
            return Err(Fault::BadLength);
        }
        if usize::from(count) > MAX_SEGMENTS {
            return Err(Fault::InvalidScene);
        }
        let mut segments = [SegmentSpec::default(); MAX_SEGMENTS];
        for s in segments.iter_mut().take(usize::from(count)) {
            let first_px = r.i32().ok_or(bad)?;
            let last_px = r.i32().ok_or(bad)?;
            let tdi_stages = r.u16().ok_or(bad)?;
            let active = match r.u8().ok_or(bad)? {
                0 => false,
                1 => true,
                _ => return Err(Fault::InvalidScene),
            };
            let _reserved = r.u8().ok_or(bad)?;
            *s = SegmentSpec {
                first_px,
                last_px,
                tdi_stages,
                active,
            };
        }
        if !r.is_done() {
            return Err(Fault::BadLength);
        }
        let floats = [
            focal_m,
            pixel_m,
            line_clock_hz,
            f64::from(mtf_floor),
            f64::from(max_roll_rad),
        ];
        if !floats.iter().all(|x| x.is_finite()) {
            return Err(Fault::NonFinite);
        }
        let scene = Scene {
            camera: Camera { focal_m, pixel_m },
            line_clock_hz,
            mtf_floor,
            max_roll_rad,
            max_stages,
            segments,
            count,
        };
        scene.validate()?;
        Ok(scene)
    }

    pub fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let mut w = Writer::new(out);
        w.put(&self.camera.focal_m.to_le_bytes())?;
        w.put(&self.camera.pixel_m.to_le_bytes())?;
        w.put(&self.line_clock_hz.to_le_bytes())?;
        w.put(&self.mtf_floor.to_le_bytes())?;
        w.put(&self.max_roll_rad.to_le_bytes())?;
        w.put(&self.max_stages.to_le_bytes())?;
        w.put(&[self.count, 0])?;
        for s in self.segments.iter().take(usize::from(self.count)) {
            w.put(&s.first_px.to_le_bytes())?;
            w.put(&s.last_px.to_le_bytes())?;
            w.put(&s.tdi_stages.to_le_bytes())?;
            w.put(&[u8::from(s.active), 0])?;
        }
        Some(w.len())
    }
}

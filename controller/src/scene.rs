//! The imaging scene: focal plane, detector segments (their stagger and the height of
//! the ground each one images), TDI stages, MTF floor, line clock, and the attitude
//! envelope the camera is planned for. Uploaded by a SCENE frame; a default (the
//! paper's camera) is in force from boot. TERRAIN frames update the ground heights in
//! flight ([`Terrain`]).

use core_math::earth::EarthCamera;
use core_math::{Camera, Ellipsoid, StageRule};

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
pub const SCENE_HEADER_LEN: usize = 44;
pub const SEGMENT_LEN: usize = 20;
/// The optional end of a SCENE payload (version 4): the camera's mounting quaternion.
pub const MOUNTING_LEN: usize = 16;
/// The identity quaternion: the camera's axes are the body's.
pub const IDENTITY_MOUNTING: [f32; 4] = [1.0, 0.0, 0.0, 0.0];
/// Ground heights a segment may image (m above the WGS 84 ellipsoid): the Dead Sea
/// shore to above Everest.
pub const MIN_GROUND_H_M: f32 = -500.0;
pub const MAX_GROUND_H_M: f32 = 9_000.0;
/// Largest |p1| / f of a segment's line (a stagger of up to a tenth of the focal
/// length; real mosaics stagger by millimetres).
pub const MAX_P1_OVER_F: f64 = 0.1;
/// Largest attitude angle and rate a scene's envelope may allow (rad, rad/s).
pub const MAX_ENVELOPE_ANGLE_RAD: f32 = 1.2;
pub const MAX_ENVELOPE_RATE_RAD_S: f32 = 0.2;

/// One detector segment (a chip of the mosaic): pixels `first_px..=last_px` counted from
/// the array centre along P2, its line at `p1_m` along P1 (the TDI direction).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SegmentSpec {
    pub first_px: i32,
    pub last_px: i32,
    pub tdi_stages: u16,
    pub active: bool,
    /// Along-track position of the chip's line on the focal plane (m): a staggered
    /// mosaic puts alternate chips ahead of and behind the optical axis.
    pub p1_m: f32,
    /// Height above the ellipsoid of the ground the segment images (m), until a
    /// TERRAIN frame changes it.
    pub ground_h_m: f32,
}

impl SegmentSpec {
    /// The segment's centre pixel (may fall between two pixels).
    pub fn centre_px(&self) -> f64 {
        0.5 * (f64::from(self.first_px) + f64::from(self.last_px))
    }
}

/// The attitudes the scene is imaged at: every NAV frame must stay inside, at its own
/// instant and propagated at its rates to every update it may serve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeEnvelope {
    /// Largest |roll| and |pitch| (rad). Yaw is free (yaw steering may take any value).
    pub max_roll_rad: f32,
    pub max_pitch_rad: f32,
    /// Largest |rate| of each angle (rad/s).
    pub max_rate_rad_s: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scene {
    /// Focal length and pixel pitch (m).
    pub camera: Camera,
    /// Frequency of the counter the period registers count (Hz).
    pub line_clock_hz: f64,
    /// Smallest acceptable MTF at Nyquist, mismatch times drift smear (default 0.95).
    pub mtf_floor: f32,
    pub envelope: AttitudeEnvelope,
    /// Largest TDI stage count the sensor can select.
    pub max_stages: u16,
    pub segments: [SegmentSpec; MAX_SEGMENTS],
    pub count: u8,
    /// The camera's mounting on the body (Part II's `cam_q`): `w, x, y, z`, scalar
    /// first, x_body = R(q) x_camera. Used with the bus's ATTITUDE frames; a NAV
    /// frame's attitude is the camera's own. Identity unless the SCENE payload ends
    /// with one.
    pub mounting_q: [f32; 4],
}

/// Pixel `n` of `camera` looks inside the limb whose tangent (off the optical axis) is
/// `tan_limb`; refused (`invalid_scene`) otherwise or if the pixel is off its optics'
/// domain.
// Out of line: the scene's check of each segment's two ends held a copy each.
#[inline(never)]
fn inside_limb(camera: &EarthCamera, n: i32, tan_limb: f64) -> Result<(), Fault> {
    let (p1, p2) = camera
        .focal_plane_m(f64::from(n))
        .map_err(|_| Fault::InvalidScene)?;
    let tan_off_axis = core_math::sqrt_f64(p1 * p1 + p2 * p2) / camera.focal_m;
    if !(tan_off_axis < tan_limb) {
        return Err(Fault::InvalidScene);
    }
    Ok(())
}

impl Scene {
    /// The paper's camera: f 555 mm, 13 um pixels, 60 000 pixels as 10 chips of 6 000
    /// on one line (no stagger), all active, 16 TDI stages, MTF floor 0.95, a 10 MHz line
    /// clock, ground at the ellipsoid. Envelope: roll and pitch up to 25 deg (with the
    /// 35 deg half field the far pixel then looks 60 deg off nadir, 4 deg inside the limb
    /// from 800 km), rates up to 1.5 deg/s (an agile imager's stereo and strip
    /// manoeuvres).
    // Out of line: the boot builds it in two places, and inlined each wrote the whole
    // table field by field (docs/target.md, flash).
    #[inline(never)]
    pub fn paper_default() -> Scene {
        let mut segments = [SegmentSpec::default(); MAX_SEGMENTS];
        for (k, s) in segments.iter_mut().take(10).enumerate() {
            let first = -30_000 + 6_000 * k as i32;
            *s = SegmentSpec {
                first_px: first,
                last_px: first + 5_999,
                tdi_stages: 16,
                active: true,
                p1_m: 0.0,
                ground_h_m: 0.0,
            };
        }
        Scene {
            camera: Camera {
                focal_m: 0.555,
                pixel_m: 13e-6,
            },
            line_clock_hz: 10e6,
            mtf_floor: 0.95,
            envelope: AttitudeEnvelope {
                max_roll_rad: 25f32.to_radians(),
                max_pitch_rad: 25f32.to_radians(),
                max_rate_rad_s: 1.5f32.to_radians(),
            },
            max_stages: 96,
            segments,
            count: 10,
            mounting_q: IDENTITY_MOUNTING,
        }
    }

    pub fn active(&self) -> impl Iterator<Item = (usize, &SegmentSpec)> {
        self.segments
            .iter()
            .take(usize::from(self.count))
            .enumerate()
            .filter(|(_, s)| s.active)
    }

    /// Whether segment `k`'s output under `old` (its period, held or not, and what its
    /// record says of it) still holds under this scene: the same camera, line clock,
    /// MTF floor, envelope (the period bounds) and stage limit, and the same chip,
    /// active in both (its pixels, line p1 and stages). Only the ground height may
    /// differ: a TERRAIN frame changes it as well, without dropping a held period.
    pub fn keeps_output_of(&self, old: &Scene, k: usize) -> bool {
        let same_camera = self.camera == old.camera
            && self.line_clock_hz == old.line_clock_hz
            && self.mtf_floor == old.mtf_floor
            && self.envelope == old.envelope
            && self.max_stages == old.max_stages
            && self.mounting_q == old.mounting_q;
        let chip = |s: &Scene| {
            s.table().get(k).filter(|c| c.active).map(|c| SegmentSpec {
                ground_h_m: 0.0,
                ..*c
            })
        };
        same_camera && chip(self).is_some() && chip(self) == chip(old)
    }

    /// Clears `kept[k]` for each segment k whose output under `old` does not hold
    /// under this scene ([`Scene::keeps_output_of`]).
    // Out of line with its loop: inlined into the install, the loop was unrolled, a
    // call and its test per segment (docs/target.md, flash).
    #[inline(never)]
    pub fn keep_outputs_of(&self, old: &Scene, kept: &mut [bool]) {
        for (k, kept) in kept.iter_mut().enumerate() {
            *kept = *kept && self.keeps_output_of(old, k);
        }
    }

    /// The table's entries (active or not).
    pub fn table(&self) -> &[SegmentSpec] {
        &self.segments[..usize::from(self.count).min(MAX_SEGMENTS)]
    }

    /// The real-Earth model's camera of one segment: the scene's optics, the segment's
    /// line position.
    pub fn earth_camera(&self, spec: &SegmentSpec) -> EarthCamera {
        EarthCamera {
            focal_m: self.camera.focal_m,
            pixel_m: self.camera.pixel_m,
            p1_m: f64::from(spec.p1_m),
        }
    }

    /// Everything a plan needs to hold: the optics, the clock, the floor, the envelope,
    /// each segment; and every pixel must see the Earth from the highest orbit of
    /// `altitude_max_m` at zero attitude (a segment that cannot is no use to image).
    // Out of line: smaller than inlined into the plan build (docs/target.md, flash).
    #[inline(never)]
    pub fn validate(&self, ellipsoid: &Ellipsoid, altitude_max_m: f64) -> Result<(), Fault> {
        self.camera.validate().map_err(|_| Fault::InvalidScene)?;
        let clock_ok = self.line_clock_hz.is_finite()
            && self.line_clock_hz >= 1.0
            && self.line_clock_hz <= 1e9;
        let e = &self.envelope;
        let angle_ok = |x: f32| x.is_finite() && (0.0..=MAX_ENVELOPE_ANGLE_RAD).contains(&x);
        let envelope_ok = angle_ok(e.max_roll_rad)
            && angle_ok(e.max_pitch_rad)
            && e.max_rate_rad_s.is_finite()
            && (0.0..=MAX_ENVELOPE_RATE_RAD_S).contains(&e.max_rate_rad_s);
        let q = self.mounting_q.map(f64::from);
        let norm = core_math::sqrt_f64(q.iter().map(|x| x * x).sum::<f64>());
        if !(libm::fabs(norm - 1.0) <= core_math::earth::bus::MAX_QUATERNION_NORM_ERROR) {
            return Err(Fault::BadQuaternion);
        }
        if !clock_ok || !envelope_ok || self.stage_rule().is_err() {
            return Err(Fault::InvalidScene);
        }
        if self.count == 0
            || usize::from(self.count) > MAX_SEGMENTS
            || self.max_stages == 0
            || self.max_stages > MAX_TDI_STAGES
            || !self.table().iter().any(|s| s.active)
        {
            return Err(Fault::InvalidScene);
        }
        // The smallest limb angle: the polar radius seen from the highest orbit, as its
        // tangent b / sqrt(S^2 - b^2), S = a + h, that the off-axis angles' tangents are
        // compared with (no arc sine or arctangent: docs/target.md, flash).
        let (b, big_s) = (ellipsoid.b_m(), ellipsoid.a_m + altitude_max_m);
        let tan_limb = b / core_math::sqrt_f64((big_s - b) * (big_s + b));
        let f = self.camera.focal_m;
        // Segments are chips of one array: in order along it, none overlapping another.
        let mut previous_last: Option<i32> = None;
        for s in self.table() {
            let p1 = f64::from(s.p1_m);
            if s.first_px > s.last_px
                || previous_last.is_some_and(|p| s.first_px <= p)
                || s.tdi_stages == 0
                || s.tdi_stages > self.max_stages
                || !(libm::fabs(p1) <= MAX_P1_OVER_F * f)
                || !(MIN_GROUND_H_M..=MAX_GROUND_H_M).contains(&s.ground_h_m)
            {
                return Err(Fault::InvalidScene);
            }
            previous_last = Some(s.last_px);
            for n in [s.first_px, s.last_px] {
                inside_limb(&self.earth_camera(s), n, tan_limb)?;
            }
        }
        Ok(())
    }

    /// The stage rule of the scene's MTF floor.
    // Not inlined: the checks and the plan share one copy.
    #[inline(never)]
    pub fn stage_rule(&self) -> Result<StageRule<f32>, Fault> {
        StageRule::<f32>::new(f64::from(self.mtf_floor)).map_err(|_| Fault::InvalidScene)
    }

    /// Parses a SCENE payload; the physical checks are [`Scene::validate`]'s.
    // Not inlined: SCENE intake and a restore after a reset share one copy.
    #[inline(never)]
    pub fn decode(payload: &[u8]) -> Result<Scene, Fault> {
        let mut r = Reader::new(payload);
        let bad = Fault::BadLength;
        let focal_m = r.f64().ok_or(bad)?;
        let pixel_m = r.f64().ok_or(bad)?;
        let line_clock_hz = r.f64().ok_or(bad)?;
        let mtf_floor = r.f32().ok_or(bad)?;
        let max_roll_rad = r.f32().ok_or(bad)?;
        let max_pitch_rad = r.f32().ok_or(bad)?;
        let max_rate_rad_s = r.f32().ok_or(bad)?;
        let max_stages = r.u16().ok_or(bad)?;
        let count = r.u8().ok_or(bad)?;
        let _reserved = r.u8().ok_or(bad)?;
        // A length that matches its own count is well formed, even when the count is
        // more than the table holds: that is a scene the camera cannot use. The
        // mounting may follow the table.
        let table_len = SCENE_HEADER_LEN + usize::from(count) * SEGMENT_LEN;
        let with_mounting = payload.len() == table_len + MOUNTING_LEN;
        if payload.len() != table_len && !with_mounting {
            return Err(Fault::BadLength);
        }
        if usize::from(count) > MAX_SEGMENTS {
            return Err(Fault::InvalidScene);
        }
        let mut segments = [SegmentSpec::default(); MAX_SEGMENTS];
        let mut finite = true;
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
            let p1_m = r.f32().ok_or(bad)?;
            let ground_h_m = r.f32().ok_or(bad)?;
            finite &= p1_m.is_finite() && ground_h_m.is_finite();
            *s = SegmentSpec {
                first_px,
                last_px,
                tdi_stages,
                active,
                p1_m,
                ground_h_m,
            };
        }
        let mut mounting_q = IDENTITY_MOUNTING;
        if with_mounting {
            for x in mounting_q.iter_mut() {
                *x = r.f32().ok_or(bad)?;
            }
            finite &= mounting_q.iter().all(|x| x.is_finite());
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
            f64::from(max_pitch_rad),
            f64::from(max_rate_rad_s),
        ];
        if !finite || !floats.iter().all(|x| x.is_finite()) {
            return Err(Fault::NonFinite);
        }
        Ok(Scene {
            camera: Camera { focal_m, pixel_m },
            line_clock_hz,
            mtf_floor,
            envelope: AttitudeEnvelope {
                max_roll_rad,
                max_pitch_rad,
                max_rate_rad_s,
            },
            max_stages,
            segments,
            count,
            mounting_q,
        })
    }

    pub fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let mut w = Writer::new(out);
        w.put(&self.camera.focal_m.to_le_bytes())?;
        w.put(&self.camera.pixel_m.to_le_bytes())?;
        w.put(&self.line_clock_hz.to_le_bytes())?;
        w.put(&self.mtf_floor.to_le_bytes())?;
        w.put(&self.envelope.max_roll_rad.to_le_bytes())?;
        w.put(&self.envelope.max_pitch_rad.to_le_bytes())?;
        w.put(&self.envelope.max_rate_rad_s.to_le_bytes())?;
        w.put(&self.max_stages.to_le_bytes())?;
        w.put(&[self.count, 0])?;
        for s in self.segments.iter().take(usize::from(self.count)) {
            w.put(&s.first_px.to_le_bytes())?;
            w.put(&s.last_px.to_le_bytes())?;
            w.put(&s.tdi_stages.to_le_bytes())?;
            w.put(&[u8::from(s.active), 0])?;
            w.put(&s.p1_m.to_le_bytes())?;
            w.put(&s.ground_h_m.to_le_bytes())?;
        }
        // Version 3's layout whenever it says the same.
        if self.mounting_q != IDENTITY_MOUNTING {
            for x in self.mounting_q {
                w.put(&x.to_le_bytes())?;
            }
        }
        Some(w.len())
    }
}

/// A TERRAIN payload: the ground height of every segment of the scene's table (m above
/// the ellipsoid), in table order, in force from the frame's time tag.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terrain {
    pub heights_m: [f32; MAX_SEGMENTS],
    pub count: u8,
}

/// TERRAIN payload: count (u8), 3 reserved, then `count` f32 heights.
pub const TERRAIN_HEADER_LEN: usize = 4;

impl Terrain {
    /// Parses and checks a TERRAIN payload against the scene in force: one height per
    /// table entry (else `invalid_scene`), each finite (`non_finite`) and within
    /// [`MIN_GROUND_H_M`]..=[`MAX_GROUND_H_M`] (`out_of_range`).
    // Not inlined: TERRAIN intake and a restore after a reset share one copy.
    #[inline(never)]
    pub fn decode(payload: &[u8], scene: &Scene) -> Result<Terrain, Fault> {
        let mut r = Reader::new(payload);
        let count = r.u8().ok_or(Fault::BadLength)?;
        for _ in 0..3 {
            r.u8().ok_or(Fault::BadLength)?;
        }
        if payload.len() != TERRAIN_HEADER_LEN + 4 * usize::from(count) {
            return Err(Fault::BadLength);
        }
        if count != scene.count {
            return Err(Fault::InvalidScene);
        }
        let mut heights_m = [0.0f32; MAX_SEGMENTS];
        for h in heights_m.iter_mut().take(usize::from(count)) {
            *h = r.f32().ok_or(Fault::BadLength)?;
        }
        let heights = &heights_m[..usize::from(count).min(MAX_SEGMENTS)];
        if !heights.iter().all(|h| h.is_finite()) {
            return Err(Fault::NonFinite);
        }
        if !heights
            .iter()
            .all(|h| (MIN_GROUND_H_M..=MAX_GROUND_H_M).contains(h))
        {
            return Err(Fault::OutOfRange);
        }
        Ok(Terrain { heights_m, count })
    }

    pub fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let mut w = Writer::new(out);
        w.put(&[self.count, 0, 0, 0])?;
        for h in self.heights_m.iter().take(usize::from(self.count)) {
            w.put(&h.to_le_bytes())?;
        }
        Some(w.len())
    }
}

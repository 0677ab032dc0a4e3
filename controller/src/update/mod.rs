//! The update: state to periods. At every update instant, the NAV state (or the bus's
//! fix and attitude, [`crate::track`]) carried to it, each active segment's line period, its MTF (mismatch times drift smear) and TDI
//! stage limit, its drift angles, and the yaw steering request; the periods written
//! through a [`LinePeriodSink`]. A refused computation leaves that segment's last good
//! period in force, and nothing outside the physically possible period range is ever
//! written. Which parts are out of line, and why: docs/controller.md.

use core_math::earth::{GeneralInstant, GeneralRowMotion, GeneralUpdate};
use core_math::ImageMotion;
use core_math::{nearest_ticks, smear_mtf, Backend, Real, GENERAL_F32};

use crate::config::{EARTH, EARTH_RATE_RAD_S, MAX_TIME_TAG_US};
use crate::control::{Controller, Mode, SegmentOutput};
use crate::dem_ground::{
    motion_at_range, DemGround, DemStats, SampleGround, SegmentRays, TileRefusal,
};
use crate::fault::Fault;
use crate::nav::attitude_at;
use crate::plan::SegmentPlan;
use crate::sink::LinePeriodSink;
use crate::track::{self, ItrfFrame};

impl Controller {
    /// Whether the sample pixels are evaluated in fixed point: `Config::fixed_point_pixels`,
    /// or always with the feature `fixed-only`, which leaves the f32 route unlinked.
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    fn fixed_pixels(&self) -> bool {
        cfg!(feature = "fixed-only") || self.config.fixed_point_pixels
    }

    /// Moves the clock to `now_us` (from the time source) and runs the update that is due,
    /// if any, writing periods to `sink`. Returns true when an update ran.
    pub fn advance<S: LinePeriodSink>(&mut self, now_us: u64, sink: &mut S) -> bool {
        // The clock never passes the largest tag, whatever the time source says: past
        // it no frame could be accepted again.
        self.now_us = self.now_us.max(now_us.min(MAX_TIME_TAG_US));
        if self.now_us < self.next_update_us {
            return false;
        }
        // Only the latest due instant is computed: after a gap, catching up on missed
        // updates would only delay the current one.
        let period = self.config.update_period_us.max(1);
        // The instant due is the one scheduled, unless the clock has passed the next one
        // too or the period was changed: a 64-bit division (a software call here) only
        // then.
        let t = if period == self.scheduled_period_us && self.now_us - self.next_update_us < period
        {
            self.next_update_us
        } else {
            self.now_us - self.now_us % period
        };
        self.scheduled_period_us = period;
        // t <= MAX_TIME_TAG_US; saturating all the same, for any configured period.
        self.next_update_us = t.saturating_add(period);
        self.last_update_us = Some(t);
        self.updates = self.updates.saturating_add(1);
        let previous = self.update_mode;
        self.update_mode = self.mode_at(t);
        // One stale episode is a run of updates in mode stale: so the counter equals
        // the PERIODS frames in mode stale whose predecessor was not.
        if self.update_mode == Mode::Stale && previous != Mode::Stale {
            self.reject(Fault::Stale);
        }
        self.update_at(t, sink);
        true
    }

    fn update_at<S: LinePeriodSink>(&mut self, t_us: u64, sink: &mut S) {
        self.yaw_request_rad = None;
        // The satellite and the camera in the ITRF: the DEM's ground needs them, and
        // only the bus's frames give them (NAV's frame has no longitude).
        let mut itrf: Option<ItrfFrame> = None;
        let instant = match (&self.nav, &self.gnss, &self.attitude) {
            (Some(nav), _, _) if self.update_mode != Mode::Stale => {
                let dt_s = seconds_since(t_us, nav.time_us);
                let state = nav.propagator.parts_at(dt_s);
                let attitude = attitude_at(&nav.attitude, dt_s);
                GENERAL_F32.instant_parts(
                    state.position_m,
                    state.velocity_mps,
                    state.r2_minus_a2_m2,
                    &attitude,
                    EARTH_RATE_RAD_S as f32,
                )
            }
            (None, Some(gnss), Some(attitude)) if self.update_mode != Mode::Stale => {
                track::instant_in_itrf(
                    gnss,
                    attitude,
                    seconds_since(t_us, gnss.fix_us),
                    seconds_since(t_us, attitude.received.valid_us),
                )
                .map(|(instant, frame)| {
                    itrf = Some(frame);
                    instant
                })
            }
            (None, None, _) | (None, _, None) => return,
            _ => {
                self.hold_planned();
                return;
            }
        };
        let instant = match instant {
            Ok(i) => i,
            Err(e) => {
                self.reject(Fault::from(e));
                self.hold_planned();
                return;
            }
        };
        // The yaw steering request: at the boresight a turn about it turns (v1, v2) by
        // the turn and changes nothing else, so atan(v2/v1) there zeroes its drift.
        // Segments over the same ground height share its update: made once per height
        // in a row (a flat scene makes one, terrain one per segment). It stays in one
        // place in memory, which the out-of-line `segment` and `extremes` read.
        let (steer, mut ground_h_m, mut ground) = self.steer_and_ground(&instant);
        self.yaw_request_rad = steer.map(|(_, _, rad)| rad);
        // Output slots by `get` (`index` < MAX_SEGMENTS by construction of the plan): no
        // panic path (docs/no-panic.md).
        // The DEM's route needs a tile in force and the ITRF of the instant.
        let dem_frame = if self.dem_ground.is_some() {
            itrf
        } else {
            None
        };
        for k in 0..self.plan.segments.len() {
            let Some(seg) = self.plan.segments.get(k) else {
                break;
            };
            let index = seg.index;
            let height_m = self.height(index);
            // NaN never equals: the first segment makes the first ground.
            if height_m != ground_h_m {
                ground = self.make_ground(&instant, height_m, steer);
                ground_h_m = height_m;
            }
            let result = match (&ground, &dem_frame) {
                (Err(f), _) => Err(*f),
                // With a DEM tile in force, each sample's own ground on it.
                (Ok(update), Some(frame)) => self
                    .dem_segment(k, frame, update, &instant, height_m)
                    .and_then(|e| match self.plan.segments.get(k) {
                        Some(seg) => self.segment(update, seg, steer, Some(&e)),
                        None => Err(Fault::InvalidScene),
                    }),
                (Ok(update), _) => self.segment(update, seg, steer, None),
            };
            let slot = usize::from(index);
            match result {
                Ok(out) => {
                    // Only a period inside the physical range reaches a register.
                    if sink.write_period(index, out.ticks).is_ok() {
                        if let (Some(o), Some(h)) =
                            (self.outputs.get_mut(slot), self.has_output.get_mut(slot))
                        {
                            *o = out;
                            *h = true;
                        }
                    } else {
                        // The register kept its old period: report it as held, not as
                        // the new value.
                        self.hold(index);
                    }
                }
                Err(f) => {
                    self.reject(f);
                    self.hold(index);
                }
            }
        }
    }

    /// The segment's [`Extremes`] by the configured backend.
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    fn extremes(&self, update: &Ground, seg: &SegmentPlan) -> Result<Extremes, Fault> {
        extremes(update, seg)
    }

    /// The segment's [`Extremes`] by the configured backend.
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    fn extremes(&self, update: &Ground, seg: &SegmentPlan) -> Result<Extremes, Fault> {
        if self.fixed_pixels() {
            extremes_fixed(update, seg)
        } else {
            extremes(&update.float, seg)
        }
    }

    /// The MTF at `stages` under the mismatch `worst` and the drift tangent `tan_max`,
    /// and the stage limit, in f32.
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    fn mtf_and_stages(&self, stages: u32, worst: f32, tan_max: f32) -> Result<(f32, u32), Fault> {
        mtf_and_stages_f32(&self.plan, stages, worst, tan_max)
    }

    /// The same by the configured backend: with fixed-point pixels, every sinc in Q30
    /// integers (`core_math::mtf::int`; soft float on the M3 made them a third of an
    /// update: docs/controller.md, "What it costs").
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    fn mtf_and_stages(&self, stages: u32, worst: f32, tan_max: f32) -> Result<(f32, u32), Fault> {
        if self.fixed_pixels() {
            let mtf = core_math::mtf::int::smear_mtf_pair(stages, worst, tan_max);
            let m = self
                .plan
                .stage_rule
                .max_stages_with_drift_int(worst, tan_max, u32::from(self.plan.max_stages))
                .map_err(Fault::from)?;
            Ok((mtf, m))
        } else {
            mtf_and_stages_f32(&self.plan, stages, worst, tan_max)
        }
    }

    /// (v2, v1) at the segment's centre seen by the camera turned by the yaw request.
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    fn steered_centre(
        &self,
        update: &Ground,
        seg: &SegmentPlan,
        sin: f32,
        cos: f32,
    ) -> Result<(f32, f32), Fault> {
        let m = steered_centre(update, seg, sin, cos)?;
        Ok((m.v2_mps, m.v1_mps))
    }

    /// The drift angles at the centre, the worst, and the steered centre's (the
    /// centre's without a request), from their tangents.
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    fn drift_angles(
        &self,
        centre: &ImageMotion<f32>,
        _drift: (f32, f32),
        tan_max: f32,
        residual: Option<(f32, f32)>,
    ) -> [f32; 3] {
        drift_angles_f32(centre, tan_max, residual)
    }

    /// The same by the configured backend: with fixed-point pixels each angle from its
    /// (v2, v1) pair in integers ([`atan_pair_rad`]), the worst never below the
    /// centre's magnitude.
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    fn drift_angles(
        &self,
        centre: &ImageMotion<f32>,
        drift: (f32, f32),
        tan_max: f32,
        residual: Option<(f32, f32)>,
    ) -> [f32; 3] {
        if self.fixed_pixels() {
            let centre_rad = atan_pair_rad(centre.v2_mps, centre.v1_mps);
            let worst_rad = atan_pair_rad(drift.0, drift.1);
            let worst_rad = if worst_rad < centre_rad.abs() {
                centre_rad.abs()
            } else {
                worst_rad
            };
            let residual_rad = match residual {
                Some((v2, v1)) => atan_pair_rad(v2, v1),
                None => centre_rad,
            };
            [centre_rad, worst_rad, residual_rad]
        } else {
            drift_angles_f32(centre, tan_max, residual)
        }
    }

    /// The same by the configured backend: with fixed-point pixels, the centre's
    /// `EARTH_FIXED.motion` on the ground's turned update (integers only), the f32 form
    /// where the turn left the envelope.
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    fn steered_centre(
        &self,
        update: &Ground,
        seg: &SegmentPlan,
        sin: f32,
        cos: f32,
    ) -> Result<(f32, f32), Fault> {
        match (&update.yawed, seg.fixed.first()) {
            // The pair in I24F40 units: only its ratio is used.
            (Some(up), Some(px)) => {
                let m = core_math::EARTH_FIXED.motion(up, px)?;
                Ok((m.v2_mps.to_bits() as f32, m.v1_mps.to_bits() as f32))
            }
            _ => {
                let m = steered_centre(&update.float, seg, sin, cos)?;
                Ok((m.v2_mps, m.v1_mps))
            }
        }
    }

    /// The yaw request's (sin, cos, angle) from the boresight's motion, and the first
    /// ground of the update with its height (none yet: NaN never equals a height).
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    fn steer_and_ground(
        &self,
        instant: &GeneralInstant<f32>,
    ) -> (Steer, f32, Result<Ground, Fault>) {
        (self.steer_f32(instant), f32::NAN, Err(Fault::OutOfRange))
    }

    /// The same by the configured backend. With fixed-point pixels the boresight
    /// segment's ground comes first (the loop then reuses it for every segment at its
    /// height), and the request from its fixed-point update: the boresight's v/f in
    /// integers (`EarthFixedUpdate::boresight_over_focal`) instead of a second f32
    /// ground and motion in soft float.
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    fn steer_and_ground(
        &self,
        instant: &GeneralInstant<f32>,
    ) -> (Steer, f32, Result<Ground, Fault>) {
        if !self.fixed_pixels() {
            return (self.steer_f32(instant), f32::NAN, Err(Fault::OutOfRange));
        }
        let boresight_h = self.height(self.plan.boresight_segment);
        let mut ground = self.make_ground(instant, boresight_h, None);
        let steer = match &ground {
            Ok(Ground { fixed: Some(f), .. }) => {
                f.boresight_over_focal().ok().and_then(|(vf1, vf2)| {
                    // Q63 rad/s, below 2^63: their squares stay inside f32's range.
                    let (v1, v2) = (vf1 as f32, vf2 as f32);
                    steer_from(v1, v2, atan_pair_rad(v2, v1))
                })
            }
            _ => None,
        };
        if let (Ok(g), Some((sin, cos, _))) = (&mut ground, steer) {
            g.yawed = g
                .fixed
                .as_ref()
                .and_then(|f| f.yawed(q30(sin), q30(cos)).ok());
        }
        (steer, boresight_h, ground)
    }

    /// The yaw request from the boresight's motion in f32 at the boresight segment's
    /// height.
    #[inline(always)]
    fn steer_f32(&self, instant: &GeneralInstant<f32>) -> Option<(f32, f32, f32)> {
        let boresight_h = self.height(self.plan.boresight_segment);
        GENERAL_F32
            .ground(instant, &EARTH, boresight_h)
            .and_then(|u| GENERAL_F32.motion(&u, &self.plan.boresight))
            .ok()
            .and_then(|m| steer_from(m.v1_mps, m.v2_mps, drift_angle_rad(m.v2_mps / m.v1_mps)))
    }

    fn height(&self, index: u8) -> f32 {
        self.heights_m
            .get(usize::from(index))
            .copied()
            .unwrap_or(0.0)
    }

    /// Out of line, so that the plan's values it reads are loaded where they are used:
    /// inlined into the update's loop, they were hoisted out of it into registers that
    /// every call in the segment's work then saved and restored (the counts:
    /// docs/controller.md, "What it costs").
    #[inline(never)]
    fn segment(
        &self,
        update: &Ground,
        seg: &SegmentPlan,
        steer: Option<(f32, f32, f32)>,
        dem: Option<&Extremes>,
    ) -> Result<SegmentOutput, Fault> {
        // |v1| extremes and the largest |v2/v1| over the samples and the centre; every
        // one must move the same way along P1 (one transfer direction per segment). In
        // forward flight the image moves towards -P1 (the ground runs backwards under
        // the camera); towards +P1 is the reversed transfer.
        // The samples and the centre lie on the segment's row: its constants once, then
        // about twenty operations a pixel.
        let Extremes {
            centre,
            lo,
            hi,
            drift_v2,
            drift_v1,
        } = match dem {
            Some(e) => *e,
            None => self.extremes(update, seg)?,
        };
        let reversed = centre.v1_mps > 0.0;
        // v1's extremes are tracked signed, and its sign checked once after the loop;
        // the largest |v2/v1| as the pair (|v2|, |v1|) that gives it, compared by
        // cross-multiplying (|v1| > 0): one division at the end, not one a pixel. The loop
        // keeps no error exit of its own, so none of the exit's work is hoisted into it.
        // Every sample must move the same way as the centre (one transfer direction per
        // segment).
        let (v_min, v_max) = if reversed { (lo, hi) } else { (-hi, -lo) };
        if !(v_min > 0.0) {
            return Err(Fault::PeriodOutOfRange);
        }
        let tan_max = drift_v2 / drift_v1;
        // The period minimising the worst relative mismatch over [v_min, v_max]: the
        // line speed equal to the harmonic mean of the extremes, i.e. the mean of the
        // extremes' periods.
        let a = self.plan.pixel_m;
        let period_s = 0.5 * (a / v_min + a / v_max);
        let (lo, hi) = self.plan.period_bounds_s;
        if !(period_s >= lo && period_s <= hi) {
            return Err(Fault::PeriodOutOfRange);
        }
        // The clock was checked when the scene arrived and the period just above:
        // only the rounding to whole ticks is left (`line_period_ticks` less its input
        // checks, a tenth of a segment's work).
        let ticks = nearest_ticks(period_s * self.plan.line_clock_hz).map_err(Fault::from)?;
        // The mismatch of the period actually programmed, rounding to ticks included,
        // against the range v1 may take between the samples.
        let v_line = a * self.plan.line_clock_hz / ticks as f32;
        let (v_lo, v_hi) = (v_min - seg.interpolation_mps, v_max + seg.interpolation_mps);
        let stages = u32::from(seg.tdi_stages);
        let (worst_mismatch, mtf, max_stages) = if v_lo > 0.0 {
            let (below, above) = ((v_line / v_lo - 1.0).abs(), (1.0 - v_line / v_hi).abs());
            let worst = if below > above { below } else { above };
            let (mtf, m) = self.mtf_and_stages(stages, worst, tan_max)?;
            (worst, mtf, m as u16)
        } else {
            // The image is slower than the interpolation bound: no bound on the
            // mismatch, no contrast promised.
            (f32::MAX, 0.0, 0)
        };
        let residual = match steer {
            Some((sin, cos, _)) => Some(self.steered_centre(update, seg, sin, cos)?),
            None => None,
        };
        let [drift_rad, worst_drift_rad, residual_drift_rad] =
            self.drift_angles(&centre, (drift_v2, drift_v1), tan_max, residual);
        Ok(SegmentOutput {
            index: seg.index,
            ticks,
            worst_mismatch,
            mtf,
            max_stages,
            drift_rad,
            worst_drift_rad,
            residual_drift_rad,
            reversed,
            held: false,
        })
    }
}

/// The MTF and the stage limit in f32 (the M4F boards').
#[inline(always)]
fn mtf_and_stages_f32(
    plan: &crate::plan::Plan,
    stages: u32,
    worst: f32,
    tan_max: f32,
) -> Result<(f32, u32), Fault> {
    let half_pi_m = core::f32::consts::FRAC_PI_2 * stages as f32;
    // Each factor is |sinc|, the modulus of the smear's transfer function: past the
    // first zero the contrast is reversed and weaker, not gone (docs/controller.md, "Per
    // update"). In [0, 1]: the polynomial's (sinc(x) - 1) / x^2 part is negative on its
    // whole range, and past pi |sinc| < 1/pi.
    let mtf = smear_mtf(half_pi_m * worst) * smear_mtf(half_pi_m * tan_max);
    let m = plan
        .stage_rule
        .max_stages_with_drift(worst, tan_max, u32::from(plan.max_stages))
        .map_err(Fault::from)?;
    Ok((mtf, m))
}

/// The drift angles in f32 from their tangents (the centre's, the worst, the steered
/// centre's: the centre's without a request).
#[inline(always)]
fn drift_angles_f32(
    centre: &ImageMotion<f32>,
    tan_max: f32,
    residual: Option<(f32, f32)>,
) -> [f32; 3] {
    let tan_centre = centre.v2_mps / centre.v1_mps;
    let tan_residual = match residual {
        Some((v2, v1)) => v2 / v1,
        None => tan_centre,
    };
    drift_angles_rad(tan_centre, tan_max, tan_residual)
}

/// The yaw request as the turn's (sin, cos) and its angle (rad).
type Steer = Option<(f32, f32, f32)>;

/// The yaw turn (sin, cos) that zeroes the boresight's drift, from its (v1, v2) (any
/// common scale), and the request `rad`; None when they are not finite.
#[inline(always)]
fn steer_from(v1: f32, v2: f32, rad: f32) -> Option<(f32, f32, f32)> {
    let speed = Real::sqrt(v1 * v1 + v2 * v2);
    let sign = if v1 < 0.0 { -1.0 } else { 1.0 };
    let (sin, cos) = (sign * v2 / speed, sign * v1 / speed);
    (sin.is_finite() && cos.is_finite()).then_some((sin, cos, rad))
}

/// A sine or cosine in Q30 (|x| <= 1 to f32's rounding: inside i32).
#[cfg(feature = "earth-fixed")]
#[inline(always)]
fn q30(x: f32) -> i32 {
    (x * (1u32 << 30) as f32) as i32
}

/// The time from `t0_us` to `t_us` (s). Both are < 2^53 us and, where it is used,
/// t - t0 lies within an update period before and a staleness limit after: the
/// difference is exact in i64 and small in f32. Converted from i32 when it fits (one
/// instruction; from i64 it is a software call), to the same f32.
#[inline(always)]
fn seconds_since(t_us: u64, t0_us: u64) -> f32 {
    let dt_us = (t_us as i64).wrapping_sub(t0_us as i64);
    (match i32::try_from(dt_us) {
        Ok(dt) => dt as f32,
        Err(_) => i64_to_f32(dt_us),
    }) * 1e-6
}

/// `x as f32` out of line: inline, LLVM evaluated it (a software call) beside the
/// one-instruction i32 conversion on every update, then picked one.
#[cold]
#[inline(never)]
fn i64_to_f32(x: i64) -> f32 {
    x as f32
}

/// What the segments over one ground height are evaluated from: the f32 general form's
/// update (docs/controller.md, "Backends").
#[cfg(not(feature = "earth-fixed"))]
type Ground = GeneralUpdate<f32>;

/// What the segments over one ground height are evaluated from: the f32 update, which
/// the steered centre uses, and the same rounded to the fixed-point backend's formats,
/// which every sample pixel uses (docs/controller.md, "Backends").
#[cfg(feature = "earth-fixed")]
struct Ground {
    float: GeneralUpdate<f32>,
    /// None unless [`Controller::fixed_pixels`].
    fixed: Option<core_math::earth::fixed::EarthFixedUpdate>,
    /// `fixed` turned by the yaw request, for the steered centres; None without a
    /// request, or where the turn leaves the fixed formats' envelope.
    yawed: Option<core_math::earth::fixed::EarthFixedUpdate>,
}

impl Controller {
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    fn make_ground(
        &self,
        instant: &GeneralInstant<f32>,
        height_m: f32,
        _steer: Option<(f32, f32, f32)>,
    ) -> Result<Ground, Fault> {
        GENERAL_F32
            .ground(instant, &EARTH, height_m)
            .map_err(Fault::from)
    }

    /// The f32 update of the ground and, for fixed-point pixels, the same widened to
    /// f64 and rounded once to the fixed-point formats: per ground height, not per pixel.
    #[cfg(feature = "earth-fixed")]
    fn make_ground(
        &self,
        instant: &GeneralInstant<f32>,
        height_m: f32,
        steer: Option<(f32, f32, f32)>,
    ) -> Result<Ground, Fault> {
        let float = GENERAL_F32.ground(instant, &EARTH, height_m)?;
        let fixed = if self.fixed_pixels() {
            Some(fixed_update(&float, instant.r2_m2)?)
        } else {
            None
        };
        let yawed = match (&fixed, steer) {
            (Some(f), Some((sin, cos, _))) => f.yawed(q30(sin), q30(cos)).ok(),
            _ => None,
        };
        Ok(Ground {
            float,
            fixed,
            yawed,
        })
    }
}

/// `float` rounded to the fixed-point backend's formats, in integers
/// (`EarthFixed::from_general_f32`: within a unit and 1.7e-9 relative of the same
/// update widened to f64 and rounded there, which cost soft f64 on the M3).
#[cfg(feature = "earth-fixed")]
fn fixed_update(
    float: &GeneralUpdate<f32>,
    r2_m2: f32,
) -> Result<core_math::earth::fixed::EarthFixedUpdate, Fault> {
    Ok(core_math::EARTH_FIXED.from_general_f32(float, r2_m2)?)
}

#[cfg(not(feature = "earth-fixed"))]
#[inline(always)]
fn float(g: &Ground) -> &GeneralUpdate<f32> {
    g
}

#[cfg(feature = "earth-fixed")]
#[inline(always)]
fn float(g: &Ground) -> &GeneralUpdate<f32> {
    &g.float
}

mod dem;
mod sweep;

pub use sweep::drift_angle_rad;
use sweep::*;

#[cfg(test)]
mod tests {
    extern crate std;
    use super::drift_angles_rad;

    /// The three drift angles against atan in f64: the worst one by its difference form
    /// within 4 f32 ulp of 1 rad, never below the centre's magnitude.
    #[test]
    fn drift_angles_match_atan() {
        let mut rng = core_math::sample::SplitMix64(0x5EED_2026_1124);
        let mut next = || rng.uniform(0.0, 1.0);
        let mut worst_err = 0f64;
        for _ in 0..200_000 {
            // Tangents over drifts of 0 to 1.5 rad, either sign.
            let c = libm::tan(1.5 * next()) * if next() < 0.5 { -1.0 } else { 1.0 };
            let m = libm::fabs(c) + libm::tan(1.5 * next()) * next();
            let r = libm::tan(0.3 * next() - 0.15);
            let (c, m, r) = (c as f32, (m as f32).max((c as f32).abs()), r as f32);
            let [dc, dm, dr] = drift_angles_rad(c, m, r);
            for (got, t) in [(dc, c), (dm, m), (dr, r)] {
                let want = libm::atan(f64::from(t));
                worst_err = worst_err.max(libm::fabs(f64::from(got) - want));
            }
            assert!(dm >= dc.abs(), "{c} {m}: {dm} < |{dc}|");
        }
        assert!(
            worst_err <= 4.0 * f64::from(f32::EPSILON) / 2.0,
            "{worst_err:e}"
        );
        std::eprintln!("drift angles: worst error {worst_err:.2e} rad");
    }

    /// The integer drift angle of a (v2, v1) pair (the Cortex-M3's) against atan2 in
    /// f64 of the same f32 inputs: within 5e-9 rad plus half an f32 ulp of the result,
    /// over ratios from 1e-9 to 1e9, either sign, and the edge cases.
    #[cfg(feature = "earth-fixed")]
    #[test]
    fn integer_drift_angle_matches_atan() {
        use super::sweep::{atan_pair_rad, q30_to_f32};
        let mut rng = core_math::sample::SplitMix64(0x5EED_2026_1127);
        let mut worst_err = 0f64;
        let mut check = |num: f32, den: f32| {
            let got = f64::from(atan_pair_rad(num, den));
            let want = libm::atan(f64::from(num) / f64::from(den));
            let err = libm::fabs(got - want);
            assert!(
                err <= 5e-9 + 0.5 * f64::from(f32::EPSILON) * libm::fabs(want),
                "atan({num:e} / {den:e}) = {got} vs {want}"
            );
            worst_err = worst_err.max(err);
        };
        for _ in 0..400_000 {
            let den = (libm::exp(rng.uniform(-20.0, 20.0)) * rng.uniform(-1.0, 1.0)) as f32;
            let ratio = libm::exp(rng.uniform(-21.0, 21.0)) * rng.uniform(-1.0, 1.0);
            let num = (f64::from(den) * ratio) as f32;
            if den != 0.0 && den.is_normal() {
                check(num, den);
            }
        }
        for (num, den) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (1.0, 1.0),
            (-1.0, 1.0),
            (1.0, -1.0),
            (7_000.0, 1e-30),
            (1e-30, 7_000.0),
            (f32::MAX, 1.0),
            (1.0, f32::MAX),
            (f32::MIN_POSITIVE, 3.0),
        ] {
            check(num, den);
        }
        // Non-finite inputs and a zero denominator take atan_f32 of the quotient.
        assert_eq!(
            atan_pair_rad(1.0, 0.0),
            drift_angles_rad(f32::INFINITY, 0.0, 0.0)[0]
        );
        assert!(atan_pair_rad(f32::NAN, 1.0).is_nan());
        std::eprintln!("integer drift angle: worst error {worst_err:.2e} rad");
        // Q30 to f32 against the conversion and scaling in f32 (round to nearest even:
        // they may differ at exact ties only, by one ulp).
        let mut x = 0x9E37_79B9u32;
        for i in 0..1_000_000u32 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let q = x >> (i % 32);
            let want = q as f32 * (1.0 / (1u32 << 30) as f32);
            let got = q30_to_f32(q);
            let exact = f64::from(q) / (1u64 << 30) as f64;
            assert!(
                libm::fabs(f64::from(got) - exact)
                    <= 0.5 * f64::from(want) * f64::from(f32::EPSILON),
                "{q}: {got} vs {want}"
            );
        }
        assert_eq!(q30_to_f32(0), 0.0);
    }
}

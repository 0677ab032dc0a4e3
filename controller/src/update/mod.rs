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
    motion_at_range, DemGround, DemStats, SampleGround, SegmentRays, TileRefusal, BORESIGHT_SLOT,
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

    /// The general form's per-instant constants of the NAV route: with fixed-point pixels
    /// (a core without an FPU, where each f32 operation is a software call) in integers,
    /// rounded once to f32 ([`instant::instant_int`]), else in f32 through an out-of-line
    /// form that the plan build calls too (inlined here, it was a second copy:
    /// docs/target.md, flash).
    #[inline(always)]
    fn nav_instant(
        &self,
        state: &crate::nav::StateParts,
        attitude: &core_math::earth::Attitude<f32>,
    ) -> Result<GeneralInstant<f32>, core_math::ModelError> {
        let (r, v, r2_minus_a2) = (state.position_m, state.velocity_mps, state.r2_minus_a2_m2);
        let w = EARTH_RATE_RAD_S as f32;
        #[cfg(feature = "earth-fixed")]
        if self.fixed_pixels() {
            return instant::instant_int(r, v, r2_minus_a2, attitude, w);
        }
        GENERAL_F32.instant_parts(r, v, r2_minus_a2, attitude, w)
    }

    /// The NAV state `dt_s` after its frame: with fixed-point pixels in integers
    /// ([`crate::nav::Propagator::parts_at_int`]) where its formats hold, else in f32.
    #[inline(always)]
    fn nav_state(&self, p: &crate::nav::Propagator, dt_s: f32) -> crate::nav::StateParts {
        #[cfg(feature = "earth-fixed")]
        if self.fixed_pixels() {
            if let Some(s) = p.parts_at_int(dt_s) {
                return s;
            }
        }
        p.parts_at(dt_s)
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
                let state = self.nav_state(&nav.propagator, dt_s);
                let attitude = attitude_at(&nav.attitude, dt_s);
                self.nav_instant(&state, &attitude)
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
        // The DEM's route needs a tile in force and the ITRF of the instant.
        let dem_frame = if self.dem_ground.active() { itrf } else { None };
        // With fixed-point pixels the ground is one place per update that each height's
        // update is written into (returned by value, its copies were a twentieth of the
        // M3's update); the f32 route returns its smaller update as before.
        #[cfg(feature = "earth-fixed")]
        let mut update = empty_ground(&self.plan);
        #[cfg(feature = "earth-fixed")]
        let (steer, mut ground_h_m, mut ground) =
            self.steer_and_ground(&instant, dem_frame.as_ref(), &mut update);
        #[cfg(not(feature = "earth-fixed"))]
        let (steer, mut ground_h_m, mut ground) =
            self.steer_and_ground(&instant, dem_frame.as_ref());
        self.yaw_request_rad = steer.map(|(_, _, rad)| rad);
        // Output slots by `get` (`index` < MAX_SEGMENTS by construction of the plan): no
        // panic path (docs/no-panic.md).
        for k in 0..self.plan.segments.len() {
            let Some(seg) = self.plan.segments.get(k) else {
                break;
            };
            let index = seg.index;
            let height_m = self.height(index);
            // NaN never equals: the first segment makes the first ground. Compared as
            // bits (no software comparison on a core without an FPU): a NaN has no
            // height's bits, and -0 against 0 only makes the same ground again.
            let bits = ground_h_m.to_bits();
            if height_m.to_bits() != bits || bits & 0x7fff_ffff > 0x7f80_0000 {
                #[cfg(feature = "earth-fixed")]
                {
                    ground = self.make_ground(&mut update, &instant, height_m, steer);
                }
                #[cfg(not(feature = "earth-fixed"))]
                {
                    ground = self.make_ground(&instant, height_m, steer);
                }
                ground_h_m = height_m;
            }
            #[cfg(feature = "earth-fixed")]
            let made = ground.map(|()| &update);
            #[cfg(not(feature = "earth-fixed"))]
            let made = ground.as_ref().map_err(|f| *f);
            let result = match (made, &dem_frame) {
                (Err(f), _) => Err(f),
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
        // With fixed-point pixels the DEM's f32 extremes take the integer route too: its
        // f32 twin here was a second copy of the tail in the M3's flash.
        #[cfg(feature = "earth-fixed")]
        if self.fixed_pixels() {
            return self.segment_fixed(update, seg, steer, dem.map(ExtremesBits::of));
        }
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

mod backend;
mod dem;
#[cfg(feature = "earth-fixed")]
mod fixed;
#[cfg(feature = "earth-fixed")]
mod instant;
mod sweep;

use backend::*;
#[cfg(feature = "earth-fixed")]
pub(crate) use fixed::i64_to_f32_call as i64_to_f32_scaled;
#[cfg(feature = "earth-fixed")]
use fixed::*;
pub use sweep::drift_angle_rad;
use sweep::*;

#[cfg(all(test, feature = "earth-fixed"))]
mod fixed_tests;
#[cfg(test)]
mod tests;

//! Which route evaluates a segment: the f32 general form, or with the feature
//! `earth-fixed` and fixed-point pixels the integer forms (`core_math::EARTH_FIXED`,
//! `core_math::mtf::int`) that a core without an FPU flies; the ground each segment is
//! evaluated from, the MTF and stage limit, the drift angles and the yaw steering by
//! either route (docs/controller.md, "Backends").

use super::*;
use core_math::trig::atan_reduced;

impl Controller {
    /// The segment's [`Extremes`] by the configured backend.
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    pub(super) fn extremes(&self, update: &Ground, seg: &SegmentPlan) -> Result<Extremes, Fault> {
        extremes(update, seg)
    }

    /// The segment's [`Extremes`] in f32: with fixed-point pixels, only the DEM's route
    /// comes here (the others take [`Controller::segment_fixed`]).
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    pub(super) fn extremes(&self, update: &Ground, seg: &SegmentPlan) -> Result<Extremes, Fault> {
        extremes(&update.float, seg)
    }

    /// The MTF at `stages` under the mismatch `worst` and the drift tangent `tan_max`,
    /// and the stage limit, in f32.
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    pub(super) fn mtf_and_stages(
        &self,
        stages: u32,
        worst: f32,
        tan_max: f32,
    ) -> Result<(f32, u32), Fault> {
        mtf_and_stages_f32(&self.plan, stages, worst, tan_max)
    }

    /// The same by the configured backend: with fixed-point pixels, every sinc in Q30
    /// integers (`core_math::mtf::int`; soft float on the M3 made them a third of an
    /// update: docs/controller.md, "What it costs").
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    pub(super) fn mtf_and_stages(
        &self,
        stages: u32,
        worst: f32,
        tan_max: f32,
    ) -> Result<(f32, u32), Fault> {
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
    pub(super) fn steered_centre(
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
    pub(super) fn drift_angles(
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
    pub(super) fn drift_angles(
        &self,
        centre: &ImageMotion<f32>,
        drift: (f32, f32),
        tan_max: f32,
        residual: Option<(f32, f32)>,
    ) -> [f32; 3] {
        if self.fixed_pixels() {
            let centre_rad = atan_pair_rad(centre.v2_mps, centre.v1_mps);
            let worst_rad = atan_pair_rad(drift.0, drift.1);
            // Both >= 0 (or NaN): their bits order as their values, without the
            // software comparison.
            let worst_rad = if worst_rad.to_bits() < centre_rad.abs().to_bits() {
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
    pub(super) fn steered_centre(
        &self,
        update: &Ground,
        seg: &SegmentPlan,
        sin: f32,
        cos: f32,
    ) -> Result<(f32, f32), Fault> {
        match (update.yawed(), seg.fixed.first()) {
            // The pair in I24F40 units: only its ratio is used.
            (Some(up), Some(px)) => {
                let m = core_math::EARTH_FIXED.motion(up, px)?;
                let f = |bits: i64| super::fixed::i64_to_f32(bits, 0);
                Ok((f(m.v2_mps.to_bits()), f(m.v1_mps.to_bits())))
            }
            _ => {
                let m = steered_centre(&update.float, seg, sin, cos)?;
                Ok((m.v2_mps, m.v1_mps))
            }
        }
    }

    /// The yaw request's (sin, cos, angle) from the boresight's motion, and the first
    /// ground of the update with its height: the boresight segment's, which the request
    /// is formed on and the loop then reuses for every segment at that height (made
    /// again there, it was a second `ground` per update).
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(always)]
    pub(super) fn steer_and_ground(
        &mut self,
        instant: &GeneralInstant<f32>,
        dem: Option<&ItrfFrame>,
    ) -> (Steer, f32, Result<Ground, Fault>) {
        let boresight_h = self.height(self.plan.boresight_segment);
        let ground = self.make_ground(instant, boresight_h, None);
        let steer = ground.as_ref().ok().and_then(|g| {
            let on_dem = match dem {
                Some(_) => self.dem_boresight(dem, g, instant.r2_minus_a2_m2, boresight_h),
                None => None,
            };
            match on_dem {
                Some(m) => steer_from(m.v1_mps, m.v2_mps, atan_reduced(m.v2_mps / m.v1_mps)),
                None => self.steer_f32(g),
            }
        });
        (steer, boresight_h, ground)
    }

    /// The same by the configured backend. With fixed-point pixels the boresight
    /// segment's ground comes first (the loop then reuses it for every segment at its
    /// height), and the request from its fixed-point update: the boresight's v/f in
    /// integers (`EarthFixedUpdate::boresight_over_focal`) instead of a second f32
    /// ground and motion in soft float.
    #[cfg(feature = "earth-fixed")]
    #[inline(always)]
    pub(super) fn steer_and_ground(
        &mut self,
        instant: &GeneralInstant<f32>,
        dem: Option<&ItrfFrame>,
        g: &mut Ground,
    ) -> (Steer, f32, Result<(), Fault>) {
        let boresight_h = self.height(self.plan.boresight_segment);
        let ground = self.make_ground(g, instant, boresight_h, None);
        // Over a DEM tile, the boresight's ground on it (the f32 route's, soft float on
        // a core without an FPU, as the DEM's samples are).
        let on_dem = match (ground, dem) {
            (Ok(()), Some(_)) => {
                self.dem_boresight(dem, &g.float, instant.r2_minus_a2_m2, boresight_h)
            }
            _ => None,
        };
        if !self.fixed_pixels() {
            let steer = ground.ok().and_then(|()| match on_dem {
                Some(m) => steer_from(m.v1_mps, m.v2_mps, atan_reduced(m.v2_mps / m.v1_mps)),
                None => self.steer_f32(&g.float),
            });
            return (steer, boresight_h, ground);
        }
        let turn = match (ground, on_dem, g.fixed()) {
            // Over the DEM, the request from the boresight's f32 motion there.
            (Ok(()), Some(m), _) => {
                steer_from(m.v1_mps, m.v2_mps, atan_pair_rad(m.v2_mps, m.v1_mps))
                    .map(|(sin, cos, rad)| (q30(sin), q30(cos), (sin, cos, rad)))
            }
            (Ok(()), None, Some(f)) => f
                .boresight_over_focal()
                .ok()
                .and_then(|(vf1, vf2)| steer_fixed(vf1, vf2)),
            _ => None,
        };
        if let (Ok(()), Some((sin_q30, cos_q30, _))) = (ground, turn) {
            g.turn(sin_q30, cos_q30);
            // A turn past the fixed formats: its steered centres take the f32 ground.
            if !g.yawed_ok && !g.float_ok {
                let ground = self.float_ground(g, instant, boresight_h);
                return (turn.map(|t| t.2), boresight_h, ground);
            }
        }
        (turn.map(|t| t.2), boresight_h, ground)
    }

    /// The yaw request from the boresight's motion in f32 on `ground`, the boresight
    /// segment's.
    #[inline(always)]
    pub(super) fn steer_f32(&self, ground: &GeneralUpdate<f32>) -> Option<(f32, f32, f32)> {
        GENERAL_F32
            .motion(ground, &self.plan.boresight)
            .ok()
            // `atan_f32`'s value as a call (once per update; inlined, a second copy).
            .and_then(|m| steer_from(m.v1_mps, m.v2_mps, atan_reduced(m.v2_mps / m.v1_mps)))
    }
}

/// The MTF and the stage limit in f32 (the M4F boards').
#[inline(always)]
pub(super) fn mtf_and_stages_f32(
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
pub(super) fn drift_angles_f32(
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
pub(super) type Steer = Option<(f32, f32, f32)>;

/// The yaw turn (sin, cos) that zeroes the boresight's drift, from its (v1, v2) (any
/// common scale), and the request `rad`; None when they are not finite.
#[inline(always)]
pub(super) fn steer_from(v1: f32, v2: f32, rad: f32) -> Option<(f32, f32, f32)> {
    let speed = Real::sqrt(v1 * v1 + v2 * v2);
    let sign = if v1 < 0.0 { -1.0 } else { 1.0 };
    let (sin, cos) = (sign * v2 / speed, sign * v1 / speed);
    (sin.is_finite() && cos.is_finite()).then_some((sin, cos, rad))
}

/// What the segments over one ground height are evaluated from: the f32 general form's
/// update (docs/controller.md, "Backends").
#[cfg(not(feature = "earth-fixed"))]
pub(super) type Ground = GeneralUpdate<f32>;

/// What the segments over one ground height are evaluated from: the f32 update, which
/// the steered centre uses, and the same rounded to the fixed-point backend's formats,
/// which every sample pixel uses (docs/controller.md, "Backends"). Made in place, once
/// per update, and overwritten per ground height: returned by value, its copies were a
/// twentieth of the M3's update.
#[cfg(feature = "earth-fixed")]
pub(super) struct Ground {
    /// The f32 update: valid when `float_ok`; with fixed-point pixels made only where
    /// read (the DEM's route, a steered centre past the fixed formats).
    pub(super) float: GeneralUpdate<f32>,
    pub(super) float_ok: bool,
    /// Valid when `fixed_ok` (never unless [`Controller::fixed_pixels`]).
    fixed: core_math::earth::fixed::EarthFixedUpdate,
    fixed_ok: bool,
    /// `fixed` turned by the yaw request, for the steered centres; valid when
    /// `yawed_ok`: not without a request, or where the turn leaves the fixed formats'
    /// envelope.
    yawed: core_math::earth::fixed::EarthFixedUpdate,
    yawed_ok: bool,
    /// The plan's line speed (pixel x clock, m/s) and period bounds in ticks, for
    /// [`Controller::segment_fixed`]: once per update, not per segment.
    pub(super) period: PeriodConsts,
}

#[cfg(feature = "earth-fixed")]
impl Ground {
    /// No ground yet: nothing valid.
    pub(super) fn empty(plan: &crate::plan::Plan) -> Ground {
        use core_math::earth::fixed::EarthFixedUpdate;
        Ground {
            float: ZERO_UPDATE,
            float_ok: false,
            fixed: EarthFixedUpdate::ZERO,
            fixed_ok: false,
            yawed: EarthFixedUpdate::ZERO,
            yawed_ok: false,
            period: PeriodConsts::of(plan),
        }
    }

    /// The fixed-point update, where made.
    #[inline(always)]
    pub(super) fn fixed(&self) -> Option<&core_math::earth::fixed::EarthFixedUpdate> {
        self.fixed_ok.then_some(&self.fixed)
    }

    /// The fixed-point update turned by the yaw request, where made.
    #[inline(always)]
    pub(super) fn yawed(&self) -> Option<&core_math::earth::fixed::EarthFixedUpdate> {
        self.yawed_ok.then_some(&self.yawed)
    }

    /// Turns the fixed-point update by the yaw request (sine and cosine in Q30) into
    /// `yawed`; not valid where it is not made or the turn leaves the envelope.
    #[inline(always)]
    fn turn(&mut self, sin_q30: i32, cos_q30: i32) {
        self.yawed_ok = self.fixed_ok
            && self
                .fixed
                .yawed_into(sin_q30, cos_q30, &mut self.yawed)
                .is_ok();
    }
}

/// The Earth's constants of `EarthFixed::ground_f32_into`, made at compile time.
#[cfg(feature = "earth-fixed")]
const GROUND: core_math::earth::fixed::GroundConsts =
    core_math::earth::fixed::GroundConsts::new(&EARTH);

/// A placeholder f32 update, overwritten before any use.
#[cfg(feature = "earth-fixed")]
const ZERO_UPDATE: GeneralUpdate<f32> = GeneralUpdate {
    n_b: [0.0; 3],
    rho_b_m: [0.0; 3],
    stretch2_minus_1: 0.0,
    c_m2: 0.0,
    inv_c_per_m2: 0.0,
    w_b_rad_s: [0.0; 3],
    v_b_mps: [0.0; 3],
};

/// No ground yet: nothing valid.
#[cfg(feature = "earth-fixed")]
#[inline(always)]
pub(super) fn empty_ground(plan: &crate::plan::Plan) -> Ground {
    Ground::empty(plan)
}

impl Controller {
    #[cfg(not(feature = "earth-fixed"))]
    #[inline(never)]
    pub(super) fn make_ground(
        &self,
        instant: &GeneralInstant<f32>,
        height_m: f32,
        _steer: Option<(f32, f32, f32)>,
    ) -> Result<Ground, Fault> {
        GENERAL_F32
            .ground(instant, &EARTH, height_m)
            .map_err(Fault::from)
    }

    /// The f32 update of the ground and, for fixed-point pixels, the same rounded once
    /// to the fixed-point formats in integers, turned by the yaw request `steer` where
    /// one is given: per ground height, not per pixel, into `g` in place. A refusal
    /// leaves nothing of `g` valid.
    #[cfg(feature = "earth-fixed")]
    pub(super) fn make_ground(
        &self,
        g: &mut Ground,
        instant: &GeneralInstant<f32>,
        height_m: f32,
        steer: Option<(f32, f32, f32)>,
    ) -> Result<(), Fault> {
        g.fixed_ok = false;
        g.yawed_ok = false;
        g.float_ok = false;
        if self.fixed_pixels() {
            // Straight from the instant in integers (`EarthFixed::ground_f32_into`,
            // within two units and 1.4e-9 relative of the f64 ground's rounding), without
            // the f32 ground in soft float.
            // Where the integers hand over (`EarthFixed::ground_int_into`: a height of
            // 2^16 m or more, which no scene or TERRAIN frame passes, -500..9 000 m; a
            // non-finite instant; |r|^2 - A^2 <= 0, C / |r|^2 below the formats' 0.05),
            // the f32 ground and its rounding refuse too, each as `Fault::OutOfRange`:
            // so here, without linking that route.
            match core_math::EARTH_FIXED.ground_int_into(instant, &GROUND, height_m, &mut g.fixed) {
                Some(r) => r?,
                None => return Err(Fault::OutOfRange),
            }
            g.fixed_ok = true;
            if let Some((sin, cos, _)) = steer {
                g.turn(q30(sin), q30(cos));
            }
            // The f32 ground only where it is read: the DEM's route, or a steered centre
            // whose turn left the fixed formats.
            if g.float_ok || !self.dem_ground.active() && (steer.is_none() || g.yawed_ok) {
                return Ok(());
            }
        }
        self.float_ground(g, instant, height_m)
    }

    /// The f32 ground into `g.float`.
    #[cfg(feature = "earth-fixed")]
    #[inline(never)]
    pub(super) fn float_ground(
        &self,
        g: &mut Ground,
        instant: &GeneralInstant<f32>,
        height_m: f32,
    ) -> Result<(), Fault> {
        g.float = GENERAL_F32.ground(instant, &EARTH, height_m)?;
        g.float_ok = true;
        Ok(())
    }
}

#[cfg(not(feature = "earth-fixed"))]
#[inline(always)]
pub(super) fn float(g: &Ground) -> &GeneralUpdate<f32> {
    g
}

#[cfg(feature = "earth-fixed")]
#[inline(always)]
pub(super) fn float(g: &Ground) -> &GeneralUpdate<f32> {
    &g.float
}

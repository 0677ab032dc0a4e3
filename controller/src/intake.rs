//! Frame intake: frames to state. Each decoded frame's time tag is checked against the
//! time window (with re-synchronisation to a new time line), then its content: a NAV
//! frame against the mission's orbit and the scene's attitude envelope, a SCENE frame by
//! planning it, a TERRAIN frame against the scene in force. A refused frame leaves the
//! state as it was and is counted ([`Controller::reject`]).

use core_math::earth::frames::CelestialPole;
use core_math::earth::Attitude;
use core_math::StateVector;

use crate::bus::{decode_time_scales, Gnss, StarAttitude};
use crate::config::{EARTH, MAX_TIME_TAG_US};
use crate::control::{Controller, NavState};
use crate::fault::Fault;
use crate::frame::{kind, Frame};
use crate::nav::{Nav, Propagator};
use crate::plan::{MAX_SPEED2_RATIO, MIN_SPEED2_RATIO};
use crate::scene::{AttitudeEnvelope, Scene, Terrain};
use crate::track::{pole_for, AttitudeState, GnssState};

impl Controller {
    /// One decoded frame. Its time tag moves the controller's clock forward.
    ///
    /// The time window (docs/telemetry.md "Time"): a tag is taken when it is after the
    /// last accepted one and at most `max_time_jump_us` ahead of the clock (any tag up
    /// to [`MAX_TIME_TAG_US`] before the first frame). A tag outside it is refused, but
    /// remembered: if the very next frame is valid and lies after it by at most the
    /// jump, the two agree on a new time line and the clock re-synchronises to it.
    // Out of line: inlined, the frame checks shared the session's per-byte closure
    // and its registers (docs/target.md, flash).
    #[inline(never)]
    pub fn on_frame(&mut self, frame: &Frame<'_>) {
        let t = frame.time_us;
        let candidate = self.resync_candidate_us.take();
        let resync = match self.time_check(t) {
            Ok(()) => false,
            Err(f) => {
                let confirms = candidate.is_some_and(|c| {
                    t > c && t - c <= self.config.max_time_jump_us && t <= MAX_TIME_TAG_US
                });
                if !confirms {
                    // A tag the clock can never take cannot start a new time line.
                    if t <= MAX_TIME_TAG_US {
                        self.resync_candidate_us = Some(t);
                    }
                    return self.reject(f);
                }
                true
            }
        };
        if resync {
            // Content first: a frame refused for its content re-synchronises nothing.
            if let Err(f) = self.check_content(frame) {
                return self.reject(f);
            }
            self.resynchronise(t);
        }
        let result = self.apply(frame);
        match result {
            Ok(()) => {
                self.frames_accepted = self.frames_accepted.saturating_add(1);
                self.last_time_us = Some(t);
                self.now_us = self.now_us.max(t);
            }
            Err(f) => self.reject(f),
        }
    }

    /// Whether `t_us` lies in the time window.
    fn time_check(&self, t_us: u64) -> Result<(), Fault> {
        if t_us > MAX_TIME_TAG_US {
            return Err(Fault::TimeJump);
        }
        let Some(last) = self.last_time_us else {
            return Ok(());
        };
        if t_us <= last {
            return Err(Fault::TimeWentBackwards);
        }
        // `now_us` <= MAX_TIME_TAG_US, but the jump is configuration: saturate.
        if t_us > self.now_us.saturating_add(self.config.max_time_jump_us) {
            return Err(Fault::TimeJump);
        }
        Ok(())
    }

    /// The checks `apply` makes, without their effect (a SCENE's plan is built in the
    /// spare plan, which only a successful `set_scene` puts in force).
    fn check_content(&mut self, frame: &Frame<'_>) -> Result<(), Fault> {
        match frame.kind {
            kind::NAV => self.check_nav(frame).map(|_| ()),
            kind::SCENE => {
                let scene = Scene::decode(frame.payload)?;
                self.spare_plan.build_into(&scene, &self.config, false)
            }
            kind::TERRAIN => Terrain::decode(frame.payload, &self.scene).map(|_| ()),
            kind::GNSS => self.check_gnss(frame).map(|_| ()),
            kind::ATTITUDE => self.check_attitude(frame).map(|_| ()),
            kind::TIME_SCALES => decode_time_scales(frame.payload).map(|_| ()),
            kind::DEM_BEGIN => self.check_dem_begin(frame.payload),
            kind::DEM_CHUNK => self.check_dem_chunk(frame.payload),
            kind::TIME if frame.payload.is_empty() => Ok(()),
            kind::TIME => Err(Fault::BadLength),
            _ => Err(Fault::UnknownKind),
        }
    }

    /// A new time line from `t_us` on: the NAV state of the old one cannot be
    /// propagated across the discontinuity, so it is dropped (mode waiting for NAV, the
    /// periods in force held), and the next update is the one due at the new clock.
    fn resynchronise(&mut self, t_us: u64) {
        self.time_resyncs = self.time_resyncs.saturating_add(1);
        self.last_time_us = None;
        self.now_us = t_us;
        self.next_update_us = 0;
        self.nav = None;
        self.gnss = None;
        self.attitude = None;
        self.hold_all();
    }

    fn apply(&mut self, frame: &Frame<'_>) -> Result<(), Fault> {
        match frame.kind {
            kind::NAV => self.accept_nav(frame),
            kind::SCENE => self.accept_scene(frame.payload),
            kind::TERRAIN => {
                let terrain = Terrain::decode(frame.payload, &self.scene)?;
                self.heights_m = terrain.heights_m;
                self.inputs_generation = self.inputs_generation.wrapping_add(1);
                Ok(())
            }
            kind::GNSS => {
                self.gnss = Some(self.check_gnss(frame)?);
                self.nav = None;
                Ok(())
            }
            kind::ATTITUDE => {
                let (attitude, pole) = self.check_attitude(frame)?;
                self.attitude = Some(attitude);
                self.pole = Some(pole);
                self.nav = None;
                Ok(())
            }
            kind::TIME_SCALES => {
                let scales = decode_time_scales(frame.payload)?;
                if scales != self.time_scales {
                    self.time_scales = scales;
                    // A reset keeps them (`restart::Snapshot`).
                    self.inputs_generation = self.inputs_generation.wrapping_add(1);
                }
                self.rederive_attitude();
                Ok(())
            }
            kind::DEM_BEGIN => self.accept_dem_begin(frame.payload),
            kind::DEM_CHUNK => self.accept_dem_chunk(frame.payload),
            kind::TIME if frame.payload.is_empty() => Ok(()),
            kind::TIME => Err(Fault::BadLength),
            _ => Err(Fault::UnknownKind),
        }
    }

    fn accept_nav(&mut self, frame: &Frame<'_>) -> Result<(), Fault> {
        self.nav = Some(self.check_nav(frame)?);
        self.gnss = None;
        self.attitude = None;
        Ok(())
    }

    /// An orbit the controller flies: an orbital frame; |r| in the altitude band and a
    /// speed of an imaging orbit ([`MIN_SPEED2_RATIO`]..[`MAX_SPEED2_RATIO`] of the
    /// circular speed squared) (`out_of_range`). Every value finite (the caller's).
    fn check_orbit(&self, state: &StateVector) -> Result<(), Fault> {
        let (r, v) = (state.position_m, state.velocity_mps);
        let (r2, _) = core_math::earth::check_state(r, v).map_err(|_| Fault::OutOfRange)?;
        let r_m = libm::sqrt(r2);
        let (h_lo, h_hi) = self.config.altitude_range_m;
        if !(r_m >= EARTH.b_m() + h_lo && r_m <= EARTH.a_m + h_hi) {
            return Err(Fault::OutOfRange);
        }
        let speed2_ratio = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * r_m / core_math::GM_M3_S2;
        if !(MIN_SPEED2_RATIO..=MAX_SPEED2_RATIO).contains(&speed2_ratio) {
            return Err(Fault::OutOfRange);
        }
        Ok(())
    }

    /// A time of fix or of validity `t0_us` in a frame tagged `tag_us`: after the last
    /// one taken (`last_us`), not after the tag, and at most `max_age_us` before it
    /// (`fix_time`).
    fn check_data_time(
        t0_us: u64,
        tag_us: u64,
        last_us: Option<u64>,
        max_age_us: u64,
    ) -> Result<(), Fault> {
        let fresh = t0_us <= tag_us && tag_us - t0_us <= max_age_us;
        if !fresh || last_us.is_some_and(|last| t0_us <= last) {
            return Err(Fault::FixTime);
        }
        Ok(())
    }

    /// A GNSS frame's checks: finite (`non_finite`), the time of fix
    /// ([`Controller::check_data_time`], against `gnss_stale_after`), the orbit in I
    /// ([`Controller::check_orbit`]).
    fn check_gnss(&self, frame: &Frame<'_>) -> Result<GnssState, Fault> {
        let gnss = Gnss::decode(frame.payload)?;
        let last = self.gnss.map(|g| g.fix_us);
        Self::check_data_time(
            gnss.fix_us,
            frame.time_us,
            last,
            self.config.gnss_stale_after_us,
        )?;
        self.check_orbit(&GnssState::inertial(&gnss))?;
        Ok(GnssState::new(&gnss))
    }

    /// An ATTITUDE frame's checks: finite (`non_finite`), the time of validity
    /// ([`Controller::check_data_time`], against `stale_after`), the quaternion's norm
    /// (`bad_quaternion`), the camera's rates (Omega, each axis) within the scene's
    /// largest rate (`attitude_outside_model`). Returns the attitude in I (the
    /// quaternion blended with the last attitude carried: `Config::attitude_blend`) and
    /// the pole it was computed with (a new one when the one in force is too old for
    /// it).
    fn check_attitude(&self, frame: &Frame<'_>) -> Result<(AttitudeState, CelestialPole), Fault> {
        let received = StarAttitude::decode(frame.payload)?;
        let last = self.attitude.map(|a| a.received.valid_us);
        Self::check_data_time(
            received.valid_us,
            frame.time_us,
            last,
            self.config.stale_after_us,
        )?;
        let pole = pole_for(self.pole.as_ref(), received.valid_us, &self.time_scales)?;
        // Blended only once it passed the quaternion's own check: a bad one is refused as
        // it came.
        crate::track::check_quaternion(&received)?;
        // The last attitude carried, else the estimate kept across a reset (its rates'
        // change is not kept: the first blend after it carries the rates alone).
        let blend = &self.config.attitude_blend;
        let taken = match (&self.attitude, &self.blend_seed) {
            (Some(last), _) => blend.blend(&last.received, last.body_accel_rad_s2, &received),
            (None, Some(seed)) => blend.blend(seed, [0.0; 3], &received),
            (None, None) => received,
        };
        let state = AttitudeState::derive(
            &taken,
            &self.scene.mounting_q,
            &pole,
            &self.time_scales,
            self.gnss.as_ref(),
        )?;
        let max_rate = self.plan.envelope.max_rate_rad_s;
        if !state.omega_rad_s.iter().all(|w| w.abs() <= max_rate) {
            return Err(Fault::AttitudeOutsideModel);
        }
        Ok((state, pole))
    }

    /// A NAV frame's checks: finite; an orbital frame; |r| in the altitude band and a
    /// speed of an imaging orbit ([`MIN_SPEED2_RATIO`]..[`MAX_SPEED2_RATIO`] of the
    /// circular speed squared) (`out_of_range`); the attitude inside the scene's
    /// envelope at the frame's instant and propagated at its rates over every update it
    /// may serve, one update period back (an update instant precedes the frame's tag by
    /// up to that) to `stale_after` ahead (`attitude_outside_model`).
    fn check_nav(&self, frame: &Frame<'_>) -> Result<NavState, Fault> {
        let nav = Nav::decode(frame.payload)?;
        nav.check_state()?;
        self.check_orbit(&nav.state)?;
        let back_s = self.config.update_period_us as f32 * 1e-6;
        let ahead_s = self.config.stale_after_us as f32 * 1e-6;
        if !inside_envelope(&nav.attitude, &self.plan.envelope, back_s, ahead_s) {
            return Err(Fault::AttitudeOutsideModel);
        }
        // Any yaw is allowed: wrapped once here (in f64: an f32 yaw of any size), the
        // per-update trigonometry then works near zero.
        let yaw = core_math::earth::frames::remainder(
            f64::from(nav.attitude.yaw_rad),
            2.0 * core::f64::consts::PI,
        );
        Ok(NavState {
            time_us: frame.time_us,
            propagator: Propagator::new(&nav.state),
            attitude: Attitude {
                yaw_rad: yaw as f32,
                ..nav.attitude
            },
        })
    }

    fn accept_scene(&mut self, payload: &[u8]) -> Result<(), Fault> {
        self.set_scene(Scene::decode(payload)?)
    }
}

/// Whether `a` and its propagation at its rates `back_s` before and `ahead_s` after its
/// instant stay inside `env` (linear in time: the ends are the extremes).
fn inside_envelope(a: &Attitude<f32>, env: &AttitudeEnvelope, back_s: f32, ahead_s: f32) -> bool {
    let rates = [a.roll_rate_rad_s, a.pitch_rate_rad_s, a.yaw_rate_rad_s];
    let angle_ok = |x: f32, rate: f32, max: f32| {
        [x, x - rate * back_s, x + rate * ahead_s]
            .iter()
            .all(|y| y.abs() <= max)
    };
    // Yaw is free (finite: `Nav::check_state`).
    rates.iter().all(|r| r.abs() <= env.max_rate_rad_s)
        && angle_ok(a.roll_rad, a.roll_rate_rad_s, env.max_roll_rad)
        && angle_ok(a.pitch_rad, a.pitch_rate_rad_s, env.max_pitch_rad)
}

impl Controller {
    pub(crate) fn check_dem_begin(&self, payload: &[u8]) -> Result<(), Fault> {
        self.dem.validate_begin(payload)
    }

    pub(crate) fn check_dem_chunk(&self, payload: &[u8]) -> Result<(), Fault> {
        self.dem.validate_chunk(payload)
    }

    /// DEM_BEGIN: a new upload; one in progress is given up.
    pub(crate) fn accept_dem_begin(&mut self, payload: &[u8]) -> Result<(), Fault> {
        self.dem.begin(payload)
    }

    /// DEM_CHUNK: staged; the last one puts the tile in force.
    pub(crate) fn accept_dem_chunk(&mut self, payload: &[u8]) -> Result<(), Fault> {
        if self.dem.chunk(payload)? {
            self.refresh_dem_ground();
        }
        Ok(())
    }
}

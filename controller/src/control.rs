//! The line-rate controller: accepts frames, keeps the last good state, and at every
//! update instant computes each active segment's line period, its MTF and TDI stage
//! limit and its drift angle, writing the periods through a [`LinePeriodSink`].
//!
//! Faults never reach the registers: a refused frame leaves the state as it was, a
//! refused computation leaves that segment's last good period in force, and nothing
//! outside the physically possible period range is ever written.

use core_math::{
    line_period_ticks, mtf_mismatch, Backend, Geometry, OrbitState, CLOSED_F32, EARTH_RATE_RAD_S,
};

use crate::fault::{Counters, Fault};
use crate::frame::{kind, Frame};
use crate::nav::{Attitude, Nav};
use crate::plan::{Envelope, Plan, SegmentPlan};
use crate::scene::{Scene, MAX_SEGMENTS};

/// Where line periods go: the period registers of the camera's line clock (one per
/// segment), in the spirit of embedded-hal: small, and the only way out.
pub trait LinePeriodSink {
    type Error;
    /// Programs segment `index`'s line period, in ticks of the scene's line clock.
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), Self::Error>;
}

/// Controller settings (defaults: `Config::default()`; rationale in docs/telemetry.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Time between updates (us). Default 20 ms: a 1 deg/s roll manoeuvre changes the
    /// image speed by up to 8.8 %/s (far point, 800 km), and the drift between updates
    /// may use a tenth of a 16-stage segment's budget (2.2e-3): at most 24.9 ms
    /// (`cargo test -p controller --release --test update_rate -- --nocapture`).
    pub update_period_us: u64,
    /// No valid NAV frame for longer than this (us) is a [`Fault::Stale`] and stops updates.
    pub stale_after_us: u64,
    /// Largest step (us) a time tag may take ahead of the controller's clock. A tag
    /// further ahead is refused ([`Fault::TimeJump`]) unless the next frame confirms
    /// the new time line (a re-synchronisation, docs/telemetry.md "Time").
    pub max_time_jump_us: u64,
    /// Round-Earth radius of the model (m).
    pub earth_radius_m: f64,
    /// The mission's altitude band (m): NAV frames outside it are refused, and scenes
    /// are planned and the period guard set for it. The model itself holds over
    /// 200-2000 km; a narrower band lets the planner sample less and the guard be tighter.
    pub altitude_range_m: (f64, f64),
    /// Largest |pitch| and |yaw| for the roll-only model (rad).
    pub pitch_yaw_tolerance_rad: f32,
    /// Largest |pitch rate| and |yaw rate| for the roll-only model (rad/s).
    pub pitch_yaw_rate_tolerance_rad_s: f32,
}

impl Config {
    /// The orbits a plan must hold for.
    pub fn envelope(&self) -> Envelope {
        Envelope {
            earth_radius_m: self.earth_radius_m,
            altitude_range_m: self.altitude_range_m,
        }
    }
}

impl Default for Config {
    fn default() -> Self {
        Config {
            update_period_us: 20_000,
            stale_after_us: 1_000_000,
            max_time_jump_us: 5_000_000,
            earth_radius_m: 6_371_000.0,
            altitude_range_m: (500e3, 800e3),
            pitch_yaw_tolerance_rad: 0.5f32.to_radians(),
            pitch_yaw_rate_tolerance_rad_s: 1.0e-6,
        }
    }
}

/// Largest time tag the clock takes (us, 2^53: 285 years). Up to it every tag is exact
/// in f64 (the propagation's `dt`), and the schedule's sums cannot overflow.
pub const MAX_TIME_TAG_US: u64 = 1 << 53;

/// The last accepted NAV state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavState {
    pub time_us: u64,
    pub orbit: OrbitState,
    pub attitude: Attitude,
}

/// One segment's output at one update.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SegmentOutput {
    pub index: u8,
    pub ticks: u32,
    /// Worst relative mismatch |v_line / v - 1| over the segment's samples.
    pub worst_mismatch: f32,
    /// MTF_mismatch at the worst sample with the segment's configured stages.
    pub mtf: f32,
    /// Largest TDI stage count meeting the scene's MTF floor.
    pub max_stages: u16,
    /// atan(v2 / v1) at the segment's centre sample (rad).
    pub drift_rad: f32,
    /// True when this is the last good value held over a fault.
    pub held: bool,
}

/// Operating state, as the status frame reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Mode {
    /// No NAV frame accepted yet.
    WaitingForNav = 0,
    Nominal = 1,
    /// NAV too old: periods held.
    Stale = 2,
}

#[derive(Clone)]
pub struct Controller {
    pub config: Config,
    scene: Scene,
    plan: Plan,
    nav: Option<NavState>,
    /// Time tag of the last accepted frame of any kind (us).
    last_time_us: Option<u64>,
    /// Time tag of the previous frame, when it was refused for its time tag alone: the
    /// first half of a re-synchronisation.
    resync_candidate_us: Option<u64>,
    now_us: u64,
    next_update_us: u64,
    last_update_us: Option<u64>,
    pub counters: Counters,
    pub last_fault: Option<Fault>,
    pub frames_accepted: u32,
    /// Re-synchronisations of the clock (each also counts as an accepted frame).
    pub time_resyncs: u32,
    outputs: [SegmentOutput; MAX_SEGMENTS],
    has_output: [bool; MAX_SEGMENTS],
    period_bounds_s: (f32, f32),
    /// Update instants run, whatever they computed: one PERIODS frame each.
    pub updates: u32,
    /// The mode an update ran in (the one its PERIODS frame reports).
    update_mode: Mode,
}

impl Controller {
    /// A controller with `scene` in force (normally [`Scene::paper_default`]).
    pub fn new(config: Config, scene: Scene) -> Result<Controller, Fault> {
        let plan = Plan::new(&scene, &config.envelope())?;
        let period_bounds_s = period_bounds_s(&scene, &config);
        Ok(Controller {
            config,
            scene,
            plan,
            nav: None,
            last_time_us: None,
            resync_candidate_us: None,
            now_us: 0,
            next_update_us: 0,
            last_update_us: None,
            counters: Counters::default(),
            last_fault: None,
            frames_accepted: 0,
            time_resyncs: 0,
            outputs: [SegmentOutput::default(); MAX_SEGMENTS],
            has_output: [false; MAX_SEGMENTS],
            period_bounds_s,
            updates: 0,
            update_mode: Mode::WaitingForNav,
        })
    }

    /// A controller on the evaluate-everything plan ([`Plan::exhaustive`]): every
    /// segment, the most samples, every term. The baseline the planner is measured
    /// against (`cargo xtask bench`); not for flight.
    pub fn evaluate_everything(config: Config, scene: Scene) -> Result<Controller, Fault> {
        let mut c = Controller::new(config, scene)?;
        c.plan = Plan::exhaustive(&c.scene, &c.config.envelope())?;
        Ok(c)
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }
    pub fn plan(&self) -> &Plan {
        &self.plan
    }
    pub fn nav(&self) -> Option<&NavState> {
        self.nav.as_ref()
    }
    pub fn now_us(&self) -> u64 {
        self.now_us
    }
    /// The instant of the last update `advance` ran (a multiple of the update period).
    pub fn last_update_us(&self) -> Option<u64> {
        self.last_update_us
    }
    /// The smallest and largest line period (s) any register may receive.
    pub fn period_bounds_s(&self) -> (f32, f32) {
        self.period_bounds_s
    }

    /// The mode at the controller's clock (STATUS).
    pub fn mode(&self) -> Mode {
        self.mode_at(self.now_us)
    }

    /// The mode of the last update, at its instant (PERIODS): the clock may be up to an
    /// update period later, and NAV may go stale in between.
    pub fn update_mode(&self) -> Mode {
        self.update_mode
    }

    fn mode_at(&self, t_us: u64) -> Mode {
        match &self.nav {
            None => Mode::WaitingForNav,
            Some(n) if t_us.saturating_sub(n.time_us) > self.config.stale_after_us => Mode::Stale,
            Some(_) => Mode::Nominal,
        }
    }

    /// The outputs in force, one per active segment.
    pub fn outputs(&self) -> impl Iterator<Item = &SegmentOutput> {
        self.outputs
            .iter()
            .zip(&self.has_output)
            .filter(|(_, h)| **h)
            .map(|(o, _)| o)
    }

    pub fn reject(&mut self, f: Fault) {
        self.counters.count(f);
        self.last_fault = Some(f);
    }

    /// One decoded frame. Its time tag moves the controller's clock forward.
    ///
    /// The time window (docs/telemetry.md "Time"): a tag is taken when it is after the
    /// last accepted one and at most `max_time_jump_us` ahead of the clock (any tag up
    /// to [`MAX_TIME_TAG_US`] before the first frame). A tag outside it is refused, but
    /// remembered: if the very next frame is valid and lies after it by at most the
    /// jump, the two agree on a new time line and the clock re-synchronises to it.
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

    /// The checks `apply` makes, without their effect.
    fn check_content(&self, frame: &Frame<'_>) -> Result<(), Fault> {
        match frame.kind {
            kind::NAV => self.check_nav(frame).map(|_| ()),
            kind::SCENE => Scene::decode(frame.payload)
                .and_then(|s| Plan::new(&s, &self.config.envelope()))
                .map(|_| ()),
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
        self.hold_all();
    }

    fn apply(&mut self, frame: &Frame<'_>) -> Result<(), Fault> {
        match frame.kind {
            kind::NAV => self.accept_nav(frame),
            kind::SCENE => self.accept_scene(frame.payload),
            kind::TIME if frame.payload.is_empty() => Ok(()),
            kind::TIME => Err(Fault::BadLength),
            _ => Err(Fault::UnknownKind),
        }
    }

    fn accept_nav(&mut self, frame: &Frame<'_>) -> Result<(), Fault> {
        self.nav = Some(self.check_nav(frame)?);
        Ok(())
    }

    fn check_nav(&self, frame: &Frame<'_>) -> Result<NavState, Fault> {
        let nav = Nav::decode(frame.payload)?;
        let orbit = nav.orbit(self.config.earth_radius_m)?;
        let (h_lo, h_hi) = self.config.altitude_range_m;
        if !(orbit.altitude_m >= h_lo && orbit.altitude_m <= h_hi) {
            return Err(Fault::OutOfRange);
        }
        let a = nav.attitude;
        if a.roll_rad.abs() > self.plan.max_roll_rad + 1e-3 {
            return Err(Fault::OutOfRange);
        }
        let tol = self.config.pitch_yaw_tolerance_rad;
        let rate_tol = self.config.pitch_yaw_rate_tolerance_rad_s;
        if a.pitch_rad.abs() > tol
            || a.yaw_rad.abs() > tol
            || a.pitch_rate_rad_s.abs() > rate_tol
            || a.yaw_rate_rad_s.abs() > rate_tol
        {
            return Err(Fault::AttitudeOutsideModel);
        }
        Ok(NavState {
            time_us: frame.time_us,
            orbit,
            attitude: a,
        })
    }

    fn accept_scene(&mut self, payload: &[u8]) -> Result<(), Fault> {
        let scene = Scene::decode(payload)?;
        let plan = Plan::new(&scene, &self.config.envelope())?;
        self.period_bounds_s = period_bounds_s(&scene, &self.config);
        self.scene = scene;
        self.plan = plan;
        // A new focal plane: nothing of the old one's outputs applies.
        self.has_output = [false; MAX_SEGMENTS];
        Ok(())
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
        let t = self.now_us - self.now_us % period;
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
        let Some(nav) = self.nav else { return };
        if self.update_mode == Mode::Stale {
            self.hold_all();
            return;
        }
        // Propagate from the frame to this instant: the argument of latitude at the orbit
        // rate, the roll at its rate (a manoeuvre moves the far point fast).
        let dt_s = (t_us as f64 - nav.time_us as f64) * 1e-6;
        let o = nav.orbit;
        let roll =
            f64::from(nav.attitude.roll_rad) + f64::from(nav.attitude.roll_rate_rad_s) * dt_s;
        let geometry = Geometry {
            roll_rad: roll,
            inclination_rad: o.inclination_rad,
            arg_latitude_rad: o.arg_latitude_rad + o.orbit_rate_rad_s * dt_s,
            altitude_m: o.altitude_m,
            earth_radius_m: self.config.earth_radius_m,
            earth_rate_rad_s: EARTH_RATE_RAD_S,
            orbit_rate_rad_s: o.orbit_rate_rad_s,
        }
        .to::<f32>();
        let update = match CLOSED_F32.update(&geometry) {
            Ok(u) => u,
            Err(e) => {
                self.reject(Fault::from(e));
                self.hold_all();
                return;
            }
        };
        // Indices by `get` (`count` <= MAX_SEGMENTS and `index` < MAX_SEGMENTS by
        // construction of the plan): no panic path (docs/no-panic.md).
        for k in 0..usize::from(self.plan.count) {
            let Some(seg) = self.plan.segments.get(k) else {
                break;
            };
            let (index, result) = (seg.index, self.segment(&update, seg));
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
                    } else if let Some(o) = self.outputs.get_mut(slot) {
                        // The register kept its old period: report it as held, not as
                        // the new value.
                        o.held = true;
                    }
                }
                Err(f) => {
                    self.reject(f);
                    if let Some(o) = self.outputs.get_mut(slot) {
                        o.held = true;
                    }
                }
            }
        }
    }

    fn hold_all(&mut self) {
        for o in self.outputs.iter_mut() {
            o.held = true;
        }
    }

    fn segment(
        &self,
        update: &core_math::closed_form::UpdateConst<f32>,
        seg: &SegmentPlan,
    ) -> Result<SegmentOutput, Fault> {
        // One monomorphisation per plan: the terms are chosen once, not per sample.
        let (v_min, v_max) = match (self.plan.terms.limb, self.plan.terms.drift) {
            (true, true) => extremes::<true, true>(update, seg.samples())?,
            (true, false) => extremes::<true, false>(update, seg.samples())?,
            (false, true) => extremes::<false, true>(update, seg.samples())?,
            (false, false) => extremes::<false, false>(update, seg.samples())?,
        };
        // The drift angle needs v2 at one point, whatever the plan left out.
        let centre = seg
            .samples()
            .get(seg.samples().len() / 2)
            .ok_or(Fault::InvalidScene)?;
        let m = CLOSED_F32.motion(update, centre)?;
        let drift_rad = libm::atanf(m.v2_mps / m.v1_mps);
        // The period minimising the worst relative mismatch over [v_min, v_max]: the
        // line speed equal to the harmonic mean of the extremes, i.e. the mean of the
        // extremes' periods.
        let a = self.plan.pixel_m;
        let period_s = 0.5 * (a / v_min + a / v_max);
        let (lo, hi) = self.period_bounds_s;
        if !(period_s >= lo && period_s <= hi) {
            return Err(Fault::PeriodOutOfRange);
        }
        let ticks = line_period_ticks(period_s, self.plan.line_clock_hz).map_err(Fault::from)?;
        // The mismatch of the period actually programmed, rounding to ticks included.
        let v_line = a * self.plan.line_clock_hz / ticks.ticks as f32;
        let worst_mismatch = (v_line / v_min - 1.0)
            .abs()
            .max((1.0 - v_line / v_max).abs());
        // Past the sinc's first zero no contrast is left; its negative lobe is a phase
        // reversal, not an MTF below 0.
        let mtf = mtf_mismatch(u32::from(seg.tdi_stages), worst_mismatch)
            .map_err(Fault::from)?
            .clamp(0.0, 1.0);
        let max_stages = self
            .plan
            .stage_rule
            .max_stages(worst_mismatch, u32::from(self.plan.max_stages))
            .map_err(Fault::from)?;
        Ok(SegmentOutput {
            index: seg.index,
            ticks: ticks.ticks,
            worst_mismatch,
            mtf,
            max_stages: max_stages as u16,
            drift_rad,
            held: false,
        })
    }
}

/// Smallest and largest |v_P| over a segment's samples, with the plan's terms.
fn extremes<const LIMB: bool, const DRIFT: bool>(
    update: &core_math::closed_form::UpdateConst<f32>,
    samples: &[core_math::closed_form::PixelConst<f32>],
) -> Result<(f32, f32), Fault> {
    let mut v_min = f32::INFINITY;
    let mut v_max = 0.0f32;
    for p in samples {
        let m = CLOSED_F32.motion_terms::<LIMB, DRIFT>(update, p)?;
        let v = if DRIFT { m.speed_mps() } else { m.v1_mps.abs() };
        v_min = v_min.min(v);
        v_max = v_max.max(v);
    }
    Ok((v_min, v_max))
}

/// The physically possible line periods for `scene` over the configured altitudes, from
/// bounds on |v_P| that hold for any roll, orbit position and Earth rotation:
/// - fastest: the ground point moves at most (Omega + omega) R relative to the orbital
///   frame, at a depth of at least H cos(alpha) and magnified by f / cos(alpha), so
///   |v_P| <= f (Omega(H_min) + omega) R / (H_min cos^2 alpha_max);
/// - slowest: |v1| >= f (|Omega - omega| cos(theta) - omega sin(theta)) / (rho / R) with
///   the limb's theta and slant range rho at H_max (the worst case of each term).
///
/// The bounds are proved against the reference over the envelope by the controller's tests.
pub fn period_bounds_s(scene: &Scene, config: &Config) -> (f32, f32) {
    let r = config.earth_radius_m;
    let (h_lo, h_hi) = config.altitude_range_m;
    let w = EARTH_RATE_RAD_S;
    let f = scene.camera.focal_m;
    let a = scene.camera.pixel_m;
    // Widest field angle among the segments' ends.
    let mut tan_max = 0.0f64;
    for s in scene.segments.iter().take(usize::from(scene.count)) {
        for n in [s.first_px, s.last_px] {
            tan_max = tan_max.max((f64::from(n) * a / f).abs());
        }
    }
    let cos2 = 1.0 / (1.0 + tan_max * tan_max);
    let omega_hi = core_math::orbital_rate_rad_s(r, h_lo);
    let v_fast = f * (omega_hi + w) * r / (h_lo * cos2);
    let omega_lo = core_math::orbital_rate_rad_s(r, h_hi);
    let k = (r + h_hi) / r;
    let cos_theta = 1.0 / k;
    let sin_theta = libm::sqrt(1.0 - cos_theta * cos_theta);
    let rho_over_r = libm::sqrt(k * k - 1.0);
    let v_slow = f * ((omega_lo - w) * cos_theta - w * sin_theta) / rho_over_r;
    ((a / v_fast) as f32, (a / v_slow) as f32)
}

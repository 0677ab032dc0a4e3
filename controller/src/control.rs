//! The line-rate controller's state: the scene and its plan in force, the last accepted
//! NAV state or the bus's GNSS fix and attitude, the clock and the update schedule, the outputs in force and the fault
//! counters, with their accessors. The work on that state is in two modules of its own:
//! [`crate::intake`] (frames to state, [`Controller::on_frame`]) and [`crate::update`]
//! (state to periods, [`Controller::advance`]). Both read and write the fields, which
//! are crate-visible for them; this module uses neither.
//!
//! The model is the general real-Earth form of core-math (`GENERAL_F32`): WGS 84
//! ([`crate::EARTH`]), the NAV state propagated on a two-body orbit to the update instant
//! ([`crate::nav::Propagator`]), the full attitude at its rates, each segment's ground
//! at its own height (SCENE, TERRAIN).
//!
//! Faults never reach the registers: a refused frame leaves the state as it was, a
//! refused computation leaves that segment's last good period in force, and nothing
//! outside the physically possible period range is ever written.

use core_math::earth::dem::DemTile;
use core_math::earth::frames::{CelestialPole, TimeScales};
use core_math::earth::Attitude;

use crate::config::Config;
use crate::dem::{Dem, DemStatus, DemStore};
use crate::fault::{Counters, Fault, ResetCause};
use crate::nav::Propagator;
use crate::plan::Plan;
use crate::scene::{Scene, MAX_SEGMENTS};
use crate::track::{pole_for, AttitudeState, GnssState};

/// The last accepted NAV state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavState {
    pub time_us: u64,
    pub propagator: Propagator,
    /// The attitude, yaw wrapped to [-pi, pi].
    pub attitude: Attitude<f32>,
}

/// One segment's output at one update.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SegmentOutput {
    pub index: u8,
    pub ticks: u32,
    /// Bound on the worst relative mismatch |v_line / |v1| - 1| over every pixel of the
    /// segment: the samples' extremes widened by the plan's interpolation bound.
    /// f32::MAX when the image is too slow for any bound (the MTF is then 0).
    pub worst_mismatch: f32,
    /// MTF at Nyquist with the segment's stages: mismatch MTF at `worst_mismatch` times
    /// drift-smear MTF at `worst_drift_rad`, each |sinc|, the modulus of the smear's
    /// transfer function (in [0, 1]).
    pub mtf: f32,
    /// Largest TDI stage count whose combined MTF meets the scene's floor.
    pub max_stages: u16,
    /// atan(v2 / v1) at the segment's centre pixel (rad).
    pub drift_rad: f32,
    /// Largest |atan(v2 / v1)| over the segment's samples and centre (rad).
    pub worst_drift_rad: f32,
    /// The centre pixel's drift once the yaw steering request is applied (rad); the
    /// unsteered drift when no request could be formed.
    pub residual_drift_rad: f32,
    /// The image moves towards +P1, against the forward-flight direction (-P1): the TDI
    /// transfer must run the other way (flying backwards, yaw near 180 deg).
    pub reversed: bool,
    /// True when this is the last good value held over a fault.
    pub held: bool,
}

/// Every output slot as `SegmentOutput::default()`, as one constant: all zero, so the
/// blank session clears it at once (built from `default()` in place, it was a store
/// per field of each slot: docs/target.md, flash).
const NO_OUTPUTS: [SegmentOutput; MAX_SEGMENTS] = [SegmentOutput {
    worst_mismatch: 0.0,
    held: false,
    ..SegmentOutput::no_period(0)
}; MAX_SEGMENTS];

impl SegmentOutput {
    /// The record of an active segment that has no valid period: none computed yet
    /// under its current geometry (a new or changed segment whose updates all failed).
    /// Ticks 0, which is never a period; no contrast promised (MTF 0, stage limit 0,
    /// mismatch f32::MAX, as for an image too slow for any bound); drifts 0, not
    /// computed; flagged held. Nothing is written to its register for it.
    pub const fn no_period(index: u8) -> SegmentOutput {
        SegmentOutput {
            index,
            ticks: 0,
            worst_mismatch: f32::MAX,
            mtf: 0.0,
            max_stages: 0,
            drift_rad: 0.0,
            worst_drift_rad: 0.0,
            residual_drift_rad: 0.0,
            reversed: false,
            held: true,
        }
    }
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

/// The controller: its state here, frame intake in [`crate::intake`], the update in
/// [`crate::update`]. Not `Clone`: it may borrow its DEM tile memory exclusively
/// ([`crate::dem`]).
pub struct Controller {
    pub config: Config,
    pub(crate) scene: Scene,
    pub(crate) plan: Plan,
    /// Where a new scene's plan is built, in place, before it replaces `plan` (a plan is
    /// 4.7 KB: kept off the stack, docs/target.md).
    pub(crate) spare_plan: Plan,
    /// Ground height of each table entry (m): from the scene, then TERRAIN frames.
    pub(crate) heights_m: [f32; MAX_SEGMENTS],
    pub(crate) nav: Option<NavState>,
    /// The bus's data (version 4), the other source of state: a NAV frame drops them,
    /// a GNSS or ATTITUDE frame drops the NAV state. Updates run on them when both are
    /// in force ([`crate::track`]).
    pub(crate) gnss: Option<GnssState>,
    pub(crate) attitude: Option<AttitudeState>,
    /// The attitude estimate kept across a reset (`restart`): the blend's last estimate
    /// until an ATTITUDE frame is in force again.
    pub(crate) blend_seed: Option<crate::bus::StarAttitude>,
    /// GPS - UTC and UT1 - UTC in force (TIME_SCALES; the contract's defaults, 18 s
    /// and 0, from boot).
    pub(crate) time_scales: TimeScales,
    /// The slowly moving part of C2T, kept for up to a minute.
    pub(crate) pole: Option<CelestialPole>,
    /// Time tag of the last accepted frame of any kind (us).
    pub(crate) last_time_us: Option<u64>,
    /// Time tag of the previous frame, when it was refused for its time tag alone: the
    /// first half of a re-synchronisation.
    pub(crate) resync_candidate_us: Option<u64>,
    pub(crate) now_us: u64,
    pub(crate) next_update_us: u64,
    /// The update period `next_update_us` was scheduled with (0: none yet).
    pub(crate) scheduled_period_us: u64,
    pub(crate) last_update_us: Option<u64>,
    pub counters: Counters,
    pub last_fault: Option<Fault>,
    pub frames_accepted: u32,
    /// Re-synchronisations of the clock (each also counts as an accepted frame).
    pub time_resyncs: u32,
    pub(crate) outputs: [SegmentOutput; MAX_SEGMENTS],
    pub(crate) has_output: [bool; MAX_SEGMENTS],
    /// The yaw correction (rad) that zeroes the drift at the array centre, from the
    /// last update; `None` when that update could not form it.
    pub(crate) yaw_request_rad: Option<f32>,
    /// Update instants run, whatever they computed: one PERIODS frame each.
    pub updates: u32,
    /// The mode an update ran in (the one its PERIODS frame reports).
    pub(crate) update_mode: Mode,
    /// Changes whenever the scene or the ground heights in force change (a SCENE or
    /// TERRAIN frame accepted, a restore): when to take a new snapshot of them
    /// ([`crate::restart`]).
    pub(crate) inputs_generation: u32,
    /// Why the core last started and the resets since power-on, as the firmware noted
    /// them ([`Controller::note_boot`]): STATUS reports them.
    pub(crate) boot: Option<(ResetCause, u32)>,
    /// The DEM tile upload and the tile in force ([`crate::dem`]).
    pub(crate) dem: Dem,
    /// The DEM tile in force and the per-sample state of its route
    /// ([`crate::dem_ground`]), in place from the controller's construction; while
    /// none is in force (`DemGround::active`), the TERRAIN heights are the ground.
    pub(crate) dem_ground: crate::dem_ground::DemGround,
    /// A tile given by [`Controller::set_dem_tile`] (tests, the bench): it wins over
    /// the uploaded one.
    pub(crate) dem_given: Option<DemTile<'static, i16>>,
}

impl Controller {
    /// A controller with `scene` in force (normally [`Scene::paper_default`]).
    pub fn new(config: Config, scene: Scene) -> Result<Controller, Fault> {
        let mut c = Controller::blank(config);
        c.set_scene(scene)?;
        Ok(c)
    }

    /// A controller on the evaluate-everything plan ([`Plan::exhaustive`]): every
    /// segment, the most samples. The baseline the planner is measured against
    /// (`cargo xtask bench`); not for flight.
    pub fn evaluate_everything(config: Config, scene: Scene) -> Result<Controller, Fault> {
        let mut c = Controller::blank(config);
        c.spare_plan.build_into(&scene, &c.config, true)?;
        c.install(scene);
        Ok(c)
    }

    /// A controller with no scene (no segment, nothing to compute) until
    /// [`Controller::set_scene`]: the firmware places one in static memory this way and
    /// then plans its scene in place, so that no 10 KB controller passes through its
    /// stack.
    #[inline(always)]
    pub fn blank(config: Config) -> Controller {
        Controller {
            config,
            heights_m: [0.0; MAX_SEGMENTS],
            scene: Scene::paper_default(),
            plan: Plan::blank(),
            spare_plan: Plan::blank(),
            nav: None,
            gnss: None,
            attitude: None,
            blend_seed: None,
            time_scales: TimeScales::DEFAULT,
            pole: None,
            last_time_us: None,
            resync_candidate_us: None,
            now_us: 0,
            next_update_us: 0,
            scheduled_period_us: 0,
            last_update_us: None,
            counters: Counters::default(),
            last_fault: None,
            frames_accepted: 0,
            time_resyncs: 0,
            outputs: NO_OUTPUTS,
            has_output: [false; MAX_SEGMENTS],
            yaw_request_rad: None,
            updates: 0,
            update_mode: Mode::WaitingForNav,
            inputs_generation: 0,
            boot: None,
            dem: Dem::default(),
            dem_ground: crate::dem_ground::DemGround::blank(),
            dem_given: None,
        }
    }

    /// Puts `scene` in force, planned in place (what a SCENE frame does); on an error
    /// nothing changes.
    pub fn set_scene(&mut self, scene: Scene) -> Result<(), Fault> {
        self.spare_plan.build_into(&scene, &self.config, false)?;
        self.install(scene);
        Ok(())
    }

    /// The spare plan, just built for `scene`, goes in force.
    ///
    /// A segment's output stays in force, held or not, where the new scene leaves its
    /// period's meaning as it was ([`Scene::keeps_output_of`]: the same camera, clock,
    /// floor, envelope and chip; the ground height may change, as a TERRAIN frame
    /// changes it), so a re-upload of the same scene changes no output. A segment whose
    /// geometry changed has no valid last period: its output is dropped, and until its
    /// first period under the new scene it is reported as having none
    /// ([`SegmentOutput::no_period`]).
    fn install(&mut self, scene: Scene) {
        core::mem::swap(&mut self.plan, &mut self.spare_plan);
        scene.keep_outputs_of(&self.scene, &mut self.has_output);
        self.heights_m = scene.segments.map(|s| s.ground_h_m);
        let remount = scene.mounting_q != self.scene.mounting_q;
        self.scene = scene;
        self.inputs_generation = self.inputs_generation.wrapping_add(1);
        if remount {
            self.rederive_attitude();
        }
    }

    /// The attitude in force derived again after the mounting or the time scales
    /// changed; dropped (until the next ATTITUDE frame) should it no longer derive.
    // Out of line: inlined into both its callers, the frame intake and a scene's
    // install (docs/target.md, flash).
    #[inline(never)]
    pub(crate) fn rederive_attitude(&mut self) {
        let Some(a) = self.attitude else { return };
        let derived = pole_for(self.pole.as_ref(), a.received.valid_us, &self.time_scales)
            .and_then(|pole| {
                self.pole = Some(pole);
                AttitudeState::derive(
                    &a.received,
                    &self.scene.mounting_q,
                    &pole,
                    &self.time_scales,
                    self.gnss.as_ref(),
                )
            });
        self.attitude = derived.ok();
    }

    /// Notes why the core last started and how many resets there have been since
    /// power-on, for STATUS.
    pub fn note_boot(&mut self, cause: ResetCause, resets: u32) {
        self.boot = Some((cause, resets));
    }

    /// What [`Controller::note_boot`] noted.
    pub fn boot(&self) -> Option<(ResetCause, u32)> {
        self.boot
    }

    /// Changes whenever the scene or the ground heights in force change.
    pub fn inputs_generation(&self) -> u32 {
        self.inputs_generation
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
    /// The last GNSS fix in force (bus data).
    pub fn gnss(&self) -> Option<&GnssState> {
        self.gnss.as_ref()
    }
    /// The last attitude in force (bus data).
    pub fn bus_attitude(&self) -> Option<&AttitudeState> {
        self.attitude.as_ref()
    }
    /// GPS - UTC and UT1 - UTC in force.
    pub fn time_scales(&self) -> &TimeScales {
        &self.time_scales
    }
    /// The ground height in force for each entry of the scene's table (m).
    pub fn heights_m(&self) -> &[f32] {
        &self.heights_m[..usize::from(self.scene.count).min(MAX_SEGMENTS)]
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
        self.plan.period_bounds_s
    }
    /// The yaw steering request of the last update (rad): turn the camera by this
    /// about its boresight (add it to the yaw) to zero the drift at the array centre.
    pub fn yaw_request_rad(&self) -> Option<f32> {
        self.yaw_request_rad
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

    // Out of line: inlined into the update, the STATUS report and the firmware's loop
    // (docs/target.md, flash).
    #[inline(never)]
    pub(crate) fn mode_at(&self, t_us: u64) -> Mode {
        match (&self.nav, &self.gnss, &self.attitude) {
            (Some(n), _, _) if t_us.saturating_sub(n.time_us) > self.config.stale_after_us => {
                Mode::Stale
            }
            (Some(_), _, _) => Mode::Nominal,
            (None, Some(g), Some(a)) => {
                let old = |t0: u64, limit: u64| t_us.saturating_sub(t0) > limit;
                if old(g.fix_us, self.config.gnss_stale_after_us)
                    || old(a.received.valid_us, self.config.stale_after_us)
                {
                    Mode::Stale
                } else {
                    Mode::Nominal
                }
            }
            _ => Mode::WaitingForNav,
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

    /// Every output in force is now the last good value held over a fault.
    pub(crate) fn hold_all(&mut self) {
        for o in self.outputs.iter_mut() {
            o.held = true;
        }
    }

    /// Segment `index` keeps the output it has in force, flagged held; one with none
    /// (no period under its geometry yet) gets [`SegmentOutput::no_period`], so that
    /// every active segment has a record from the first update with NAV on.
    // Out of line: a fault's path, inlined at each of its callers in the update
    // (docs/target.md, flash).
    #[inline(never)]
    pub(crate) fn hold(&mut self, index: u8) {
        let slot = usize::from(index);
        if let (Some(o), Some(h)) = (self.outputs.get_mut(slot), self.has_output.get_mut(slot)) {
            if *h {
                o.held = true;
            } else {
                *o = SegmentOutput::no_period(index);
                *h = true;
            }
        }
    }

    /// Every active segment of the plan in force held ([`Controller::hold`]).
    pub(crate) fn hold_planned(&mut self) {
        for k in 0..self.plan.segments.len() {
            if let Some(index) = self.plan.segments.get(k).map(|s| s.index) {
                self.hold(index);
            }
        }
    }
}

impl Controller {
    /// Lends the controller its tile memory. Nothing in it is trusted: no tile is in
    /// force until an upload commits or [`Controller::restore_dem`] checks the recorded
    /// one. Returns the store it had, if any.
    pub fn attach_dem(&mut self, store: &'static mut DemStore) -> Option<&'static mut DemStore> {
        let old = self.dem.attach(store);
        self.refresh_dem_ground();
        old
    }

    /// Takes the tile memory back (the controller then refuses DEM frames and has no
    /// tile in force).
    pub fn detach_dem(&mut self) -> Option<&'static mut DemStore> {
        let store = self.dem.detach();
        self.refresh_dem_ground();
        store
    }

    /// Puts the tile recorded in the store before a reset back in force, if its record
    /// and its CRC-32 check out (a pass over the whole tile: call it after the kept
    /// periods are written). Returns its upload id; on a refusal nothing changes.
    pub fn restore_dem(&mut self) -> Result<u32, Fault> {
        let restored = self.dem.restore();
        self.refresh_dem_ground();
        restored
    }

    /// The DEM tile in force, for the per-sample ground of the update; `None` when no
    /// tile is in force (the scene's per-segment heights then apply).
    pub fn dem_tile(&self) -> Option<DemTile<'_, i16>> {
        self.dem.tile()
    }

    /// The upload's state (STATUS).
    pub fn dem_status(&self) -> DemStatus {
        self.dem.status()
    }
}

#[cfg(test)]
mod blank_tests {
    use super::*;

    /// The blank session's output slots are what `SegmentOutput::default()` gives.
    #[test]
    fn no_outputs_are_the_default() {
        assert_eq!(NO_OUTPUTS, [SegmentOutput::default(); MAX_SEGMENTS]);
    }
}

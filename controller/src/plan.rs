//! The scene plan: built once when a scene arrives, so that per update only what the
//! scene needs is evaluated. Inactive segments have no entry at all. Each active segment
//! is sampled at the fewest equally spaced field points that bound the error of its
//! velocity extremes to a tenth of its mismatch budget.
//!
//! The bound: between samples h pixels apart, a smooth |v|(n) exceeds the samples'
//! extremes by at most h^2/8 max|v''| (the error of linear interpolation), so the
//! relative error of the segment's v_min and v_max is at most c h^2 / 8 with
//! c = max |v''| / v. The planner estimates c by second differences of the shipped f32
//! model on a probe grid over the envelope (every roll the scene allows, the configured
//! altitudes, orbit positions and inclinations), doubles it for safety, and takes the
//! smallest sample count meeting the budget. The controller's tests check the result
//! against dense evaluations of the f64 reference.

use core_math::closed_form::{PixelConst, UpdateConst, LIMB_BRANCH_RAD};
use core_math::{Backend, Geometry, StageRule, CLOSED_F32, EARTH_RATE_RAD_S};

use crate::fault::Fault;
use crate::scene::{Scene, SegmentSpec, MAX_SEGMENTS};

/// Most field points one segment may be sampled at.
pub const MAX_SAMPLES: usize = 9;
/// Share of a segment's mismatch budget the sampling error may use.
pub const SAMPLING_SHARE: f64 = 0.1;
/// Safety factor on the probed curvature.
pub const CURVATURE_SAFETY: f64 = 2.0;
/// Probe points across a segment for the curvature estimate.
const PROBES: usize = 9;

/// The orbits the plan must hold for: round-Earth radius and the altitude range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Envelope {
    pub earth_radius_m: f64,
    pub altitude_range_m: (f64, f64),
}

/// One active segment, ready to evaluate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentPlan {
    /// Index in the scene's segment table.
    pub index: u8,
    pub tdi_stages: u16,
    pub samples: [PixelConst<f32>; MAX_SAMPLES],
    pub n_samples: u8,
    /// Pixel offsets of the samples.
    pub sample_px: [i32; MAX_SAMPLES],
    /// Relative error allowed on the segment's velocity extremes.
    pub sampling_budget: f32,
    /// Relative error bound of the chosen sampling (at most the budget unless even
    /// [`MAX_SAMPLES`] points could not meet it, e.g. close to the limb).
    pub sampling_bound: f32,
}

impl SegmentPlan {
    // `n_samples` <= MAX_SAMPLES in every plan `Plan::build` makes; the `min` proves it
    // to the optimiser (no panic path, docs/no-panic.md).
    pub fn samples(&self) -> &[PixelConst<f32>] {
        &self.samples[..usize::from(self.n_samples).min(MAX_SAMPLES)]
    }
    pub fn sample_px(&self) -> &[i32] {
        &self.sample_px[..usize::from(self.n_samples).min(MAX_SAMPLES)]
    }
}

/// Which optional terms of the closed form a plan evaluates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Terms {
    /// The limb-distance form (needed only within [`LIMB_BRANCH_RAD`] of the limb).
    pub limb: bool,
    /// v2 in |v_P| (its share of |v_P| is (v2/v1)^2 / 2).
    pub drift: bool,
}

impl Terms {
    pub const ALL: Terms = Terms {
        limb: true,
        drift: true,
    };
}

/// Share of a segment's mismatch budget that left-out terms may use.
pub const TERM_SHARE: f64 = 0.1;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    pub segments: [SegmentPlan; MAX_SEGMENTS],
    /// The terms every update evaluates.
    pub terms: Terms,
    /// Smallest angular distance from any sample's line of sight to the limb over the
    /// envelope (rad), computed from the lowest limb angle (highest altitude) and the
    /// largest roll plus field angle. The limb form is left out when it is at least
    /// [`LIMB_BRANCH_RAD`].
    pub limb_margin_rad: f32,
    /// Largest relative change of |v_P| from leaving v2 out, (v2/v1)^2 / 2 over the
    /// probe grid at every sample, doubled. v2 is left out when it is under
    /// [`TERM_SHARE`] of the smallest segment budget.
    pub drift_bound: f32,
    /// Number of active segments (entries in `segments`).
    pub count: u8,
    pub pixel_m: f32,
    pub line_clock_hz: f32,
    pub stage_rule: StageRule<f32>,
    pub max_stages: u16,
    pub max_roll_rad: f32,
}

/// Per-update constants of the probe grid: rolls across the scene's range, both ends
/// of the altitude range, equatorial and polar planes, four orbit positions.
fn probe_updates(scene: &Scene, env: &Envelope) -> [Option<UpdateConst<f32>>; 80] {
    let mut out = [None; 80];
    let mut k = 0;
    let r = f64::from(scene.max_roll_rad);
    for roll in [-r, -0.5 * r, 0.0, 0.5 * r, r] {
        for h in [env.altitude_range_m.0, env.altitude_range_m.1] {
            for i0 in [0.0, core::f64::consts::FRAC_PI_2] {
                for q in 0..4 {
                    let g0 = f64::from(q) * core::f64::consts::FRAC_PI_2;
                    let g = Geometry {
                        roll_rad: roll,
                        inclination_rad: i0,
                        arg_latitude_rad: g0,
                        altitude_m: h,
                        earth_radius_m: env.earth_radius_m,
                        earth_rate_rad_s: EARTH_RATE_RAD_S,
                        orbit_rate_rad_s: core_math::orbital_rate_rad_s(env.earth_radius_m, h),
                    };
                    if let Some(slot) = out.get_mut(k) {
                        *slot = CLOSED_F32.update(&g.to::<f32>()).ok();
                    }
                    k += 1;
                }
            }
        }
    }
    out
}

/// max |v''| / v over the segment (per pixel^2), by second differences on the probes.
fn curvature(
    scene: &Scene,
    spec: &SegmentSpec,
    updates: &[Option<UpdateConst<f32>>],
) -> Result<f64, Fault> {
    let width = f64::from(spec.last_px) - f64::from(spec.first_px);
    if width <= 0.0 {
        return Ok(0.0);
    }
    let h = width / (PROBES - 1) as f64;
    let mut probes = [None; PROBES];
    for (j, p) in probes.iter_mut().enumerate() {
        let n = f64::from(spec.first_px) + h * j as f64;
        *p = Some(
            CLOSED_F32
                .pixel(&scene.camera, n)
                .map_err(|_| Fault::InvalidScene)?,
        );
    }
    let mut c = 0.0f64;
    for u in updates.iter().flatten() {
        let mut v = [0.0f64; PROBES];
        let mut ok = true;
        for (vj, p) in v.iter_mut().zip(probes.iter().flatten()) {
            match CLOSED_F32.motion(u, p) {
                Ok(m) => *vj = f64::from(m.speed_mps()),
                Err(_) => ok = false,
            }
        }
        // Conditions where the segment sees past the limb cannot be imaged: skip.
        if !ok {
            continue;
        }
        for w in v.windows(3) {
            c = c.max((w[0] - 2.0 * w[1] + w[2]).abs() / (w[1] * h * h));
        }
    }
    Ok(c)
}

/// (limb margin, drift bound) of a plan's samples over the envelope; see [`Plan`].
fn term_bounds(
    scene: &Scene,
    env: &Envelope,
    segments: &[SegmentPlan],
    updates: &[Option<UpdateConst<f32>>],
) -> (f64, f64) {
    let r = env.earth_radius_m;
    let limb = libm::asin(r / (r + env.altitude_range_m.1));
    let mut widest = 0.0f64;
    let mut drift = 0.0f64;
    for seg in segments {
        for (&n, p) in seg.sample_px().iter().zip(seg.samples()) {
            let tan = f64::from(n) * scene.camera.pixel_m / scene.camera.focal_m;
            widest = widest.max(libm::fabs(libm::atan(tan)));
            for u in updates.iter().flatten() {
                if let Ok(m) = CLOSED_F32.motion(u, p) {
                    let ratio = f64::from(m.v2_mps) / f64::from(m.v1_mps);
                    drift = drift.max(ratio * ratio / 2.0);
                }
            }
        }
    }
    (limb - f64::from(scene.max_roll_rad) - widest, 2.0 * drift)
}

impl Plan {
    /// The plan of `scene`: active segments only, the fewest samples, the terms needed.
    pub fn new(scene: &Scene, env: &Envelope) -> Result<Plan, Fault> {
        Plan::build(scene, env, false)
    }

    /// The evaluate-everything plan, the baseline the planner is measured against:
    /// every segment of the table whether active or not, [`MAX_SAMPLES`] samples each,
    /// every term.
    pub fn exhaustive(scene: &Scene, env: &Envelope) -> Result<Plan, Fault> {
        Plan::build(scene, env, true)
    }

    fn build(scene: &Scene, env: &Envelope, exhaustive: bool) -> Result<Plan, Fault> {
        scene.validate()?;
        // The focal plane the scene describes must see the Earth: a pixel whose field
        // angle is past the limb at the highest altitude, even at nadir, images nothing.
        let r = env.earth_radius_m;
        let limb = libm::asin(r / (r + env.altitude_range_m.1));
        for spec in scene.segments.iter().take(usize::from(scene.count)) {
            for n in [spec.first_px, spec.last_px] {
                let alpha =
                    libm::atan((f64::from(n) * scene.camera.pixel_m / scene.camera.focal_m).abs());
                if !(alpha < limb) {
                    return Err(Fault::InvalidScene);
                }
            }
        }
        let stage_rule =
            StageRule::<f32>::new(f64::from(scene.mtf_floor)).map_err(|_| Fault::InvalidScene)?;
        let updates = probe_updates(scene, env);
        let blank_pixel = CLOSED_F32
            .pixel(&scene.camera, 0.0)
            .map_err(|_| Fault::InvalidScene)?;
        let blank = SegmentPlan {
            index: 0,
            tdi_stages: 1,
            samples: [blank_pixel; MAX_SAMPLES],
            n_samples: 0,
            sample_px: [0; MAX_SAMPLES],
            sampling_budget: 0.0,
            sampling_bound: 0.0,
        };
        let mut segments = [blank; MAX_SEGMENTS];
        let mut count = 0usize;
        let table = scene
            .segments
            .iter()
            .take(usize::from(scene.count))
            .enumerate();
        for (index, spec) in table.filter(|(_, s)| exhaustive || s.active) {
            let slot = segments.get_mut(count).ok_or(Fault::InvalidScene)?;
            let budget = SAMPLING_SHARE * f64::from(stage_rule.mismatch_budget())
                / f64::from(spec.tdi_stages);
            let c = CURVATURE_SAFETY * curvature(scene, spec, &updates)?;
            let width = f64::from(spec.last_px) - f64::from(spec.first_px);
            // Smallest K >= 2 with c (width / (K - 1))^2 / 8 <= budget.
            let mut k = if exhaustive { MAX_SAMPLES } else { 2usize };
            while k < MAX_SAMPLES
                && c * (width / (k - 1) as f64) * (width / (k - 1) as f64) / 8.0 > budget
            {
                k += 1;
            }
            let spacing = width / (k - 1) as f64;
            slot.index = index as u8;
            slot.tdi_stages = spec.tdi_stages;
            slot.n_samples = k as u8;
            slot.sampling_budget = budget as f32;
            slot.sampling_bound = (c * spacing * spacing / 8.0) as f32;
            for j in 0..k {
                // Rounded to whole pixels; the ends are exact.
                let n = libm::round(f64::from(spec.first_px) + spacing * j as f64) as i32;
                slot.sample_px[j] = n;
                slot.samples[j] = CLOSED_F32
                    .pixel(&scene.camera, f64::from(n))
                    .map_err(|_| Fault::InvalidScene)?;
            }
            count += 1;
        }
        // count <= MAX_SEGMENTS (each slot came from `get_mut`); the `min` says so.
        let active = &segments[..count.min(MAX_SEGMENTS)];
        let (limb_margin_rad, drift_bound) = term_bounds(scene, env, active, &updates);
        let smallest_budget = active
            .iter()
            .map(|s| f64::from(s.sampling_budget) / SAMPLING_SHARE)
            .fold(f64::INFINITY, f64::min);
        let terms = if exhaustive {
            Terms::ALL
        } else {
            Terms {
                limb: limb_margin_rad < LIMB_BRANCH_RAD,
                drift: drift_bound > TERM_SHARE * smallest_budget,
            }
        };
        Ok(Plan {
            segments,
            terms,
            limb_margin_rad: limb_margin_rad as f32,
            drift_bound: drift_bound as f32,
            count: count as u8,
            pixel_m: scene.camera.pixel_m as f32,
            line_clock_hz: scene.line_clock_hz as f32,
            stage_rule,
            max_stages: scene.max_stages,
            max_roll_rad: scene.max_roll_rad,
        })
    }

    pub fn active(&self) -> &[SegmentPlan] {
        &self.segments[..usize::from(self.count).min(MAX_SEGMENTS)]
    }
}

//! The scene plan: built once when a scene arrives, so that per update only what the
//! scene needs is evaluated. Inactive segments have no entry at all. Each active segment
//! is sampled at the fewest equally spaced pixels whose interpolation error stays within
//! a tenth of its mismatch budget, and that error is carried into every update's
//! reported worst mismatch, so the report bounds the truth over every pixel.
//!
//! The bound: between samples H pixels apart, a smooth v1(n) leaves the samples' range
//! by at most H^2/8 max|v1''| (the error of linear interpolation). In the general model
//! the attitude rates add to v1 a term linear in the pixel offset (-W x u, projected),
//! so |v1''| does not depend on them: it depends on the attitude angles, the orbit, the
//! ellipsoid and the terrain. The planner bounds it by second differences of the
//! shipped f32 model on a probe grid over the envelope (roll and pitch to the scene's
//! limits, yaw steering angles, the highest and lowest orbits at the equator and near
//! the pole, the lowest and highest ground), doubled for safety; the per-update bound
//! is then H^2/8 of that over the smallest sampled |v1|, which grows honestly when an
//! attitude rate slows the image. The controller's tests check it against dense
//! evaluations of the f64 reference (1 000 pixels a segment) over the envelope.

use core_math::earth::{circular_state, Attitude, GeneralPixel, GeneralRow, GeneralUpdate};
use core_math::{Backend, StageRule, GENERAL_F32};
use heapless::Vec;

use crate::config::{Config, EARTH, EARTH_RATE_RAD_S};
use crate::fault::Fault;
use crate::scene::{
    AttitudeEnvelope, Scene, SegmentSpec, MAX_GROUND_H_M, MAX_SEGMENTS, MIN_GROUND_H_M,
};

/// Most pixels one segment may be sampled at.
pub const MAX_SAMPLES: usize = 9;
/// Share of a segment's mismatch budget the sampling error may use.
pub const SAMPLING_SHARE: f64 = 0.1;
/// Safety factor on the probed curvature.
pub const CURVATURE_SAFETY: f64 = 2.0;
/// Probe points across a segment for the curvature estimate.
const PROBES: usize = 9;
/// Yaw angles of the probe grid (rad): unsteered, and steered either way by more than
/// the largest drift a yaw steering law asks for (4.6 deg, docs/derivation.md).
const PROBE_YAWS_RAD: [f64; 3] = [-0.1, 0.0, 0.1];

/// One sample pixel of a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Pixel offset n (a half-integer at the centre of an even count of pixels, any
    /// value between whole pixels inside the segment).
    pub px: f32,
    /// Its p2 = n x pixel pitch (m) on the segment's row.
    pub p2_m: f32,
}

/// One active segment, ready to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentPlan {
    /// Index in the scene's segment table.
    pub index: u8,
    pub tdi_stages: u16,
    /// The segment's row of the focal plane (its p1): every sample and the centre lie
    /// on it, so that an update evaluates them by the row form
    /// (`core_math::General::row_motion`).
    pub row: GeneralRow<f32>,
    /// The pixels evaluated at every update: first the segment's centre (its drift is
    /// reported there), then the samples, equally spaced from the segment's first pixel
    /// to its last in ascending order. The middle sample of an odd count is the centre
    /// itself, not repeated. The centre counts in the extremes like any sample: it is a
    /// pixel of the segment.
    pub samples: Vec<Sample, MAX_SAMPLES>,
    /// The centre's pixel constants, for the steered residual (`General::motion_yawed`).
    pub centre: GeneralPixel<f32>,
    /// `samples`' pixel constants of the fixed-point backend, in the same order.
    #[cfg(feature = "earth-fixed")]
    pub fixed: Vec<core_math::earth::fixed::EarthFixedPixel, MAX_SAMPLES>,
    /// Relative error allowed on the segment's velocity extremes.
    pub sampling_budget: f32,
    /// Largest amount v1 may leave the samples' range between two samples (m/s):
    /// (bound on |v1''|) x spacing^2 / 8.
    pub interpolation_mps: f32,
    /// Relative sampling error at the slowest image of the probe grid (at most the
    /// budget unless even [`MAX_SAMPLES`] pixels could not meet it).
    pub sampling_bound: f32,
}

/// The line of sight of no pixel, in unused plan entries.
const BLANK_PIXEL: GeneralPixel<f32> = GeneralPixel {
    u_m: [0.0; 3],
    uu_m2: 0.0,
    t1: 0.0,
    t2: 0.0,
};

#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The active segments, in table order.
    pub segments: Vec<SegmentPlan, MAX_SEGMENTS>,
    /// The array centre: the boresight pixel (p1 = p2 = 0), where a yaw turn turns the
    /// image motion and nothing else (the yaw steering request zeroes its drift).
    pub boresight: GeneralPixel<f32>,
    /// The table index of the segment whose ground the boresight sees: the one
    /// containing pixel 0; when none does (a gap in the mosaic at the array centre), the
    /// table entry nearest to pixel 0, active or not (its height is known: SCENE,
    /// TERRAIN), on a tie the lower index, at negative pixels. The yaw request is then
    /// still formed over that ground and flagged valid (docs/controller.md, "Per
    /// update"; `controller/tests/yaw_request.rs`).
    pub boresight_segment: u8,
    /// The plan segment and sample whose pixel is the boresight (a row at p1 = 0 with a
    /// sample at p2 = 0, as in a single row of butted segments), if any: over a DEM
    /// tile the yaw request's ground is then that sample's, searched once.
    pub boresight_sample: Option<(u8, u8)>,
    pub pixel_m: f32,
    pub line_clock_hz: f32,
    pub stage_rule: StageRule<f32>,
    pub max_stages: u16,
    pub envelope: AttitudeEnvelope,
    /// The physically possible line periods (s): see [`period_bounds_s`].
    pub period_bounds_s: (f32, f32),
}

/// Calls `f` with the update of every instant of the probe grid, at the lowest and the
/// highest ground (432 updates; the grid is walked once, never stored: a scene upload
/// costs no stack for it).
// Out of line, as the scene's checks: inlined into the plan build, which holds many
// values across it, they took more flash than as calls (docs/target.md, flash).
#[inline(never)]
fn for_each_probe(env: &AttitudeEnvelope, config: &Config, mut f: impl FnMut(&GeneralUpdate<f32>)) {
    let (r, p) = (f64::from(env.max_roll_rad), f64::from(env.max_pitch_rad));
    let (h_lo, h_hi) = config.altitude_range_m;
    let inclination = 98f64.to_radians();
    // Equator (radius a + h) and 82 deg latitude (nearly b + h).
    let places = [
        (0.0, EARTH.a_m),
        (core::f64::consts::FRAC_PI_2, EARTH.b_m()),
    ];
    for roll in [-r, 0.0, r] {
        for pitch in [-p, 0.0, p] {
            for yaw in PROBE_YAWS_RAD {
                for h in [h_lo, h_hi] {
                    for (u, radius) in places {
                        let state = circular_state(radius + h, inclination, u);
                        let attitude = Attitude {
                            roll_rad: roll,
                            pitch_rad: pitch,
                            yaw_rad: yaw,
                            ..Attitude::default()
                        }
                        .to::<f32>();
                        let Ok(instant) =
                            GENERAL_F32.instant(&state, &attitude, &EARTH, EARTH_RATE_RAD_S)
                        else {
                            continue;
                        };
                        for ground_h_m in [MIN_GROUND_H_M, MAX_GROUND_H_M] {
                            if let Ok(update) = GENERAL_F32.ground(&instant, &EARTH, ground_h_m) {
                                f(&update);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// One segment's probe pixels across its width, and what the probe grid has shown of
/// it so far: max |v1''| per pixel^2 by second differences at the probe spacing, and
/// min |v1|.
#[derive(Clone, Copy)]
struct Curvature {
    pixels: [GeneralPixel<f32>; PROBES],
    spacing_px: f64,
    c: f64,
    v_min: f64,
}

impl Curvature {
    /// `spec`'s probe pixels, nothing observed yet, written into `slot` (in place: a
    /// curvature is 300 bytes). On an error `slot` holds a part-built one.
    // Out of line: inlined into the plan build, it and its copies took more flash.
    #[inline(never)]
    fn start(slot: &mut Option<Curvature>, scene: &Scene, spec: &SegmentSpec) -> Result<(), Fault> {
        let camera = scene.earth_camera(spec);
        let width = f64::from(spec.last_px) - f64::from(spec.first_px);
        let spacing_px = width / (PROBES - 1) as f64;
        let c = slot.insert(Curvature {
            pixels: [BLANK_PIXEL; PROBES],
            spacing_px,
            c: 0.0,
            v_min: f64::INFINITY,
        });
        let first = f64::from(spec.first_px);
        for (j, p) in c.pixels.iter_mut().enumerate() {
            probe_pixel(p, &camera, first, spacing_px, j)?;
        }
        Ok(())
    }

    fn observe(&mut self, u: &GeneralUpdate<f32>) {
        let mut v = [0.0f64; PROBES];
        for (vj, p) in v.iter_mut().zip(&self.pixels) {
            match GENERAL_F32.motion(u, p) {
                Ok(m) => *vj = f64::from(m.v1_mps),
                // Conditions where the segment sees past the limb cannot be imaged.
                Err(_) => return,
            }
        }
        for vj in v {
            self.v_min = self.v_min.min(libm::fabs(vj));
        }
        let h = self.spacing_px;
        if h > 0.0 {
            for w in v.windows(3) {
                self.c = max_second_difference(self.c, [w[0], w[1], w[2]], h);
            }
        }
    }

    /// (max |v1''|, min |v1|) over the grid; refused if not one condition images it.
    fn result(&self) -> Result<(f64, f64), Fault> {
        if !(self.v_min > 0.0 && self.v_min.is_finite()) {
            return Err(Fault::InvalidScene);
        }
        Ok((self.c, self.v_min))
    }
}

impl Plan {
    /// The plan of no scene: no segment, nothing to evaluate. A placeholder that
    /// [`Plan::build_into`] overwrites (a controller keeps two plans and builds a new
    /// scene's into the spare one, in place).
    #[inline(always)]
    pub fn blank() -> Plan {
        Plan {
            segments: Vec::new(),
            boresight: BLANK_PIXEL,
            boresight_segment: 0,
            boresight_sample: None,
            pixel_m: 0.0,
            line_clock_hz: 0.0,
            stage_rule: StageRule::none(),
            max_stages: 0,
            envelope: AttitudeEnvelope {
                max_roll_rad: 0.0,
                max_pitch_rad: 0.0,
                max_rate_rad_s: 0.0,
            },
            period_bounds_s: (0.0, 0.0),
        }
    }

    /// The plan of `scene`: active segments only, the fewest samples.
    pub fn new(scene: &Scene, config: &Config) -> Result<Plan, Fault> {
        let mut plan = Plan::blank();
        plan.build_into(scene, config, false)?;
        Ok(plan)
    }

    /// The evaluate-everything plan, the baseline the planner is measured against:
    /// every segment of the table whether active or not, [`MAX_SAMPLES`] samples each.
    pub fn exhaustive(scene: &Scene, config: &Config) -> Result<Plan, Fault> {
        let mut plan = Plan::blank();
        plan.build_into(scene, config, true)?;
        Ok(plan)
    }

    /// Makes `self` the plan of `scene` (`exhaustive`: see [`Plan::exhaustive`]), in
    /// place: a plan is 4.7 KB, and a flight stack of a few KB cannot hold one more. On
    /// an error `self` is left part-built and must not be used (the controller builds
    /// into its spare plan and swaps only on success).
    pub fn build_into(
        &mut self,
        scene: &Scene,
        config: &Config,
        exhaustive: bool,
    ) -> Result<(), Fault> {
        scene.validate(&EARTH, config.altitude_range_m.1)?;
        let stage_rule = scene.stage_rule()?;
        // Every planned segment's curvature, the probe grid walked once for all.
        let mut curvatures: [Option<Curvature>; MAX_SEGMENTS] = [None; MAX_SEGMENTS];
        for (slot, spec) in curvatures.iter_mut().zip(scene.table()) {
            if exhaustive || spec.active {
                Curvature::start(slot, scene, spec)?;
            }
        }
        for_each_probe(&scene.envelope, config, |u| {
            for c in curvatures.iter_mut().flatten() {
                c.observe(u);
            }
        });
        let boresight_camera = core_math::EarthCamera {
            focal_m: scene.camera.focal_m,
            pixel_m: scene.camera.pixel_m,
            p1_m: 0.0,
        };
        let boresight = GENERAL_F32
            .pixel(&boresight_camera, 0.0)
            .map_err(|_| Fault::InvalidScene)?;
        self.segments.clear();
        let mut boresight_sample = None;
        let table = scene.table().iter().enumerate();
        for (index, spec) in table.filter(|(_, s)| exhaustive || s.active) {
            let camera = scene.earth_camera(spec);
            let budget = SAMPLING_SHARE * f64::from(stage_rule.mismatch_budget())
                / f64::from(spec.tdi_stages);
            let (c, v_min) = curvatures
                .get(index)
                .copied()
                .flatten()
                .ok_or(Fault::InvalidScene)?
                .result()?;
            let c = CURVATURE_SAFETY * c;
            let width = f64::from(spec.last_px) - f64::from(spec.first_px);
            let error = |k: usize| interpolation_error(c, width, k);
            // Smallest K >= 2 with c (width / (K - 1))^2 / 8 <= budget x v_min.
            let mut k = if exhaustive { MAX_SAMPLES } else { 2usize };
            while k < MAX_SAMPLES && error(k) > budget * v_min {
                k += 1;
            }
            let spacing = width / (k - 1) as f64;
            let (first, last) = (f64::from(spec.first_px), f64::from(spec.last_px));
            let centre_px = spec.centre_px();
            // The centre, then the samples (the ends exact); an odd count's middle sample
            // is the centre.
            let pixels =
                core::iter::once(centre_px).chain((0..k).filter(|j| 2 * j + 1 != k).map(|j| {
                    if j + 1 == k {
                        last
                    } else {
                        first + spacing * j as f64
                    }
                }));
            let mut samples = Vec::new();
            #[cfg(feature = "earth-fixed")]
            let mut fixed = Vec::new();
            for n in pixels {
                // The boresight (p1 = p2 = 0, either zero's sign): compared as bits,
                // without the f64 comparison's software call.
                if (camera.p1_m.to_bits() | n.to_bits()) << 1 == 0 {
                    boresight_sample
                        .get_or_insert((self.segments.len() as u8, samples.len() as u8));
                }
                // Checked like any pixel: the row form then needs no check of its own.
                // (`focal_plane_m` alone checks the same but, inlined, costs more flash:
                // docs/target.md, flash.)
                GENERAL_F32
                    .pixel(&camera, n)
                    .map_err(|_| Fault::InvalidScene)?;
                let p2_m = (n * camera.pixel_m) as f32;
                samples
                    .push(Sample { px: n as f32, p2_m })
                    .map_err(|_| Fault::InvalidScene)?;
                #[cfg(feature = "earth-fixed")]
                fixed
                    .push(
                        core_math::EARTH_FIXED
                            .pixel(&camera, n)
                            .map_err(|_| Fault::InvalidScene)?,
                    )
                    .map_err(|_| Fault::InvalidScene)?;
            }
            let centre = GENERAL_F32
                .pixel(&camera, centre_px)
                .map_err(|_| Fault::InvalidScene)?;
            let segment = SegmentPlan {
                index: index as u8,
                tdi_stages: spec.tdi_stages,
                row: GENERAL_F32.row(&camera).map_err(|_| Fault::InvalidScene)?,
                samples,
                centre,
                #[cfg(feature = "earth-fixed")]
                fixed,
                sampling_budget: budget as f32,
                interpolation_mps: error(k) as f32,
                sampling_bound: (error(k) / v_min) as f32,
            };
            self.segments
                .push(segment)
                .map_err(|_| Fault::InvalidScene)?;
        }
        // The segment the boresight falls in, else the one nearest to it (`min_by_key`
        // keeps the first of equals: on a tie the lower index).
        let distance = |s: &SegmentSpec| {
            if s.first_px > 0 {
                i64::from(s.first_px)
            } else if s.last_px < 0 {
                -i64::from(s.last_px)
            } else {
                0
            }
        };
        let boresight_segment = scene
            .table()
            .iter()
            .enumerate()
            .min_by_key(|(_, s)| distance(s))
            .map_or(0, |(k, _)| k as u8);
        self.boresight = boresight;
        self.boresight_segment = boresight_segment;
        self.boresight_sample = boresight_sample;
        self.pixel_m = scene.camera.pixel_m as f32;
        self.line_clock_hz = scene.line_clock_hz as f32;
        self.stage_rule = stage_rule;
        self.max_stages = scene.max_stages;
        self.envelope = scene.envelope;
        self.period_bounds_s = period_bounds_s(scene, config);
        Ok(())
    }

    pub fn active(&self) -> &[SegmentPlan] {
        &self.segments
    }
}

/// The larger of `c` and |a - 2 b + d| / h^2, the second difference of three values h
/// pixels apart (per pixel^2).
// Out of line: the probe's loop over its seven windows was unrolled, a soft-float
// copy of this in each.
#[inline(never)]
fn max_second_difference(c: f64, [a, b, d]: [f64; 3], h: f64) -> f64 {
    c.max(libm::fabs(a - 2.0 * b + d) / (h * h))
}

/// Probe pixel `j` into `p`: `first_px + spacing_px j` of `camera`.
// Out of line: the probe loop was unrolled, each of its nine copies moving the pixel's
// result three times.
#[inline(never)]
fn probe_pixel(
    p: &mut GeneralPixel<f32>,
    camera: &core_math::EarthCamera,
    first_px: f64,
    spacing_px: f64,
    j: usize,
) -> Result<(), Fault> {
    *p = GENERAL_F32
        .pixel(camera, first_px + spacing_px * j as f64)
        .map_err(|_| Fault::InvalidScene)?;
    Ok(())
}

/// How far v1 may leave the samples' range between `k` samples equally spaced over
/// `width` pixels, with |v1''| at most `c` per pixel^2: c (width / (k - 1))^2 / 8.
// Out of line: the plan's search over k was unrolled, a copy of it for each k.
#[inline(never)]
fn interpolation_error(c: f64, width: f64, k: usize) -> f64 {
    let spacing = width / (k - 1) as f64;
    c * spacing * spacing / 8.0
}

/// Largest speed/circular-speed ratio squared a NAV state may have, |v|^2 |r| / mu:
/// 1.2 is an apogee-to-perigee ratio of about 1.5, far beyond any imaging orbit, and
/// bounds the speed the period guard must allow.
pub const MAX_SPEED2_RATIO: f64 = 1.2;
/// And the smallest.
pub const MIN_SPEED2_RATIO: f64 = 0.8;

/// The physically possible line periods (s) for `scene` over the configured orbits and
/// the scene's attitude envelope, from bounds on |v1| that hold for any attitude in the
/// envelope, any orbit position, the ellipsoid and any terrain:
/// - fastest: |v1| <= |g| sqrt(1 + t1^2) with |g| <= |W| |u| + |V| |u| / d, where
///   |W| <= nu + omega + 3 max_rate (orbit rate nu <= |v| / |r|), |V| <= |v| + omega |r|,
///   and d, the distance to any ground point, at least |r| - (a + 9 km);
/// - slowest: an attitude rate can cancel the image motion (the envelope's rates reach
///   the orbit's angular rate for any agile imager), so no bound holds from the
///   geometry: the longest period the line clock can count (u32::MAX ticks).
///
/// The bounds are proved against the reference over the envelope by the controller's
/// tests.
pub fn period_bounds_s(scene: &Scene, config: &Config) -> (f32, f32) {
    let mu = core_math::GM_M3_S2;
    let (h_lo, h_hi) = config.altitude_range_m;
    let r_min = EARTH.b_m() + h_lo;
    let r_max = EARTH.a_m + h_hi;
    let w = EARTH_RATE_RAD_S;
    let v_max = core_math::sqrt_f64(MAX_SPEED2_RATIO * mu / r_min);
    let nu_max = v_max / r_min;
    let rates = 3.0 * f64::from(scene.envelope.max_rate_rad_s);
    let d_min = r_min - (EARTH.a_m + f64::from(MAX_GROUND_H_M));
    let f = scene.camera.focal_m;
    // The largest |u| and |t1| over the segments' ends.
    let (mut u_max, mut t1_max) = (f, 0.0f64);
    for s in scene.table() {
        for n in [s.first_px, s.last_px] {
            let p1 = f64::from(s.p1_m);
            let p2 = f64::from(n) * scene.camera.pixel_m;
            u_max = u_max.max(core_math::sqrt_f64(p1 * p1 + p2 * p2 + f * f));
            t1_max = t1_max.max(libm::fabs(p1 / f));
        }
    }
    let g_max = (nu_max + w + rates) * u_max + (v_max + w * r_max) * u_max / d_min;
    let v_fast = g_max * core_math::sqrt_f64(1.0 + t1_max * t1_max);
    let fastest = scene.camera.pixel_m / v_fast;
    let slowest = f64::from(u32::MAX) / scene.line_clock_hz;
    (fastest as f32, slowest as f32)
}

//! The f64 reference of one controller update (feature `reference`): what the
//! controller's periods, drifts and yaw request should be, computed independently of the
//! f32 general form, for the host tools' reference check (`cargo xtask run`), the
//! on-target tests' golden values and the controller's tests.
//!
//! Independent means: the NAV state carried to the update instant by Kepler's equation
//! (`core_math::earth::kepler`, the exact two-body motion, where the controller uses a
//! Taylor series in f32 increments), the attitude at its rates in f64, and every image
//! motion from the literal construction on dual numbers (`EarthReference`). What is
//! shared is only the definition: the plan's sample pixels and the period of a segment
//! as the mean of the periods of its fastest and slowest sampled |v1|.

use core_math::earth::kepler::Kepler;
use core_math::earth::{Attitude, EarthCamera, EarthGeometry};
use core_math::{Backend, EarthReference, ModelError, StateVector, GM_M3_S2};

use crate::config::{EARTH, EARTH_RATE_RAD_S};
use crate::plan::Plan;
use crate::scene::{Scene, MAX_SEGMENTS};

/// The reference of one segment at one update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentGolden {
    pub index: u8,
    /// The line period in ticks of the line clock, before rounding to whole ticks.
    pub ticks_exact: f64,
    /// Smallest and largest |v1| over the plan's samples (m/s).
    pub v1_min_mps: f64,
    pub v1_max_mps: f64,
    /// atan(v2 / v1) at the segment's centre pixel (rad).
    pub drift_rad: f64,
}

/// The reference of one update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateGolden {
    /// One entry per active segment of the plan, in plan order.
    pub segments: [Option<SegmentGolden>; MAX_SEGMENTS],
    /// atan(v2 / v1) at the boresight (rad): the yaw steering request.
    pub yaw_request_rad: Option<f64>,
    /// The state and attitude at the update instant the reference used.
    pub state: StateVector,
    pub attitude: Attitude<f64>,
}

/// The NAV inputs of an update: the state and attitude of the frame, its time tag.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavInput {
    pub state: StateVector,
    pub attitude: Attitude<f32>,
    pub time_us: u64,
}

/// The reference of the update at `t_us` of a controller with `scene`, its `plan`, the
/// ground `heights_m` of the scene's table, and the NAV frame `nav` in force.
pub fn update(
    scene: &Scene,
    plan: &Plan,
    heights_m: &[f32],
    nav: &NavInput,
    t_us: u64,
) -> Result<UpdateGolden, ModelError> {
    let dt_s = (t_us as f64 - nav.time_us as f64) * 1e-6;
    let kepler = Kepler::new(nav.state.position_m, nav.state.velocity_mps, GM_M3_S2)
        .ok_or(ModelError::DegenerateState)?;
    let state = kepler.state_at(dt_s);
    let a = nav.attitude.to_f64();
    let attitude = Attitude {
        roll_rad: a.roll_rad + a.roll_rate_rad_s * dt_s,
        pitch_rad: a.pitch_rad + a.pitch_rate_rad_s * dt_s,
        yaw_rad: a.yaw_rad + a.yaw_rate_rad_s * dt_s,
        ..a
    };
    let geometry = |h_m: f32| EarthGeometry {
        state,
        attitude,
        ground_h_m: f64::from(h_m),
        ellipsoid: EARTH,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    };
    let height = |index: u8| heights_m.get(usize::from(index)).copied().unwrap_or(0.0);
    let mut segments = [None; MAX_SEGMENTS];
    for (slot, seg) in segments.iter_mut().zip(plan.active()) {
        let Some(spec) = scene.segments.get(usize::from(seg.index)) else {
            continue;
        };
        let camera = scene.earth_camera(spec);
        let g = geometry(height(seg.index));
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for n in seg.samples.iter().map(|s| s.px) {
            let m = EarthReference.evaluate(&camera, &g, f64::from(n))?;
            lo = lo.min(libm::fabs(m.v1_mps));
            hi = hi.max(libm::fabs(m.v1_mps));
        }
        let centre = EarthReference.evaluate(&camera, &g, spec.centre_px())?;
        let pixel_m = scene.camera.pixel_m;
        *slot = Some(SegmentGolden {
            index: seg.index,
            ticks_exact: 0.5 * (pixel_m / lo + pixel_m / hi) * scene.line_clock_hz,
            v1_min_mps: lo,
            v1_max_mps: hi,
            drift_rad: libm::atan(centre.v2_mps / centre.v1_mps),
        });
    }
    let boresight = EarthCamera {
        p1_m: 0.0,
        ..scene.earth_camera(&scene.segments[0])
    };
    let yaw_request_rad = EarthReference
        .evaluate(&boresight, &geometry(height(plan.boresight_segment)), 0.0)
        .ok()
        .map(|m| libm::atan(m.v2_mps / m.v1_mps));
    Ok(UpdateGolden {
        segments,
        yaw_request_rad,
        state,
        attitude,
    })
}

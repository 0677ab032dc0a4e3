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

use core_math::earth::bus::{
    bus_geometry, AttitudeFrame, BusAttitude, BusState, BusTime, StateFrame,
};
use core_math::earth::dem::DemTile;
use core_math::earth::frames::{self, TimeScales};
use core_math::earth::kepler::Kepler;
use core_math::earth::reference::EarthRefPixel;
use core_math::earth::{Attitude, EarthCamera, EarthGeometry, InertialAttitude, InertialGeometry};
use core_math::{Backend, EarthReference, ImageMotion, ModelError, StateVector, GM_M3_S2};

use crate::bus::{Gnss, StarAttitude};

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
    let evaluate =
        |camera: &EarthCamera, h_m: f32, n: f64| EarthReference.evaluate(camera, &geometry(h_m), n);
    let (segments, yaw_request_rad) = segments_of(scene, plan, heights_m, evaluate)?;
    Ok(UpdateGolden {
        segments,
        yaw_request_rad,
        state,
        attitude,
    })
}

/// The reference of one update on the bus's data (protocol version 4): the GNSS fix
/// `gnss` and the attitude `attitude` in force, the time scales `scales`, the update at
/// `t_us` (us of GPS time).
///
/// Independent of [`crate::track`]: the fix's state in I at its time (r, v + w x r)
/// carried by Kepler's equation, then into I at t by the full C2T at both instants
/// (`C2T(t) C2T(t_fix)^T`, each with its own precession-nutation series); the attitude
/// turned by its body rates as a quaternion product (q exp(w dt / 2)); the camera's
/// axes and Omega from core-math's `bus_geometry` (C2T(t) R(q) R(cam_q)); every image
/// motion from the construction on dual numbers (`EarthReference::motion_of`). Shared
/// with the controller: the definitions (Part II) and the plan's samples.
#[allow(clippy::too_many_arguments)]
pub fn bus_update(
    scene: &Scene,
    plan: &Plan,
    heights_m: &[f32],
    gnss: &Gnss,
    attitude: &StarAttitude,
    scales: &TimeScales,
    t_us: u64,
) -> Result<UpdateGolden, ModelError> {
    bus_update_on(scene, plan, heights_m, gnss, attitude, scales, t_us, None)
}

/// [`bus_update`] with the ground on a DEM `tile` (Part II, "The ground from a DEM"):
/// each pixel's ground point the tile's first crossing in f64
/// (`EarthReference::motion_on_dem`: `DemTile::first_crossing`, then the construction
/// on dual numbers), and the segment's height in `heights_m` where the tile does not
/// cover the pixel (`outside_dem`).
#[allow(clippy::too_many_arguments)]
pub fn bus_update_on_dem(
    scene: &Scene,
    plan: &Plan,
    heights_m: &[f32],
    gnss: &Gnss,
    attitude: &StarAttitude,
    scales: &TimeScales,
    t_us: u64,
    tile: &DemTile<'_, i16>,
) -> Result<UpdateGolden, ModelError> {
    bus_update_on(
        scene,
        plan,
        heights_m,
        gnss,
        attitude,
        scales,
        t_us,
        Some(tile),
    )
}

#[allow(clippy::too_many_arguments)]
fn bus_update_on(
    scene: &Scene,
    plan: &Plan,
    heights_m: &[f32],
    gnss: &Gnss,
    attitude: &StarAttitude,
    scales: &TimeScales,
    t_us: u64,
    tile: Option<&DemTile<'_, i16>>,
) -> Result<UpdateGolden, ModelError> {
    with_bus_motion(
        scene,
        gnss,
        attitude,
        scales,
        t_us,
        tile,
        |state, evaluate| {
            let (segments, yaw_request_rad) = segments_of(scene, plan, heights_m, evaluate)?;
            Ok(UpdateGolden {
                segments,
                yaw_request_rad,
                state,
                // The roll-pitch-yaw attitude is Part I's; the bus's is a quaternion.
                attitude: Attitude::default(),
            })
        },
    )
}

/// The smallest and largest |v1| (m/s) over the pixels of segment `index` from its
/// first to its last, every `step_px` and the last, on the bus's data at `t_us` with the
/// ground on `tile` (else, and where it does not cover a pixel, the segment's height in
/// `heights_m`): what the plan's samples and its interpolation bound stand for.
#[allow(clippy::too_many_arguments)]
pub fn bus_v1_span_on_dem(
    scene: &Scene,
    heights_m: &[f32],
    gnss: &Gnss,
    attitude: &StarAttitude,
    scales: &TimeScales,
    t_us: u64,
    tile: &DemTile<'_, i16>,
    index: u8,
    step_px: f64,
) -> Result<(f64, f64), ModelError> {
    let spec = scene
        .segments
        .get(usize::from(index))
        .ok_or(ModelError::DegenerateState)?;
    let camera = scene.earth_camera(spec);
    let h_m = heights_m.get(usize::from(index)).copied().unwrap_or(0.0);
    let (first, last) = (f64::from(spec.first_px), f64::from(spec.last_px));
    with_bus_motion(
        scene,
        gnss,
        attitude,
        scales,
        t_us,
        Some(tile),
        |_, evaluate| {
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            let mut n = first;
            loop {
                let v1 = libm::fabs(evaluate(&camera, h_m, n.min(last))?.v1_mps);
                (lo, hi) = (lo.min(v1), hi.max(v1));
                if n >= last {
                    return Ok((lo, hi));
                }
                n += step_px;
            }
        },
    )
}

/// The reference's image motion on the bus's data at `t_us`, handed to `then` with the
/// state there: `evaluate(camera, ground height, pixel)`, on `tile` where it covers the
/// pixel.
#[allow(clippy::too_many_arguments)]
fn with_bus_motion<R>(
    scene: &Scene,
    gnss: &Gnss,
    attitude: &StarAttitude,
    scales: &TimeScales,
    t_us: u64,
    tile: Option<&DemTile<'_, i16>>,
    then: impl FnOnce(
        StateVector,
        &dyn Fn(&EarthCamera, f32, f64) -> Result<ImageMotion<f64>, ModelError>,
    ) -> Result<R, ModelError>,
) -> Result<R, ModelError> {
    let secs = |us: u64| us as f64 * 1e-6;
    let t_s = secs(t_us);
    let (r, v, w) = (gnss.position_m, gnss.velocity_mps, EARTH_RATE_RAD_S);
    let v_i = [v[0] - w * r[1], v[1] + w * r[0], v[2]];
    let kepler = Kepler::new(r, v_i, GM_M3_S2).ok_or(ModelError::DegenerateState)?;
    let c2t_fix = frames::c2t(secs(gnss.fix_us), scales)?;
    // The state at `at_s` in I of that instant: Kepler from the fix, then
    // C2T(at) C2T(fix)^T.
    let state_at = |at_s: f64| -> Result<StateVector, ModelError> {
        let carried = kepler.state_at(at_s - secs(gnss.fix_us));
        let c2t = frames::c2t(at_s, scales)?;
        let m: [[f64; 3]; 3] = core::array::from_fn(|i| {
            core::array::from_fn(|j| (0..3).map(|k| c2t[i][k] * c2t_fix[j][k]).sum())
        });
        let to = |x: [f64; 3]| -> [f64; 3] {
            core::array::from_fn(|i| m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2])
        };
        Ok(StateVector {
            position_m: to(carried.position_m),
            velocity_mps: to(carried.velocity_mps),
        })
    };
    let state = state_at(t_s)?;
    let q = quaternion_at(attitude, t_s - secs(attitude.valid_us));
    let bus_attitude = BusAttitude {
        q,
        frame: AttitudeFrame::Gcrf,
        body_rate_rad_s: attitude.body_rate_rad_s.map(f64::from),
        camera_q: scene.mounting_q.map(f64::from),
    };
    let bus_state = BusState {
        frame: StateFrame::Inertial,
        position_m: state.position_m,
        velocity_mps: state.velocity_mps,
    };
    let time = BusTime {
        gps_s: Some(t_s),
        scales: *scales,
    };
    // The controller's carry model: roll, pitch and yaw relative to the orbital frame
    // keep their rates from the time of validity. Here exactly, through Part I's
    // attitude at both instants; the quaternion at its body rates where the angles are
    // degenerate.
    let valid_s = secs(attitude.valid_us);
    let at_valid = {
        let state_v = state_at(valid_s)?;
        let camera = bus_geometry(
            &BusState {
                position_m: state_v.position_m,
                velocity_mps: state_v.velocity_mps,
                ..bus_state
            },
            &BusAttitude {
                q: attitude.q.map(f64::from),
                ..bus_attitude
            },
            &BusTime {
                gps_s: Some(valid_s),
                scales: *scales,
            },
            0.0,
            EARTH,
            EARTH_RATE_RAD_S,
        )?;
        (state_v, camera.attitude)
    };
    let euler_carried = euler_carried(&at_valid.0, &at_valid.1, &state, t_s - valid_s);
    let geometry = |h_m: f32| -> Result<InertialGeometry<f64>, ModelError> {
        let g = bus_geometry(
            &bus_state,
            &bus_attitude,
            &time,
            f64::from(h_m),
            EARTH,
            EARTH_RATE_RAD_S,
        )?;
        Ok(InertialGeometry {
            attitude: euler_carried.unwrap_or(g.attitude),
            ..g
        })
    };
    let evaluate =
        |camera: &EarthCamera, h_m: f32, n: f64| -> Result<ImageMotion<f64>, ModelError> {
            let (p1_m, p2_m) = camera.focal_plane_m(n)?;
            let pixel = EarthRefPixel {
                p1_m,
                p2_m,
                focal_m: camera.focal_m,
            };
            let g = geometry(h_m)?;
            match tile.map(|t| EarthReference::motion_on_dem(&g, &pixel, t)) {
                None | Some(Err(ModelError::OutsideDem)) => EarthReference::motion_of(&g, &pixel),
                Some(found) => found,
            }
        };
    then(state, &evaluate)
}

/// The camera's axes and angular velocity `dt_s` after `at` (in I of that instant,
/// with the orbit's state `state_at` there), carried to `state` (in I of the later
/// instant) with its roll, pitch and yaw relative to the orbital frame at constant
/// rates: Part I's attitude (`EarthGeometry::to_inertial`) whose angles reproduce `at`'s
/// axes and whose rates its angular velocity, advanced by `dt_s`. `None` where the
/// angles are degenerate (pitch within 0.6 deg of +-90 deg).
fn euler_carried(
    state_at: &StateVector,
    at: &InertialAttitude<f64>,
    state: &StateVector,
    dt_s: f64,
) -> Option<InertialAttitude<f64>> {
    let (r, v) = (state_at.position_m, state_at.velocity_mps);
    let unit = |x: [f64; 3]| {
        let n = libm::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        x.map(|c| c / n)
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let (z_l, y_l) = (unit(r), unit(cross(r, v)));
    let frame = [cross(y_l, z_l), y_l, z_l];
    let m = &at.camera_to_inertial;
    // A = L^T M: the camera's axes in the orbital frame, A = Rx(roll) Ry(pitch) Rz(yaw).
    let a: [[f64; 3]; 3] = core::array::from_fn(|i| {
        core::array::from_fn(|j| (0..3).map(|k| frame[i][k] * m[k][j]).sum())
    });
    if libm::fabs(a[0][2]) > libm::cos(0.01) {
        return None;
    }
    let angles = Attitude {
        roll_rad: libm::atan2(-a[1][2], a[2][2]),
        pitch_rad: libm::asin(a[0][2]),
        yaw_rad: libm::atan2(-a[0][1], a[0][0]),
        ..Attitude::default()
    };
    let omega = |state: &StateVector, at: Attitude<f64>| {
        EarthGeometry {
            state: *state,
            attitude: at,
            ground_h_m: 0.0,
            ellipsoid: EARTH,
            earth_rate_rad_s: EARTH_RATE_RAD_S,
        }
        .to_inertial()
        .ok()
        .map(|g| g.attitude)
    };
    // Omega is affine in the three rates: its columns by unit rates, then solved.
    let w0 = omega(state_at, angles)?.omega_rad_s;
    let column = |k: usize| -> Option<[f64; 3]> {
        let unit = Attitude {
            roll_rate_rad_s: f64::from(u8::from(k == 0)),
            pitch_rate_rad_s: f64::from(u8::from(k == 1)),
            yaw_rate_rad_s: f64::from(u8::from(k == 2)),
            ..angles
        };
        let w = omega(state_at, unit)?.omega_rad_s;
        Some(core::array::from_fn(|i| w[i] - w0[i]))
    };
    let (c0, c1, c2) = (column(0)?, column(1)?, column(2)?);
    let b: [f64; 3] = core::array::from_fn(|i| at.omega_rad_s[i] - w0[i]);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let det = dot(c0, cross(c1, c2));
    let rates = [
        dot(b, cross(c1, c2)) / det,
        dot(c0, cross(b, c2)) / det,
        dot(c0, cross(c1, b)) / det,
    ];
    omega(
        state,
        Attitude {
            roll_rad: angles.roll_rad + rates[0] * dt_s,
            pitch_rad: angles.pitch_rad + rates[1] * dt_s,
            yaw_rad: angles.yaw_rad + rates[2] * dt_s,
            roll_rate_rad_s: rates[0],
            pitch_rate_rad_s: rates[1],
            yaw_rate_rad_s: rates[2],
        },
    )
}

/// The attitude quaternion `dt_s` after its validity, turned at its body rates:
/// q exp(w dt / 2) (body rates in body axes: the turn multiplies on the right).
fn quaternion_at(a: &StarAttitude, dt_s: f64) -> [f64; 4] {
    let q = a.q.map(f64::from);
    let w = a.body_rate_rad_s.map(f64::from);
    let rate = libm::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    let half = 0.5 * rate * dt_s;
    let (s, c) = (libm::sin(half), libm::cos(half));
    let e = if rate > 0.0 {
        [c, s * w[0] / rate, s * w[1] / rate, s * w[2] / rate]
    } else {
        [1.0, 0.0, 0.0, 0.0]
    };
    [
        q[0] * e[0] - q[1] * e[1] - q[2] * e[2] - q[3] * e[3],
        q[0] * e[1] + q[1] * e[0] + q[2] * e[3] - q[3] * e[2],
        q[0] * e[2] - q[1] * e[3] + q[2] * e[0] + q[3] * e[1],
        q[0] * e[3] + q[1] * e[2] - q[2] * e[1] + q[3] * e[0],
    ]
}

/// Every active segment's reference and the yaw request, from `evaluate(camera, ground
/// height, pixel)`: the one definition of a segment's period both references share.
#[allow(clippy::type_complexity)]
fn segments_of(
    scene: &Scene,
    plan: &Plan,
    heights_m: &[f32],
    evaluate: impl Fn(&EarthCamera, f32, f64) -> Result<ImageMotion<f64>, ModelError>,
) -> Result<([Option<SegmentGolden>; MAX_SEGMENTS], Option<f64>), ModelError> {
    let height = |index: u8| heights_m.get(usize::from(index)).copied().unwrap_or(0.0);
    let mut segments = [None; MAX_SEGMENTS];
    for (slot, seg) in segments.iter_mut().zip(plan.active()) {
        let Some(spec) = scene.segments.get(usize::from(seg.index)) else {
            continue;
        };
        let camera = scene.earth_camera(spec);
        let h_m = height(seg.index);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for n in seg.samples.iter().map(|s| s.px) {
            let m = evaluate(&camera, h_m, f64::from(n))?;
            lo = lo.min(libm::fabs(m.v1_mps));
            hi = hi.max(libm::fabs(m.v1_mps));
        }
        let centre = evaluate(&camera, h_m, spec.centre_px())?;
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
    let yaw_request_rad = evaluate(&boresight, height(plan.boresight_segment), 0.0)
        .ok()
        .map(|m| libm::atan(m.v2_mps / m.v1_mps));
    Ok((segments, yaw_request_rad))
}

//! The inputs of the on-target controller test, one source for both sides: `build.rs`
//! includes this file to compute each case's golden values with the f64 reference of an
//! update (`controller::golden`), and the target builds the same cases to run the
//! flight controller on them. Everything here is plain arithmetic on `libm` (pure Rust,
//! the same bits on the host and on the Cortex-M4), so both sides see identical inputs.

use controller::nav::Attitude;
use controller::Scene;
use core_math::{StateVector, GM_M3_S2};

/// One controller update to check: a scene, the NAV frame in force, optional ground
/// heights uploaded by a TERRAIN frame, and the update instant.
#[derive(Clone, Copy, Debug)]
pub struct ControllerCase {
    pub name: &'static str,
    pub scene: Scene,
    pub state: StateVector,
    pub attitude: Attitude<f32>,
    /// Heights (m) of a TERRAIN frame sent after the NAV frame, one per segment.
    pub terrain_m: Option<[f32; 10]>,
    /// Time tag of the NAV frame (us).
    pub nav_time_us: u64,
    /// The update instant (us): a multiple of the 20 ms update period.
    pub update_time_us: u64,
}

/// Number of cases: [`case`] gives each of 0..CASE_COUNT.
pub const CASE_COUNT: usize = 10;

/// ECI state of an orbit of semi-major axis `a_m` at inclination `incl_deg`, argument of
/// latitude `u_rad`, with the circular speed scaled by `speed_factor` (1.0006 gives
/// e ~ 0.0012: the point is then the perigee).
fn state(a_m: f64, incl_deg: f64, u_rad: f64, speed_factor: f64) -> StateVector {
    let speed = libm::sqrt(GM_M3_S2 / a_m) * speed_factor;
    let i = incl_deg * core::f64::consts::PI / 180.0;
    let (si, ci) = (libm::sin(i), libm::cos(i));
    let (su, cu) = (libm::sin(u_rad), libm::cos(u_rad));
    StateVector {
        position_m: [a_m * cu, a_m * su * ci, a_m * su * si],
        velocity_mps: [-speed * su, speed * cu * ci, speed * cu * si],
    }
}

fn deg(x: f32) -> f32 {
    x * (core::f32::consts::PI / 180.0)
}

/// The paper's camera as a staggered mosaic (alternate chips 3 mm ahead of and behind
/// the axis) over terrain given in the scene.
fn staggered() -> Scene {
    let mut scene = Scene::paper_default();
    for (k, s) in scene.segments.iter_mut().take(10).enumerate() {
        s.p1_m = if k % 2 == 0 { 3e-3 } else { -3e-3 };
        s.ground_h_m = 450.0 * k as f32;
    }
    scene
}

/// Case `k` of the list, or None past its end.
pub fn case(k: usize) -> Option<ControllerCase> {
    const A_645_M: f64 = 6_378_137.0 + 645e3;
    let nadir = Attitude::default();
    let agile = Attitude {
        roll_rad: deg(20.0),
        pitch_rad: deg(-10.0),
        yaw_rad: deg(3.0),
        roll_rate_rad_s: deg(0.5),
        pitch_rate_rad_s: deg(-0.2),
        yaw_rate_rad_s: deg(0.05),
    };
    // At the envelope's corner (25 deg, 1.5 deg/s), moving inwards so that a second
    // ahead it is still inside.
    let corner = Attitude {
        roll_rad: deg(-24.5),
        pitch_rad: deg(24.0),
        yaw_rad: deg(-6.0),
        roll_rate_rad_s: deg(1.5),
        pitch_rate_rad_s: deg(-1.0),
        yaw_rate_rad_s: deg(0.2),
    };
    let stereo = Attitude {
        pitch_rad: deg(20.0),
        yaw_rad: deg(4.0),
        ..nadir
    };
    let mountains: [f32; 10] = core::array::from_fn(|j| 9_000.0 - 950.0 * j as f32);
    let default = Scene::paper_default();
    let c = |name, scene, state, attitude, terrain_m, dt_us: u64| ControllerCase {
        name,
        scene,
        state,
        attitude,
        terrain_m,
        nav_time_us: 1_000_000,
        update_time_us: 1_000_000 + dt_us,
    };
    let circular = state(A_645_M, 97.98, 0.5, 1.0);
    let eccentric = state(A_645_M, 97.98, 2.1, 1.0006);
    Some(match k {
        0 => c(
            "nadir, circular, at the frame",
            default,
            circular,
            nadir,
            None,
            0,
        ),
        1 => c(
            "nadir, circular, 480 ms on",
            default,
            circular,
            nadir,
            None,
            480_000,
        ),
        2 => c(
            "agile, eccentric, 20 ms on",
            default,
            eccentric,
            agile,
            None,
            20_000,
        ),
        3 => c(
            "agile, eccentric, 900 ms on",
            default,
            eccentric,
            agile,
            None,
            900_000,
        ),
        4 => c(
            "stereo pitch 20 deg, staggered, scene terrain",
            staggered(),
            circular,
            stereo,
            None,
            240_000,
        ),
        5 => c(
            "agile, staggered, TERRAIN 9 km..450 m",
            staggered(),
            eccentric,
            agile,
            Some(mountains),
            500_000,
        ),
        6 => c(
            "envelope corner, eccentric",
            default,
            eccentric,
            corner,
            None,
            980_000,
        ),
        7 => c(
            "envelope corner, mountains",
            staggered(),
            circular,
            corner,
            Some(mountains),
            0,
        ),
        8 => c(
            "low orbit (520 km), agile",
            default,
            state(6_378_137.0 + 520e3, 97.4, -1.2, 1.0),
            agile,
            None,
            300_000,
        ),
        9 => c(
            "high orbit (780 km), polar, stereo",
            staggered(),
            state(6_378_137.0 + 780e3, 98.5, 1.45, 1.0003),
            stereo,
            None,
            700_000,
        ),
        _ => return None,
    })
}

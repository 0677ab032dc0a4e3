//! The attitude between the star tracker's frames (docs/controller.md, "The attitude
//! between frames"): the angular acceleration the controller carries, against the
//! derivative of Part I's angular velocity at constant roll, pitch and yaw rates; and
//! the blend of each quaternion with the gyros' propagation, against the exact attitude
//! of a camera flying such rates, with and without star-tracker noise.

mod common;

use common::bus::{
    angle_between, attitude_frame, gnss_frame, scales_frame, scene_frame, EulerBus, T0_US,
};
use common::{feed, H, I0};
use controller::track::euler_accel;
use controller::{AttitudeBlend, Config, Controller, Scene};
use core_math::earth::kepler::Kepler;
use core_math::earth::Attitude;
use core_math::sample::SplitMix64;
use core_math::{StateVector, GM_M3_S2};

/// One sigma per axis of a 4-arcsecond star tracker (rad).
const SIGMA_RAD: f64 = 2e-5;

fn gaussian(rng: &mut SplitMix64) -> f64 {
    let u1 = rng.uniform(f64::MIN_POSITIVE, 1.0);
    let u2 = rng.uniform(0.0, 1.0);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// The camera's angular velocity (camera axes) at `dt_s` after `state` and `attitude`,
/// the angles advanced at their rates and the orbit by Kepler's equation.
fn omega_at(state: &StateVector, attitude: &Attitude<f64>, dt_s: f64) -> [f64; 3] {
    let k = Kepler::new(state.position_m, state.velocity_mps, GM_M3_S2).unwrap();
    let advanced = Attitude {
        roll_rad: attitude.roll_rad + attitude.roll_rate_rad_s * dt_s,
        pitch_rad: attitude.pitch_rad + attitude.pitch_rate_rad_s * dt_s,
        yaw_rad: attitude.yaw_rad + attitude.yaw_rate_rad_s * dt_s,
        ..*attitude
    };
    EulerBus::geometry_of(k.state_at(dt_s), advanced)
        .attitude
        .omega_rad_s
}

/// `euler_accel` is dOmega/dt of Part I's attitude at constant rates: against the
/// central difference of `EarthGeometry::to_inertial`'s Omega over +-5 ms, on 2 000
/// random orbits (eccentricity up to 0.01) and attitudes (roll, pitch to 60 deg, any
/// yaw, rates to 0.05 rad/s).
#[test]
fn the_carried_acceleration_is_the_derivative_of_part_i_rates() {
    let mut rng = SplitMix64(0xACCE_1E2A_7E01);
    let mut worst = 0.0f64;
    let mut largest = 0.0f64;
    for _ in 0..2_000 {
        let u = rng.uniform(0.0, std::f64::consts::TAU);
        let mut state = common::state(I0.to_radians(), u, H + rng.uniform(-100e3, 200e3));
        let boost = 1.0 + rng.uniform(-0.005, 0.005);
        state.velocity_mps = state.velocity_mps.map(|v| v * boost);
        let rate = |rng: &mut SplitMix64| rng.uniform(-0.05, 0.05);
        let attitude = Attitude {
            roll_rad: rng.uniform(-60f64, 60.0).to_radians(),
            pitch_rad: rng.uniform(-60f64, 60.0).to_radians(),
            yaw_rad: rng.uniform(-180f64, 180.0).to_radians(),
            roll_rate_rad_s: rate(&mut rng),
            pitch_rate_rad_s: rate(&mut rng),
            yaw_rate_rad_s: rate(&mut rng),
        };
        let g = EulerBus::geometry_of(state, attitude);
        let f32s = |x: [f64; 3]| x.map(|c| c as f32);
        let alpha = euler_accel(
            &g.attitude.camera_to_inertial.map(f32s),
            f32s(g.attitude.omega_rad_s),
            f32s(state.position_m),
            f32s(state.velocity_mps),
        )
        .map(f64::from);
        let h = 5e-3;
        let (ahead, behind) = (
            omega_at(&state, &attitude, h),
            omega_at(&state, &attitude, -h),
        );
        for i in 0..3 {
            let numeric = (ahead[i] - behind[i]) / (2.0 * h);
            worst = worst.max((alpha[i] - numeric).abs());
            largest = largest.max(numeric.abs());
        }
    }
    eprintln!(
        "euler_accel: {worst:.2e} rad/s^2 off the central difference (largest {largest:.2e})"
    );
    // The difference's own error: h^2/6 of the third derivative (rates^3, 2e-8 here) and
    // the rounding of Omega (1e-17 / 1e-2); euler_accel's, its f32 inputs and arithmetic
    // (6e-8 relative, a few roundings deep).
    assert!(largest > 1e-3, "{largest}");
    assert!(worst <= 1e-6 * largest, "{worst:e}");
}

/// The roll slew of the default pass: 1 deg/s of roll while the yaw steers at 2e-3
/// rad/s, over a pitch of 5 deg, the camera mounted 20 mrad off the body's axes.
fn slew() -> EulerBus {
    let attitude = Attitude {
        roll_rad: 5f64.to_radians(),
        pitch_rad: 5f64.to_radians(),
        yaw_rad: 0.07,
        roll_rate_rad_s: 1f64.to_radians(),
        pitch_rate_rad_s: 0.0,
        yaw_rate_rad_s: 2e-3,
    };
    let (s, c) = 0.01f64.sin_cos();
    let n = 0.91f64.sqrt();
    let mounting_q = [c, s * 0.3 / n, s * 0.9 / n, s * 0.1 / n];
    EulerBus::new(common::state(I0.to_radians(), 0.9, H), attitude, mounting_q)
}

fn scene(bus: &EulerBus) -> Scene {
    let mut s = Scene::paper_default();
    s.mounting_q = bus.mounting_q.map(|x| x as f32);
    s
}

/// Plays 30 s of frames (GNSS at 1 Hz, ATTITUDE at 10 Hz with the error `error(k)` on
/// frame k) and returns, for each attitude frame after the first second, the angle
/// between the attitude in force and the exact one, and between the frame and the
/// exact one.
fn fly(bus: &EulerBus, config: Config, mut error: impl FnMut(u64) -> [f64; 3]) -> Vec<(f64, f64)> {
    let mut c = Controller::new(config, Scene::paper_default()).unwrap();
    feed(&mut c, &scene_frame(1, T0_US - 500_000, &scene(bus)));
    feed(&mut c, &scales_frame(2, T0_US - 400_000, 18, 0.125));
    let mut seq = 10u16;
    let mut out = Vec::new();
    for k in 0..300u64 {
        let valid = T0_US + k * 100_000;
        if k % 10 == 0 {
            let g = bus.bus.gnss(valid);
            feed(&mut c, &gnss_frame(seq, valid + 50_000, &g));
            seq += 1;
        }
        let a = bus.attitude(valid, error(k));
        feed(&mut c, &attitude_frame(seq, valid + 60_000, &a));
        seq += 1;
        assert_eq!(c.counters.total(), 0, "{:?}", c.last_fault);
        let taken = c.bus_attitude().unwrap().received;
        assert_eq!(taken.valid_us, valid);
        let (exact, _) = bus.exact(valid);
        if k >= 10 {
            out.push((
                angle_between(taken.q.map(f64::from), exact),
                angle_between(a.q.map(f64::from), exact),
            ));
        }
    }
    out
}

/// Without noise the gyros' propagation lands on each new quaternion: the attitude in
/// force is the frame's to the f32 rounding of the blend (each step rounds the estimate
/// to 6e-8, which the blend's memory of 16 frames lets wander), in a slew whose body
/// rates turn by 4e-5 rad/s^2 (a constant-rate propagation would be off by 2e-7 rad a
/// frame, and the blend would lag by 15 times that: 3e-6 rad at every frame).
#[test]
fn without_noise_the_blend_keeps_the_star_tracker_attitude() {
    let bus = slew();
    let flown = fly(&bus, Config::default(), |_| [0.0; 3]);
    let worst = flown.iter().map(|f| f.0).fold(0.0, f64::max);
    let rms = (flown.iter().map(|f| f.0 * f.0).sum::<f64>() / flown.len() as f64).sqrt();
    let rounding = flown.iter().map(|f| f.1).fold(0.0, f64::max);
    eprintln!(
        "no noise: in force {rms:.2e} rad RMS off, {worst:.2e} at most; the frames' f32 rounding {rounding:.2e}"
    );
    assert!(rms <= 1e-6, "{rms:e}");
    assert!(worst <= 1.5e-6, "{worst:e}");
}

/// With a star tracker's white noise (2e-5 rad per axis) the attitude in force is
/// within sqrt(gain / (2 - gain)) = 0.18 of the frames' error (RMS, 290 frames); taken
/// as it is (`AttitudeBlend::NONE`) it is the frames' error.
#[test]
fn the_blend_takes_the_star_tracker_noise_down() {
    let bus = slew();
    let rms = |v: &[(f64, f64)], k: usize| {
        let s: f64 = v
            .iter()
            .map(|x| if k == 0 { x.0 * x.0 } else { x.1 * x.1 })
            .sum();
        (s / v.len() as f64).sqrt()
    };
    let noisy = |seed: u64| {
        let mut rng = SplitMix64(seed);
        move |_| core::array::from_fn(|_| SIGMA_RAD * gaussian(&mut rng))
    };
    let blended = fly(&bus, Config::default(), noisy(0x57A7));
    let (in_force, frames) = (rms(&blended, 0), rms(&blended, 1));
    let none = Config {
        attitude_blend: AttitudeBlend::NONE,
        ..Config::default()
    };
    let raw = fly(&bus, none, noisy(0x57A7));
    eprintln!(
        "noise: frames {frames:.2e} rad RMS, in force {in_force:.2e} (ratio {:.3}); unblended {:.2e}",
        in_force / frames,
        rms(&raw, 0)
    );
    assert!(
        (frames / (SIGMA_RAD * 3f64.sqrt()) - 1.0).abs() < 0.15,
        "{frames:e}"
    );
    assert!(in_force <= 0.25 * frames, "{in_force:e} vs {frames:e}");
    assert!((rms(&raw, 0) / frames - 1.0).abs() < 1e-3);
}

/// A turn the gyros did not see (2 mrad from frame 100 on, beyond the 0.3 mrad gate)
/// is taken at once: the attitude in force is that frame's.
#[test]
fn a_turn_beyond_the_gate_is_taken_at_once() {
    let bus = slew();
    let step = |k: u64| if k >= 100 { [2e-3, 0.0, 0.0] } else { [0.0; 3] };
    let flown = fly(&bus, Config::default(), step);
    // Index k is frame k + 10.
    for f in &flown[80..90] {
        assert!(f.0 <= 1.5e-6, "{:e}", f.0);
    }
    assert!((flown[90].0 - 2e-3).abs() <= 2e-7, "{:e}", flown[90].0);
}

/// A reset keeps the blend's estimate (`Snapshot::attitude`): restored into a blank
/// controller at frame 150 of the noisy slew, then fed the same frames as the
/// controller that was not reset, its attitude in force stays within 1e-6 rad of that
/// one's (the seed carries the rates without their change, 2e-7 rad at the first frame,
/// and the blend forgets it at 15/16 a frame); without the seed the first frame is taken
/// as it came, 2e-5 rad of noise away.
#[test]
fn the_blend_goes_on_across_a_reset() {
    use controller::restart::Snapshot;
    let bus = slew();
    let mut rng = SplitMix64(0x5EED);
    let errors: Vec<[f64; 3]> = (0..200)
        .map(|_| core::array::from_fn(|_| SIGMA_RAD * gaussian(&mut rng)))
        .collect();
    let start = || {
        let mut c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
        feed(&mut c, &scene_frame(1, T0_US - 500_000, &scene(&bus)));
        feed(&mut c, &scales_frame(2, T0_US - 400_000, 18, 0.125));
        c
    };
    let frames = |k: u64, seq: u16| {
        let valid = T0_US + k * 100_000;
        let mut out = Vec::new();
        if k.is_multiple_of(10) {
            out.push(gnss_frame(seq, valid + 50_000, &bus.bus.gnss(valid)));
        }
        let a = bus.attitude(valid, errors[k as usize]);
        out.push(attitude_frame(seq + 1, valid + 60_000, &a));
        out
    };
    let run = |keep_seed: bool| -> f64 {
        let mut c = start();
        let mut restored: Option<Controller> = None;
        let mut worst = 0.0f64;
        for k in 0..200u64 {
            if k == 150 {
                let mut s = Snapshot::EMPTY;
                assert!(c.snapshot_inputs(&mut s) && c.snapshot_periods(&mut s.periods));
                if keep_seed {
                    assert!(c.snapshot_attitude(&mut s.attitude));
                    assert_ne!(s.attitude.len, 0);
                }
                let mut r = Controller::blank(Config::default());
                r.restore(&s, &mut common::Registers::default()).unwrap();
                restored = Some(r);
            }
            let seq = 10 + 2 * k as u16;
            for f in frames(k, seq) {
                feed(&mut c, &f);
                if let Some(r) = restored.as_mut() {
                    feed(r, &f);
                }
            }
            if let Some(r) = &restored {
                assert_eq!(r.counters.total(), 0, "{:?}", r.last_fault);
                let q = |c: &Controller| c.bus_attitude().unwrap().received.q.map(f64::from);
                worst = worst.max(angle_between(q(&c), q(r)));
            }
        }
        worst
    };
    let (kept, lost) = (run(true), run(false));
    eprintln!("across a reset: attitude in force {kept:.2e} rad from the run without it; without the seed {lost:.2e}");
    assert!(kept <= 1e-6, "{kept:e}");
    assert!(lost >= 5e-6, "{lost:e}");
}

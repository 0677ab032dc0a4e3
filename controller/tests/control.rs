//! The controller against independent computations: periods, drifts and the yaw
//! request from the f64 reference of the real-Earth model, every fault counted and
//! harmless, the period guard's bounds.

mod common;

use common::{feed, nav_frame, roll, state, Registers, H, I0};
use controller::frame::{encode, kind, MAX_FRAME};
use controller::golden;
use controller::nav::Attitude;
use controller::{Config, Controller, Fault, Mode, Scene, Terrain, EARTH};
use core_math::earth::EarthGeometry;
use core_math::{Backend, EarthReference};
use proptest::prelude::*;

/// An agile imaging scene: the paper's camera as a staggered mosaic (alternate chips
/// 3 mm ahead of and behind the axis), over mountains.
fn agile_scene() -> Scene {
    let mut scene = Scene::paper_default();
    for (k, s) in scene.segments.iter_mut().take(10).enumerate() {
        s.p1_m = if k % 2 == 0 { 3e-3 } else { -3e-3 };
        s.ground_h_m = 400.0 * k as f32;
    }
    scene
}

fn agile_attitude() -> Attitude<f32> {
    Attitude {
        roll_rad: 12f32.to_radians(),
        pitch_rad: -10f32.to_radians(),
        yaw_rad: 2.5f32.to_radians(),
        roll_rate_rad_s: 0.1f32.to_radians(),
        pitch_rate_rad_s: 0.05f32.to_radians(),
        yaw_rate_rad_s: -0.02f32.to_radians(),
    }
}

/// An eccentric orbit's state (e ~ 0.0012) at 645 km.
fn eccentric() -> core_math::StateVector {
    let mut s = state(I0.to_radians(), 0.5, H);
    for v in s.velocity_mps.iter_mut() {
        *v *= 1.0006;
    }
    s
}

fn terrain_frame(seq: u16, t_us: u64, heights: &[f32]) -> Vec<u8> {
    let t = Terrain {
        heights_m: std::array::from_fn(|k| heights.get(k).copied().unwrap_or(0.0)),
        count: heights.len() as u8,
    };
    let mut p = [0u8; 128];
    let n = t.encode(&mut p).unwrap();
    common::frame(kind::TERRAIN, seq, t_us, &p[..n])
}

/// Periods, drifts and the yaw request against the f64 reference of the same update
/// (`controller::golden`: Kepler propagation, the attitude at its rates in f64, the
/// dual-number construction), at the NAV instant and propagated up to 0.9 s: an
/// eccentric orbit, roll, pitch and yaw with their rates, a staggered mosaic, terrain
/// from the scene and then from a TERRAIN frame.
#[test]
fn periods_match_the_reference_and_follow_the_orbit_and_the_attitude() {
    against_the_reference(Config::default(), 1e-6);
}

/// The same with the sample pixels in fixed point (the Cortex-M3's controller): the
/// fixed-point backend's 2e-6 (docs/fixed-point.md, "The error bound") on top of the
/// f32 update's 1e-6.
#[cfg(feature = "earth-fixed")]
#[test]
fn fixed_point_pixels_match_the_reference() {
    let config = Config {
        fixed_point_pixels: true,
        ..Config::default()
    };
    against_the_reference(config, 3e-6);
}

/// Periods (within `rel_tol` of the reference plus the rounding to whole ticks), drifts
/// and the yaw request (2e-6 rad) against the reference, and the outputs' MTF and stage
/// limits against their rule.
fn against_the_reference(config: Config, rel_tol: f64) {
    let scene = agile_scene();
    let mut c = Controller::new(config, scene).unwrap();
    let mut regs = Registers::default();
    assert!(c.advance(0, &mut regs));
    assert_eq!(c.mode(), Mode::WaitingForNav);
    assert!(
        regs.writes.is_empty(),
        "nothing is written before the first NAV frame"
    );
    let nav = golden::NavInput {
        state: eccentric(),
        attitude: agile_attitude(),
        time_us: 1_000_000,
    };
    feed(&mut c, &nav_frame(1, nav.time_us, nav.state, nav.attitude));
    let heights: Vec<f32> = (0..10).map(|k| 8_000.0 - 750.0 * k as f32).collect();
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for (dt_us, terrain) in [
        (0u64, false),
        (200_000, false),
        (400_000, true),
        (900_000, true),
    ] {
        if terrain && c.heights_m()[0] == 0.0 {
            feed(&mut c, &terrain_frame(2, 1_300_000, &heights));
            assert_eq!(c.counters.total(), 0);
        }
        regs.writes.clear();
        let t = 1_000_000 + dt_us;
        assert!(c.advance(t, &mut regs));
        assert_eq!(c.mode(), Mode::Nominal);
        let g = golden::update(c.scene(), c.plan(), c.heights_m(), &nav, t).unwrap();
        assert_eq!(regs.writes.len(), 10);
        for (o, gold) in c.outputs().zip(g.segments.iter().flatten()) {
            assert_eq!(o.index, gold.index);
            let diff = (f64::from(o.ticks) - gold.ticks_exact).abs();
            assert!(
                diff <= rel_tol * gold.ticks_exact + 0.5,
                "segment {}: {} ticks vs {:.3}",
                o.index,
                o.ticks,
                gold.ticks_exact
            );
            let drift = (f64::from(o.drift_rad) - gold.drift_rad).abs();
            assert!(drift <= 2e-6, "segment {} drift off by {drift:e}", o.index);
            worst.0 = worst.0.max(diff / gold.ticks_exact);
            worst.1 = worst.1.max(drift);
        }
        let yaw = (f64::from(c.yaw_request_rad().unwrap()) - g.yaw_request_rad.unwrap()).abs();
        assert!(yaw <= 2e-6, "yaw request off by {yaw:e}");
        worst.2 = worst.2.max(yaw);
    }
    eprintln!(
        "controller vs reference: ticks {:.2e} relative (with the rounding to ticks), drift {:.2e} rad, yaw request {:.2e} rad",
        worst.0, worst.1, worst.2
    );
    // Outputs: MTF and stages are the combined rule's, recomputed here in f64.
    let floor = f64::from(c.scene().mtf_floor);
    for o in c.outputs() {
        // Pitched, the far segments' drift (the keystone: tan(pitch) tan(field)) smears
        // beyond the sinc's first zero: the contrast there is reversed and weak, and
        // the MTF is its modulus.
        assert!(
            !o.held && !o.reversed && (0.0..=1.0).contains(&o.mtf),
            "{o:?}"
        );
        let product = |m: u32| {
            let h = std::f64::consts::FRAC_PI_2 * f64::from(m);
            // Each factor the modulus |sin(x)/x| (docs/controller.md, "Per update").
            let s = |x: f64| {
                if x == 0.0 {
                    1.0
                } else {
                    (x.sin() / x).abs()
                }
            };
            s(h * f64::from(o.worst_mismatch)) * s(h * f64::from(o.worst_drift_rad).tan())
        };
        let m = u32::from(o.max_stages);
        assert!(
            product(m) >= floor - 1e-6,
            "stage limit {m} misses the floor"
        );
        assert!(
            m == 96 || product(m + 1) < floor + 1e-6,
            "stage limit {m} not the largest"
        );
        assert!(
            (product(16) - f64::from(o.mtf)).abs() < 1e-5,
            "MTF {} vs {}",
            o.mtf,
            product(16)
        );
        assert!(o.worst_drift_rad >= o.drift_rad.abs());
    }
}

/// The yaw steering request closes the loop: a NAV frame whose yaw follows the request
/// gives a drift at the boresight of zero (to f32's rounding), and each segment's
/// reported residual drift is the drift the steered attitude then shows there, computed
/// the other way (a whole update at the turned yaw, not the turned update).
#[test]
fn steering_the_yaw_as_requested_leaves_the_reported_residual_drift() {
    steering_leaves_the_residual(Config::default());
}

/// The same with fixed-point pixels (the Cortex-M3's controller): the residual from the
/// fixed-point update turned by the request (`EarthFixedUpdate::yawed`).
#[cfg(feature = "earth-fixed")]
#[test]
fn fixed_point_steering_leaves_the_reported_residual_drift() {
    steering_leaves_the_residual(Config {
        fixed_point_pixels: true,
        ..Config::default()
    });
}

fn steering_leaves_the_residual(config: Config) {
    let scene = agile_scene();
    let mut c = Controller::new(config, scene).unwrap();
    let mut regs = Registers::default();
    let mut att = agile_attitude();
    att.yaw_rate_rad_s = 0.0;
    att.roll_rate_rad_s = 0.0;
    att.pitch_rate_rad_s = 0.0;
    let s = eccentric();
    feed(&mut c, &nav_frame(1, 1_000_000, s, att));
    c.advance(1_000_000, &mut regs);
    let request = c.yaw_request_rad().unwrap();
    let residual: Vec<f32> = c.outputs().map(|o| o.residual_drift_rad).collect();
    let unsteered: Vec<f32> = c.outputs().map(|o| o.drift_rad).collect();
    eprintln!(
        "unsteered drifts {:?} mrad",
        unsteered
            .iter()
            .map(|r| (r * 1e4).round() / 10.0)
            .collect::<Vec<_>>()
    );
    att.yaw_rad += request;
    feed(&mut c, &nav_frame(2, 1_020_000, s, att));
    c.advance(1_020_000, &mut regs);
    assert!(
        c.yaw_request_rad().unwrap().abs() < 2e-6,
        "after steering the request is {}",
        c.yaw_request_rad().unwrap()
    );
    for (o, r) in c.outputs().zip(&residual) {
        assert!(
            (o.drift_rad - r).abs() < 3e-6,
            "segment {}: steered drift {} vs reported residual {r}",
            o.index,
            o.drift_rad
        );
    }
    eprintln!(
        "yaw request {:.3} mrad; residual drifts {:?} mrad",
        request * 1e3,
        residual
            .iter()
            .map(|r| (r * 1e4).round() / 10.0)
            .collect::<Vec<_>>()
    );
}

fn running_controller() -> (Controller, Registers) {
    let mut c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut regs = Registers::default();
    feed(
        &mut c,
        &nav_frame(1, 1_000_000, state(I0.to_radians(), 0.3, H), roll(0.2)),
    );
    c.advance(1_000_000, &mut regs);
    (c, regs)
}

fn outputs(c: &Controller) -> Vec<u32> {
    c.outputs().map(|o| o.ticks).collect()
}

#[test]
fn every_fault_is_counted_and_changes_nothing() {
    let (mut c, _) = running_controller();
    let before = outputs(&c);
    let nav_before = *c.nav().unwrap();
    let good = state(I0.to_radians(), 0.31, H);
    let mut nan = good;
    nan.velocity_mps[1] = f64::NAN;
    let low = state(I0.to_radians(), 0.31, 100e3);
    let mut fast = good;
    fast.velocity_mps = fast.velocity_mps.map(|v| v * 1.2);
    let cases: Vec<(Vec<u8>, Fault)> = vec![
        (
            nav_frame(2, 900_000, good, roll(0.2)),
            Fault::TimeWentBackwards,
        ),
        (nav_frame(3, 1_100_000, nan, roll(0.2)), Fault::NonFinite),
        (nav_frame(4, 1_150_000, low, roll(0.2)), Fault::OutOfRange),
        (
            nav_frame(
                5,
                1_200_000,
                good,
                Attitude {
                    pitch_rad: 0.6,
                    ..roll(0.2)
                },
            ),
            Fault::AttitudeOutsideModel,
        ),
        (
            nav_frame(
                6,
                1_250_000,
                good,
                Attitude {
                    yaw_rate_rad_s: 0.1,
                    ..roll(0.2)
                },
            ),
            Fault::AttitudeOutsideModel,
        ),
        (
            nav_frame(7, 1_300_000, good, roll(0.9)),
            Fault::AttitudeOutsideModel,
        ),
        // Issue 12: 24 deg of roll at 0.5 rad/s would be 52 deg a second later.
        (
            nav_frame(
                71,
                1_310_000,
                good,
                Attitude {
                    roll_rate_rad_s: 0.5,
                    ..roll(24f32.to_radians())
                },
            ),
            Fault::AttitudeOutsideModel,
        ),
        // Inside the envelope now, outside it 0.7 s later (30 deg at 1 s).
        (
            nav_frame(
                72,
                1_320_000,
                good,
                Attitude {
                    pitch_rate_rad_s: 1.2f32.to_radians(),
                    pitch_rad: 29.3f32.to_radians(),
                    ..roll(0.2)
                },
            ),
            Fault::AttitudeOutsideModel,
        ),
        (nav_frame(73, 1_330_000, fast, roll(0.2)), Fault::OutOfRange),
        (
            terrain_frame(74, 1_340_000, &[9_500.0; 10]),
            Fault::OutOfRange,
        ),
        (
            terrain_frame(75, 1_345_000, &[f32::NAN; 10]),
            Fault::NonFinite,
        ),
        (
            terrain_frame(76, 1_346_000, &[100.0; 9]),
            Fault::InvalidScene,
        ),
        (
            nav_frame(
                8,
                1_350_000,
                good,
                Attitude {
                    roll_rad: f32::NAN,
                    ..Attitude::default()
                },
            ),
            Fault::NonFinite,
        ),
        (
            {
                let mut f = nav_frame(9, 1_400_000, good, roll(0.2));
                f[20] ^= 1;
                f
            },
            Fault::BadCrc,
        ),
        (
            {
                let mut buf = [0u8; MAX_FRAME];
                let n = encode(kind::NAV, 10, 1_450_000, &[1, 2, 3], &mut buf).unwrap();
                buf[..n].to_vec()
            },
            Fault::BadLength,
        ),
        (
            {
                let mut buf = [0u8; MAX_FRAME];
                let n = encode(0x7F, 11, 1_500_000, &[], &mut buf).unwrap();
                buf[..n].to_vec()
            },
            Fault::UnknownKind,
        ),
    ];
    let mut regs = Registers::default();
    for (bytes, fault) in cases {
        let n = c.counters.get(fault);
        feed(&mut c, &bytes);
        assert_eq!(c.counters.get(fault), n + 1, "{fault:?} not counted");
        assert_eq!(*c.nav().unwrap(), nav_before, "{fault:?} changed the state");
        assert_eq!(c.heights_m(), &[0.0; 10], "{fault:?} changed the terrain");
        c.advance(1_000_000, &mut regs);
        assert_eq!(outputs(&c), before, "{fault:?} changed the outputs");
    }
}

#[test]
fn stale_telemetry_holds_the_last_periods_and_is_reported_once() {
    let (mut c, mut regs) = running_controller();
    // The frame (1 s) serves updates up to 2 s; from 2.02 s on it is stale.
    let mut before = outputs(&c);
    for t in (1_020_000..4_000_000).step_by(20_000) {
        c.advance(t, &mut regs);
        if t <= 2_000_000 {
            before = outputs(&c);
        }
    }
    assert_eq!(c.mode(), Mode::Stale);
    assert_eq!(c.counters.get(Fault::Stale), 1);
    assert_eq!(outputs(&c), before);
    assert!(c.outputs().all(|o| o.held));
    // Recovery with a fresh frame.
    feed(
        &mut c,
        &nav_frame(2, 4_000_000, state(I0.to_radians(), 0.5, H), roll(0.2)),
    );
    c.advance(4_000_000, &mut regs);
    assert_eq!(c.mode(), Mode::Nominal);
    assert!(c.outputs().all(|o| !o.held));
}

#[test]
fn a_segment_beyond_the_limb_keeps_its_last_period_and_the_others_go_on() {
    let mut scene = Scene::paper_default();
    scene.envelope.max_roll_rad = 1.0;
    let mut c = Controller::new(Config::default(), scene).unwrap();
    let mut regs = Registers::default();
    feed(
        &mut c,
        &nav_frame(1, 1_000_000, state(I0.to_radians(), 0.3, H), roll(0.4)),
    );
    c.advance(1_000_000, &mut regs);
    let before: Vec<_> = c.outputs().copied().collect();
    assert_eq!(before.len(), 10);
    // Roll 55 deg: the far segments (field up to +17 deg) look past the limb (64 deg).
    feed(
        &mut c,
        &nav_frame(
            2,
            1_250_000,
            state(I0.to_radians(), 0.3, H),
            roll(55f32.to_radians()),
        ),
    );
    regs.writes.clear();
    c.advance(1_250_000, &mut regs);
    assert!(c.counters.get(Fault::BeyondLimb) >= 1);
    let after: Vec<_> = c.outputs().copied().collect();
    let written: Vec<u8> = regs.writes.iter().map(|w| w.0).collect();
    for (b, a) in before.iter().zip(&after) {
        if written.contains(&a.index) {
            assert!(!a.held);
        } else {
            assert!(
                a.held && a.ticks == b.ticks,
                "segment {} changed while faulted",
                a.index
            );
        }
    }
    assert!(written.contains(&0), "the near segments still update");
}

#[test]
fn scene_upload_replaces_the_plan() {
    let (mut c, mut regs) = running_controller();
    let mut scene = Scene::paper_default();
    scene.count = 4;
    scene.segments[1].active = false;
    let mut payload = [0u8; 400];
    let n = scene.encode(&mut payload).unwrap();
    let mut buf = [0u8; MAX_FRAME];
    let len = encode(kind::SCENE, 2, 1_010_000, &payload[..n], &mut buf).unwrap();
    feed(&mut c, &buf[..len]);
    assert_eq!(c.counters.total(), 0);
    assert_eq!(
        c.plan().active().len(),
        3,
        "inactive segments are not planned"
    );
    regs.writes.clear();
    c.advance(1_050_000, &mut regs);
    let idx: Vec<u8> = regs.writes.iter().map(|w| w.0).collect();
    assert_eq!(idx, vec![0, 2, 3]);
    // A bad scene is refused and the plan in force stays.
    scene.mtf_floor = 1.5;
    let n = scene.encode(&mut payload).unwrap();
    let len = encode(kind::SCENE, 3, 1_020_000, &payload[..n], &mut buf).unwrap();
    feed(&mut c, &buf[..len]);
    assert_eq!(c.counters.get(Fault::InvalidScene), 1);
    assert_eq!(c.plan().active().len(), 3);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    /// The period guard never refuses a physically possible period: the reference's
    /// pixel / |v1| over the envelope (any orbit position and inclination, altitude in
    /// the configured band, eccentric, attitude and rates within the scene's envelope,
    /// any yaw, any terrain, any pixel of the staggered mosaic) lies inside it.
    #[test]
    fn period_bounds_hold_over_the_envelope(
        h in 500e3f64..800e3, i0 in 0f64..180.0, u in 0f64..360.0, speed in 0.95f64..1.05,
        angles in proptest::array::uniform3(-1f64..1.0), rates in proptest::array::uniform3(-1f64..1.0),
        yaw in -3.2f64..3.2, ground in -500f64..9_000.0, k in 0usize..10, n in 0i32..6_000,
    ) {
        let scene = agile_scene();
        let (lo, hi) = c_bounds(&scene);
        let mut sv = state(i0.to_radians(), u.to_radians(), h);
        sv.velocity_mps = sv.velocity_mps.map(|v| v * speed);
        let e = scene.envelope;
        let rate = f64::from(e.max_rate_rad_s);
        let g = EarthGeometry {
            state: sv,
            attitude: Attitude {
                roll_rad: f64::from(e.max_roll_rad) * angles[0],
                pitch_rad: f64::from(e.max_pitch_rad) * angles[1],
                yaw_rad: yaw,
                roll_rate_rad_s: rate * rates[0],
                pitch_rate_rad_s: rate * rates[1],
                yaw_rate_rad_s: rate * rates[2],
            },
            ground_h_m: ground,
            ellipsoid: EARTH,
            earth_rate_rad_s: core_math::EARTH_RATE_RAD_S,
        };
        let spec = scene.segments[k];
        let camera = scene.earth_camera(&spec);
        if let Ok(m) = EarthReference.evaluate(&camera, &g, f64::from(spec.first_px + n)) {
            let t = camera.pixel_m / m.v1_mps.abs();
            prop_assert!(t >= f64::from(lo) && t <= f64::from(hi), "{t} outside [{lo}, {hi}]");
        }
    }
}

fn c_bounds(scene: &Scene) -> (f32, f32) {
    controller::plan::period_bounds_s(scene, &Config::default())
}

#[test]
fn periods_and_status_frames_round_trip() {
    let (mut c, _) = running_controller();
    c.reject(Fault::BadCrc);
    let mut buf = [0u8; 600];
    let n = controller::report::encode_periods(&c, &mut buf).unwrap();
    let p = controller::report::Periods::decode(&buf[..n]).unwrap();
    assert_eq!(p.mode, Mode::Nominal as u8);
    let mine: Vec<_> = c.outputs().copied().collect();
    assert_eq!(p.records(), &mine[..]);
    let n = controller::report::encode_status(&c, 7, 3, &mut buf).unwrap();
    assert_eq!(n, controller::report::STATUS_LEN);
    let s = controller::report::Status::decode(&buf[..n]).unwrap();
    assert_eq!(s.downlink_dropped, 3);
    assert_eq!(s.count(Fault::BadCrc), 1);
    assert_eq!(s.last_fault, Some(Fault::BadCrc));
    assert_eq!(s.skipped_bytes, 7);
    assert_eq!(s.frames_accepted, c.frames_accepted);
}

#[test]
fn time_tags_at_the_end_of_the_clock_do_not_wrap_the_schedule() {
    let mut c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut regs = Registers::default();
    // The largest tag the clock takes is accepted even as the first one.
    let t = controller::config::MAX_TIME_TAG_US;
    feed(
        &mut c,
        &nav_frame(1, t, state(I0.to_radians(), 0.3, H), roll(0.2)),
    );
    assert_eq!(c.nav().map(|n| n.time_us), Some(t));
    assert!(c.advance(t, &mut regs));
    assert_eq!(c.last_update_us(), Some(t - t % 20_000));
    assert!(!c.advance(t, &mut regs));
    // A time source beyond it does not move the clock past it.
    c.advance(u64::MAX, &mut regs);
    assert_eq!(c.now_us(), t);
}

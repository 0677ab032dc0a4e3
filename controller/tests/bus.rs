//! The controller on the satellite bus's own frames (protocol version 4): GNSS fixes in
//! the ITRF at 1 Hz, star-tracker quaternions relative to the GCRF with gyro rates at
//! 10 Hz, the time scales, a camera mounted off the body's axes; against the f64
//! reference of the same inputs (`controller::golden::bus_update`: Kepler, the full
//! C2T at each instant, the quaternion turned exactly, the dual-number construction),
//! and every typed fault of the bus frames injected into a twin without changing any
//! output.

mod common;

use common::bus::{attitude_frame, gnss_frame, scales_frame, scene_frame, Bus, SCALES, T0_US};
use common::{feed, frame, periods, Registers, H, I0};
use controller::bus::{Gnss, StarAttitude};
use controller::frame::kind;
use controller::{golden, Config, Controller, Fault, Mode, Scene};
use core_math::earth::frames::Mat3;
use core_math::earth::{Attitude, EarthGeometry};
use core_math::{StateVector, EARTH_RATE_RAD_S};

const WGS84: core_math::Ellipsoid = core_math::Ellipsoid::WGS84;

/// The orbit in I at T0 (the ITRF frozen then).
fn orbit_t0() -> StateVector {
    common::state(I0.to_radians(), 0.9, H + 7_000.0)
}

fn rotation_of(q: [f64; 4]) -> Mat3 {
    core_math::earth::bus::quaternion_matrix(q, core_math::Param::Quaternion).unwrap()
}

/// The mounting: the camera turned 30 mrad about (0.3, 0.9, 0.1) on the body.
fn mounting() -> [f64; 4] {
    let axis = [0.3f64, 0.9, 0.1];
    let n = (axis.iter().map(|x| x * x).sum::<f64>()).sqrt();
    let (s, c) = (0.015f64.sin(), 0.015f64.cos());
    [c, s * axis[0] / n, s * axis[1] / n, s * axis[2] / n]
}

fn scene() -> Scene {
    let mut s = Scene::paper_default();
    s.mounting_q = mounting().map(|x| x as f32);
    for (k, seg) in s.segments.iter_mut().take(10).enumerate() {
        seg.ground_h_m = 300.0 * k as f32;
    }
    s
}

/// What the bus sends: the truth is a Kepler orbit in I at T0 and a camera rolled 12
/// deg, pitched 5 deg, yawed 3 deg relative to the orbital frame at T0, then turning at
/// constant body rates (a roll and pitch slew over the orbit rate).
fn bus() -> Bus {
    let g = EarthGeometry {
        state: orbit_t0(),
        attitude: Attitude {
            roll_rad: 12f64.to_radians(),
            pitch_rad: 5f64.to_radians(),
            yaw_rad: 3f64.to_radians(),
            roll_rate_rad_s: 0.0,
            pitch_rate_rad_s: 0.0,
            yaw_rate_rad_s: 0.0,
        },
        ground_h_m: 0.0,
        ellipsoid: WGS84,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    }
    .to_inertial()
    .unwrap();
    let cam = rotation_of(mounting());
    Bus::new(g, &cam, [0.012, -0.006, 0.002], T0_US + 70_000)
}

/// One event of the clean stream: a frame at its tag, or an update instant.
enum Step {
    Frame(u64, Vec<u8>, Option<Gnss>, Option<StarAttitude>),
    Update(u64),
}

/// 3.2 s of bus data: the time scales, GNSS at 1 Hz (tagged 80 ms after the fix),
/// attitude at 10 Hz (tagged 20 ms after validity), updates every 20 ms.
fn clean_stream(bus: &Bus) -> Vec<Step> {
    let mut steps = vec![
        Step::Frame(
            T0_US - 500_000,
            scene_frame(1, T0_US - 500_000, &scene()),
            None,
            None,
        ),
        Step::Frame(
            T0_US - 400_000,
            scales_frame(2, T0_US - 400_000, 18, 0.125),
            None,
            None,
        ),
    ];
    let mut frames: Vec<Step> = Vec::new();
    for k in 0..4u64 {
        let g = bus.gnss(T0_US + k * 1_000_000);
        let tag = g.fix_us + 80_000;
        frames.push(Step::Frame(
            tag,
            gnss_frame(10 + k as u16, tag, &g),
            Some(g),
            None,
        ));
    }
    for j in 0..32u64 {
        let a = bus.attitude(bus.valid0_us + j * 100_000);
        let tag = a.valid_us + 20_000;
        frames.push(Step::Frame(
            tag,
            attitude_frame(100 + j as u16, tag, &a),
            None,
            Some(a),
        ));
    }
    let mut updates: Vec<u64> = (0..160u64).map(|k| T0_US + 100_000 + k * 20_000).collect();
    let tag = |s: &Step| match s {
        Step::Frame(t, ..) | Step::Update(t) => *t,
    };
    frames.sort_by_key(tag);
    let mut fi = frames.into_iter().peekable();
    for t in updates.drain(..) {
        while let Some(f) = fi.next_if(|f| tag(f) <= t) {
            steps.push(f);
        }
        steps.push(Step::Update(t));
    }
    steps
}

#[test]
fn bus_periods_match_the_reference_of_the_same_itrf_state_quaternion_and_time() {
    let bus = bus();
    let mut c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut regs = Registers::default();
    let (mut gnss, mut att) = (None, None);
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    let mut checked = 0;
    for step in clean_stream(&bus) {
        match step {
            Step::Frame(_, bytes, g, a) => {
                feed(&mut c, &bytes);
                assert_eq!(
                    c.counters.total(),
                    0,
                    "{:?} kind {}",
                    c.last_fault,
                    bytes[3]
                );
                gnss = g.or(gnss);
                att = a.or(att);
            }
            Step::Update(t) => {
                regs.writes.clear();
                assert!(c.advance(t, &mut regs));
                let (Some(g), Some(a)) = (gnss, att) else {
                    assert_eq!(c.mode(), Mode::WaitingForNav);
                    assert!(regs.writes.is_empty());
                    continue;
                };
                assert_eq!(c.mode(), Mode::Nominal);
                assert_eq!(c.time_scales(), &SCALES);
                // The attitude in force: the quaternion as blended with the gyros'
                // propagation (`tests/attitude_blend.rs` holds the blend to its own truth).
                let a = c.bus_attitude().map_or(a, |s| s.received);
                let gold =
                    golden::bus_update(c.scene(), c.plan(), c.heights_m(), &g, &a, &SCALES, t)
                        .unwrap();
                assert_eq!(regs.writes.len(), 10);
                for (o, gs) in c.outputs().zip(gold.segments.iter().flatten()) {
                    assert_eq!(o.index, gs.index);
                    assert!(!o.held);
                    let diff = (f64::from(o.ticks) - gs.ticks_exact).abs();
                    assert!(
                        diff <= 1e-6 * gs.ticks_exact + 0.5,
                        "t {t}: segment {}: {} ticks vs {:.3}",
                        o.index,
                        o.ticks,
                        gs.ticks_exact
                    );
                    let drift = (f64::from(o.drift_rad) - gs.drift_rad).abs();
                    assert!(drift <= 2e-6, "segment {} drift off by {drift:e}", o.index);
                    worst.0 = worst.0.max(diff / gs.ticks_exact);
                    worst.1 = worst.1.max(drift);
                }
                let yaw =
                    (f64::from(c.yaw_request_rad().unwrap()) - gold.yaw_request_rad.unwrap()).abs();
                assert!(yaw <= 2e-6, "yaw request off by {yaw:e}");
                worst.2 = worst.2.max(yaw);
                checked += 1;
            }
        }
    }
    assert!(checked >= 150, "{checked} updates checked");
    eprintln!(
        "bus frames vs reference over {checked} updates: ticks {:.2e} relative (with the \
         rounding to ticks), drift {:.2e} rad, yaw request {:.2e} rad",
        worst.0, worst.1, worst.2
    );
}

/// The same stream with every typed fault of the bus frames injected between its
/// frames: each is counted under its own fault, and no output differs from the clean
/// run's (every PERIODS frame and every register write).
#[test]
fn every_bus_fault_changes_no_output() {
    let bus = bus();
    let mut clean = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut faulty = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let (mut clean_regs, mut faulty_regs) = (Registers::default(), Registers::default());
    let mut last_tag = 0u64;
    let mut expected: Vec<Fault> = Vec::new();
    let mut injected = 0usize;
    let mut last_valid_us = 0u64;
    for step in clean_stream(&bus) {
        match step {
            Step::Frame(tag, bytes, _, a) => {
                feed(&mut clean, &bytes);
                feed(&mut faulty, &bytes);
                last_tag = tag;
                if let Some(a) = a {
                    last_valid_us = a.valid_us;
                }
            }
            Step::Update(t) => {
                // One faulty frame after the stream's first second, tagged between
                // the last frame and this update.
                if t > T0_US + 1_000_000 && injected < 16 {
                    let tag = last_tag + 1;
                    let (bytes, fault) = bad_frame(&bus, injected, tag, last_valid_us);
                    feed(&mut faulty, &bytes);
                    expected.push(fault);
                    assert_eq!(faulty.last_fault, Some(fault), "injection {injected}");
                    injected += 1;
                }
                assert_eq!(
                    clean.advance(t, &mut clean_regs),
                    faulty.advance(t, &mut faulty_regs)
                );
                assert_eq!(periods(&clean), periods(&faulty), "t {t}");
            }
        }
    }
    assert_eq!(injected, 16);
    assert_eq!(clean.counters.total(), 0);
    assert_eq!(clean_regs.writes, faulty_regs.writes);
    for f in Fault::ALL {
        let want = expected.iter().filter(|e| **e == f).count() as u32;
        assert_eq!(faulty.counters.get(f), want, "{}", f.name());
    }
    for f in [
        Fault::BadQuaternion,
        Fault::FixTime,
        Fault::TimeScales,
        Fault::NonFinite,
        Fault::AttitudeOutsideModel,
        Fault::OutOfRange,
    ] {
        assert!(faulty.counters.get(f) > 0, "{} never injected", f.name());
    }
    assert_eq!(clean.mode(), Mode::Nominal);
}

/// The `k`-th faulty frame, tagged `tag_us`, and the fault it must be refused with.
fn bad_frame(bus: &Bus, k: usize, tag_us: u64, last_valid_us: u64) -> (Vec<u8>, Fault) {
    let seq = 900 + k as u16;
    let good_att = bus.attitude(tag_us - 10_000);
    let good_gnss = bus.gnss(tag_us - 50_000);
    let att = |a: StarAttitude| attitude_frame(seq, tag_us, &a);
    let gnss = |g: Gnss| gnss_frame(seq, tag_us, &g);
    match k {
        0 => (
            att(StarAttitude {
                q: good_att.q.map(|x| x * 1.0015),
                ..good_att
            }),
            Fault::BadQuaternion,
        ),
        1 => (
            att(StarAttitude {
                body_rate_rad_s: [0.05, 0.0, 0.0],
                ..good_att
            }),
            Fault::AttitudeOutsideModel,
        ),
        2 => (
            att(StarAttitude {
                valid_us: tag_us + 1,
                ..good_att
            }),
            Fault::FixTime,
        ),
        3 => (
            att(StarAttitude {
                valid_us: last_valid_us,
                ..good_att
            }),
            Fault::FixTime,
        ),
        4 => (
            gnss(Gnss {
                fix_us: tag_us - 2_000_001,
                ..good_gnss
            }),
            Fault::FixTime,
        ),
        5 => (
            gnss(Gnss {
                fix_us: tag_us + 10,
                ..good_gnss
            }),
            Fault::FixTime,
        ),
        6 => (scales_frame(seq, tag_us, 61, 0.1), Fault::TimeScales),
        7 => (scales_frame(seq, tag_us, -1, 0.1), Fault::TimeScales),
        8 => (scales_frame(seq, tag_us, 18, 0.95), Fault::TimeScales),
        9 => (scales_frame(seq, tag_us, 18, f32::NAN), Fault::NonFinite),
        10 => {
            let mut g = good_gnss;
            g.position_m[1] = f64::NAN;
            (gnss(g), Fault::NonFinite)
        }
        11 => {
            let mut a = good_att;
            a.q[2] = f32::INFINITY;
            (att(a), Fault::NonFinite)
        }
        12 => {
            let mut g = good_gnss;
            g.position_m = g.position_m.map(|x| x * 0.93);
            (gnss(g), Fault::OutOfRange)
        }
        13 => {
            let mut s = scene();
            s.mounting_q = s.mounting_q.map(|x| x * 1.01);
            (scene_frame(seq, tag_us, &s), Fault::BadQuaternion)
        }
        14 => (
            att(StarAttitude {
                body_rate_rad_s: [0.0, 0.0, f32::NAN],
                ..good_att
            }),
            Fault::NonFinite,
        ),
        _ => (
            frame(kind::TIME_SCALES, seq, tag_us, &[18, 0, 0, 0]),
            Fault::BadLength,
        ),
    }
}

/// The bus's data go stale as NAV does, each by its own limit: an attitude more than
/// `stale_after` (1 s) old holds every period and counts one `stale`; a fresh attitude
/// brings the updates back while the fix is within `gnss_stale_after` (2 s); a NAV
/// frame then replaces the bus's data, and a GNSS frame the NAV state.
#[test]
fn bus_data_go_stale_by_their_own_limits_and_one_source_replaces_the_other() {
    let bus = bus();
    let mut c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut regs = Registers::default();
    let mut last_valid_us = 0;
    for step in clean_stream(&bus) {
        match step {
            Step::Frame(_, bytes, _, a) => {
                feed(&mut c, &bytes);
                if let Some(a) = a {
                    last_valid_us = a.valid_us;
                }
            }
            Step::Update(t) => {
                c.advance(t, &mut regs);
            }
        }
    }
    assert_eq!(c.counters.total(), 0);
    let last_fix_us = c.gnss().unwrap().fix_us;
    // The attitude 1.02 s old, the fix 1.2 s: stale, by the attitude.
    let t = last_valid_us + 1_020_000;
    assert!(c.advance(t, &mut regs));
    assert_eq!(c.update_mode(), Mode::Stale);
    assert_eq!(c.counters.get(Fault::Stale), 1);
    assert!(c.outputs().all(|o| o.held));
    // A fresh attitude: nominal again (the fix is 1.3 s old).
    let a = bus.attitude(t + 60_000);
    feed(&mut c, &attitude_frame(500, t + 80_000, &a));
    assert!(c.advance(t + 100_000, &mut regs));
    assert_eq!(c.update_mode(), Mode::Nominal);
    assert!(c.outputs().all(|o| !o.held));
    // The fix more than 2 s old: stale again, by the fix.
    let a = bus.attitude(last_fix_us + 2_050_000);
    feed(&mut c, &attitude_frame(501, last_fix_us + 2_060_000, &a));
    assert!(c.advance(last_fix_us + 2_060_000, &mut regs));
    assert_eq!(c.update_mode(), Mode::Stale);
    assert_eq!(c.counters.get(Fault::Stale), 2);
    // NAV replaces the bus's data; a GNSS frame then replaces NAV (and waits for an
    // attitude).
    let t = last_fix_us + 2_100_000;
    let nav = common::nav_frame(502, t, orbit_t0(), common::roll(0.1));
    feed(&mut c, &nav);
    assert!(c.nav().is_some() && c.gnss().is_none() && c.bus_attitude().is_none());
    let g = bus.gnss(t + 10_000);
    feed(&mut c, &gnss_frame(503, t + 20_000, &g));
    assert!(c.nav().is_none() && c.gnss().is_some());
    assert_eq!(c.mode(), Mode::WaitingForNav);
    assert_eq!(c.counters.total(), 2, "{:?}", c.last_fault);
}

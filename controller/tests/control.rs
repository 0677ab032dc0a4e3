//! The controller against independent computations: periods from the f64 reference
//! chain, every fault counted and harmless, the period guard's bounds.

mod common;

use common::{nav_frame, roll, state, R};
use controller::frame::{encode, kind, Decoder, Event, MAX_FRAME};
use controller::nav::Attitude;
use controller::{Config, Controller, Fault, LinePeriodSink, Mode, Scene};
use core_math::{Backend, Camera, Geometry, Reference};
use proptest::prelude::*;

#[derive(Default)]
struct Registers {
    writes: Vec<(u8, u32)>,
}

impl LinePeriodSink for Registers {
    type Error = ();
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), ()> {
        self.writes.push((index, ticks));
        Ok(())
    }
}

const I0: f64 = 97.98;
const H: f64 = 645e3;

fn feed(c: &mut Controller, bytes: &[u8]) {
    let mut d = Decoder::new();
    d.feed(bytes, |e| match e {
        Event::Frame(f) => c.on_frame(&f),
        Event::Rejected(r) => c.reject(Fault::from(r)),
    });
}

/// Ticks the reference gives for segment `k` of `scene`: |v| at its first, centre and
/// last pixel from the f64 chain, the period of the harmonic mean of the extremes.
fn reference_ticks(scene: &Scene, g: &Geometry<f64>, k: usize) -> u32 {
    let s = scene.segments[k];
    let centre = (s.first_px + s.last_px) / 2;
    let v: Vec<f64> = [s.first_px, centre, s.last_px]
        .iter()
        .map(|&n| {
            Reference
                .evaluate(&scene.camera, g, f64::from(n))
                .unwrap()
                .speed_mps()
        })
        .collect();
    let (lo, hi) = (
        v.iter().cloned().fold(f64::INFINITY, f64::min),
        v.iter().cloned().fold(0.0, f64::max),
    );
    let a = scene.camera.pixel_m;
    let period = 0.5 * (a / lo + a / hi);
    (period * scene.line_clock_hz + 0.5).floor() as u32
}

fn geometry(roll_rad: f64, u_rad: f64) -> Geometry<f64> {
    Geometry::circular(roll_rad, I0.to_radians(), u_rad, H, R)
}

#[test]
fn periods_match_the_reference_and_follow_the_orbit_and_the_roll() {
    let scene = Scene::paper_default();
    let mut c = Controller::new(Config::default(), scene).unwrap();
    let mut regs = Registers::default();
    assert!(c.advance(0, &mut regs));
    assert_eq!(c.mode(), Mode::WaitingForNav);
    assert!(
        regs.writes.is_empty(),
        "nothing is written before the first NAV frame"
    );

    let u0 = 0.5;
    let roll_rate = 0.5f32.to_radians();
    let att = Attitude {
        roll_rad: 20f32.to_radians(),
        roll_rate_rad_s: roll_rate,
        ..Attitude::default()
    };
    feed(
        &mut c,
        &nav_frame(1, 1_000_000, state(I0.to_radians(), u0, H), att),
    );
    // Updates at the frame instant and 0.2 s later (propagated orbit and roll).
    for dt_us in [0u64, 200_000] {
        regs.writes.clear();
        assert!(c.advance(1_000_000 + dt_us, &mut regs));
        assert_eq!(c.mode(), Mode::Nominal);
        let dt = dt_us as f64 * 1e-6;
        let omega = core_math::orbital_rate_rad_s(R, H);
        let g = geometry(
            f64::from(att.roll_rad) + f64::from(roll_rate) * dt,
            u0 + omega * dt,
        );
        assert_eq!(regs.writes.len(), 10);
        for &(k, ticks) in &regs.writes {
            let expect = reference_ticks(&scene, &g, usize::from(k));
            // f32 against f64 may land a period that sits on a half tick either way.
            assert!(
                ticks.abs_diff(expect) <= 1,
                "segment {k}: {ticks} vs {expect}"
            );
        }
    }
    // Outputs carry MTF and stages consistent with each other.
    for o in c.outputs() {
        assert!(!o.held);
        assert!(o.mtf > 0.0 && o.mtf <= 1.0);
        let m = core_math::mtf_mismatch(u32::from(o.max_stages), o.worst_mismatch).unwrap();
        assert!(
            m >= 0.95 - 1e-6,
            "stage limit {} gives MTF {m}",
            o.max_stages
        );
    }
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
                    pitch_rad: 0.02,
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
                    yaw_rate_rad_s: 1e-4,
                    ..roll(0.2)
                },
            ),
            Fault::AttitudeOutsideModel,
        ),
        (nav_frame(7, 1_300_000, good, roll(0.9)), Fault::OutOfRange),
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
        c.advance(1_000_000, &mut regs);
        assert_eq!(outputs(&c), before, "{fault:?} changed the outputs");
    }
}

#[test]
fn stale_telemetry_holds_the_last_periods_and_is_reported_once() {
    let (mut c, mut regs) = running_controller();
    let before = outputs(&c);
    regs.writes.clear();
    for t in (1_100_000..4_000_000).step_by(50_000) {
        c.advance(t, &mut regs);
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
    scene.max_roll_rad = 0.8;
    let mut c = Controller::new(Config::default(), scene).unwrap();
    let mut regs = Registers::default();
    feed(
        &mut c,
        &nav_frame(1, 1_000_000, state(I0.to_radians(), 0.3, H), roll(0.4)),
    );
    c.advance(1_000_000, &mut regs);
    let before: Vec<_> = c.outputs().copied().collect();
    assert_eq!(before.len(), 10);
    // Roll 40 deg: the far segments (field up to +35 deg) look past the limb (65 deg).
    feed(
        &mut c,
        &nav_frame(
            2,
            1_250_000,
            state(I0.to_radians(), 0.3, H),
            roll(40f32.to_radians()),
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
    let mut payload = [0u8; 320];
    let n = scene.encode(&mut payload).unwrap();
    let mut buf = [0u8; MAX_FRAME];
    let len = encode(kind::SCENE, 2, 1_010_000, &payload[..n], &mut buf).unwrap();
    feed(&mut c, &buf[..len]);
    assert_eq!(c.counters.total(), 0);
    assert_eq!(c.plan().count, 3, "inactive segments are not planned");
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
    assert_eq!(c.plan().count, 3);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    /// The period guard never refuses a physically possible period: the reference's
    /// A/|v| over the envelope (any orbit position and inclination, altitude in the
    /// configured range, roll within the scene's limit, any pixel) lies inside it.
    #[test]
    fn period_bounds_hold_over_the_envelope(
        h in 500e3f64..800e3, i0 in 0f64..180.0, g0 in 0f64..360.0, frac in -1f64..1.0, n in -30_000i32..30_000,
    ) {
        let scene = Scene::paper_default();
        let (lo, hi) = controller::control::period_bounds_s(&scene, &Config::default());
        let g = Geometry::circular(f64::from(scene.max_roll_rad) * frac, i0.to_radians(), g0.to_radians(), h, R);
        let cam: Camera = scene.camera;
        if let Ok(m) = Reference.evaluate(&cam, &g, f64::from(n)) {
            let t = cam.pixel_m / m.speed_mps();
            prop_assert!(t >= f64::from(lo) && t <= f64::from(hi), "{t} outside [{lo}, {hi}]");
        }
    }
}

#[test]
fn periods_and_status_frames_round_trip() {
    let (mut c, _) = running_controller();
    c.reject(Fault::BadCrc);
    let mut buf = [0u8; 400];
    let n = controller::report::encode_periods(&c, &mut buf).unwrap();
    let p = controller::report::Periods::decode(&buf[..n]).unwrap();
    assert_eq!(p.mode, Mode::Nominal as u8);
    let mine: Vec<_> = c.outputs().copied().collect();
    assert_eq!(p.records(), &mine[..]);
    let n = controller::report::encode_status(&c, 7, &mut buf).unwrap();
    assert_eq!(n, controller::report::STATUS_LEN);
    let s = controller::report::Status::decode(&buf[..n]).unwrap();
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
    let t = controller::control::MAX_TIME_TAG_US;
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

//! Regressions for the link defects an outside client found (issue 13): a time tag that
//! wedged the link, an update counter that could not be reconciled, SCENE uploads the
//! camera cannot use. Each test failed on the code before its fix.

mod common;

use common::{frame, nav_frame, roll, state, Accept};
use controller::frame::{kind, Decoder, Event};
use controller::report::{Periods, Status};
use controller::scene::{SCENE_HEADER_LEN, SEGMENT_LEN};
use controller::session::Session;
use controller::{Config, Controller, Fault, Scene};

fn session() -> Session {
    Session::new(Controller::new(Config::default(), Scene::paper_default()).unwrap())
}

/// What the session sent for `bytes`: PERIODS time tags and decoded STATUS frames.
fn feed(s: &mut Session, bytes: &[u8]) -> (Vec<u64>, Vec<Status>) {
    let mut out = Vec::new();
    s.feed(bytes, &mut Accept, |f| out.extend_from_slice(f));
    let (mut periods, mut status) = (Vec::new(), Vec::new());
    Decoder::new().feed(&out, |e| match e {
        Event::Frame(f) if f.kind == kind::PERIODS => {
            assert!(Periods::decode(f.payload).is_some());
            periods.push(f.time_us);
        }
        Event::Frame(f) if f.kind == kind::STATUS => {
            status.push(Status::decode(f.payload).unwrap())
        }
        other => panic!("unexpected downlink event {other:?}"),
    });
    (periods, status)
}

fn nav_at(seq: u16, t_us: u64) -> Vec<u8> {
    nav_frame(
        seq,
        t_us,
        state(97.98f64.to_radians(), 0.3, 645e3),
        roll(0.1),
    )
}

/// Defect 1: a TIME frame tagged 2^64 - 1 was accepted, after which every byte produced
/// a STATUS frame, PERIODS repeated, and no later frame was ever accepted again.
#[test]
fn a_time_tag_at_the_end_of_the_clock_is_refused_and_the_link_recovers_at_once() {
    let mut s = session();
    feed(&mut s, &nav_at(0, 1_000_000));
    let accepted = s.controller.frames_accepted;
    let (periods, status) = feed(&mut s, &frame(kind::TIME, 1, u64::MAX, &[]));
    assert!(periods.is_empty() && status.is_empty());
    assert_eq!(s.controller.frames_accepted, accepted);
    assert_eq!(s.controller.last_fault.map(Fault::name), Some("time_jump"));
    assert_eq!(s.controller.counters.total(), 1);
    assert_eq!(s.controller.now_us(), 1_000_000, "the clock did not move");
    // The next good frame is accepted and runs its update.
    let (periods, _) = feed(&mut s, &frame(kind::TIME, 2, 1_020_000, &[]));
    assert_eq!(s.controller.frames_accepted, accepted + 1);
    assert_eq!(periods, [1_020_000]);
    // Noise neither sends STATUS nor runs updates.
    let (periods, status) = feed(&mut s, &[0x55; 500]);
    assert!(periods.is_empty() && status.is_empty());
    // A tag just past the window is refused as well; one within it is accepted.
    let jump = Config::default().max_time_jump_us;
    feed(&mut s, &frame(kind::TIME, 3, 1_020_000 + jump + 1, &[]));
    assert_eq!(s.controller.counters.get(Fault::TimeJump), 2);
    feed(&mut s, &frame(kind::TIME, 4, 1_020_000 + jump, &[]));
    assert_eq!(s.controller.now_us(), 1_020_000 + jump);
    assert_eq!(s.controller.frames_accepted, accepted + 2);
}

/// A ground station's re-synchronisation: two consecutive frames on a new time line
/// (here 1 000 s back) move the clock there; the NAV of the old time line is dropped.
#[test]
fn two_consistent_frames_outside_the_window_resynchronise_the_clock() {
    let mut s = session();
    feed(&mut s, &nav_at(0, 1_000_000_000));
    feed(&mut s, &frame(kind::TIME, 1, 1_000_020_000, &[]));
    assert!(s.controller.nav().is_some());
    feed(&mut s, &nav_at(2, 5_000_000));
    assert_eq!(s.controller.counters.get(Fault::TimeWentBackwards), 1);
    assert_eq!(s.controller.now_us(), 1_000_020_000);
    let (periods, status) = feed(&mut s, &nav_at(3, 5_250_000));
    assert_eq!(s.controller.time_resyncs, 1);
    assert_eq!(s.controller.now_us(), 5_250_000);
    assert_eq!(s.controller.nav().map(|n| n.time_us), Some(5_250_000));
    assert_eq!(
        periods,
        [5_240_000],
        "the update due on the new time line runs"
    );
    assert_eq!(status.len(), 1, "a re-synchronisation is reported at once");
    assert_eq!(status[0].time_resyncs, 1);
    // Normal operation on the new time line.
    let (periods, _) = feed(&mut s, &frame(kind::TIME, 4, 5_260_000, &[]));
    assert_eq!(periods, [5_260_000]);
}

/// Defect 2: "updates run" left out the updates that held their periods (before the
/// first NAV, stale NAV), so it could not be reconciled with the PERIODS frames sent.
#[test]
fn updates_run_equals_the_periods_frames_sent_held_ones_included() {
    let mut s = session();
    let mut bytes = Vec::new();
    let mut seq = 0;
    // 0.5 s without NAV, NAV until 1 s, then 3 s of TIME only (stale from 2 s).
    for k in 0..=200u64 {
        let t = k * 20_000;
        bytes.extend(if (500_000..=1_000_000).contains(&t) && t % 250_000 == 0 {
            nav_at(seq, t)
        } else {
            frame(kind::TIME, seq, t, &[])
        });
        seq += 1;
    }
    bytes.extend(frame(kind::END, seq, 4_000_001, &[]));
    let (periods, status) = feed(&mut s, &bytes);
    let last = status.last().unwrap();
    assert_eq!(periods.len(), 201);
    assert_eq!(last.updates, 201);
    assert_eq!(last.count(Fault::Stale), 1);
    // Every frame sent was accepted, END included; the one fault is the stale episode.
    assert_eq!(last.frames_accepted, 202);
    assert_eq!(last.total(), 1);
}

/// A SCENE payload of `count` segments: the paper's scene, then `edit` on the bytes.
fn scene_payload(count: u8, edit: impl Fn(&mut Vec<u8>)) -> Vec<u8> {
    let base = Scene::paper_default();
    let mut p = vec![0u8; 400];
    let n = base.encode(&mut p).unwrap();
    p.truncate(n);
    p[42] = count;
    let seg = p[SCENE_HEADER_LEN..SCENE_HEADER_LEN + SEGMENT_LEN].to_vec();
    p.truncate(SCENE_HEADER_LEN);
    for k in 0..i32::from(count) {
        let mut s = seg.clone();
        // 10 segments of 6 000 px tiling -30 000..30 000; more are narrower.
        let width = 60_000 / i32::from(count.max(10));
        let first = -30_000 + width * k;
        s[0..4].copy_from_slice(&first.to_le_bytes());
        s[4..8].copy_from_slice(&(first + width - 1).to_le_bytes());
        p.extend_from_slice(&s);
    }
    edit(&mut p);
    p
}

fn segment(p: &mut [u8], k: usize) -> &mut [u8] {
    &mut p[SCENE_HEADER_LEN + k * SEGMENT_LEN..SCENE_HEADER_LEN + (k + 1) * SEGMENT_LEN]
}

/// Defect 3: scenes the camera cannot use were accepted (an `active` byte of 2, 65 535
/// stages, no active segment, overlapping segments), and 17 segments were reported as
/// `bad_length`. Each must be refused as `invalid_scene` and change nothing.
#[test]
fn unusable_scenes_are_refused_as_invalid_scene() {
    let cases: Vec<(&str, Vec<u8>)> = vec![
        (
            "active byte 2",
            scene_payload(10, |p| segment(p, 3)[10] = 2),
        ),
        (
            "65 535 stages",
            scene_payload(10, |p| {
                p[40..42].copy_from_slice(&u16::MAX.to_le_bytes());
                segment(p, 0)[8..10].copy_from_slice(&u16::MAX.to_le_bytes());
            }),
        ),
        (
            "largest stage count beyond the MTF formula's range",
            scene_payload(10, |p| p[40..42].copy_from_slice(&u16::MAX.to_le_bytes())),
        ),
        (
            "no active segment",
            scene_payload(10, |p| {
                for k in 0..10 {
                    segment(p, k)[10] = 0;
                }
            }),
        ),
        (
            "overlapping segments",
            scene_payload(10, |p| {
                segment(p, 4)[0..4].copy_from_slice(&(-7_000i32).to_le_bytes())
            }),
        ),
        (
            "unordered segments",
            scene_payload(10, |p| {
                let (a, b) = (segment(p, 2).to_vec(), segment(p, 7).to_vec());
                segment(p, 2).copy_from_slice(&b);
                segment(p, 7).copy_from_slice(&a);
            }),
        ),
        ("17 segments", scene_payload(17, |_| {})),
        (
            "a pixel that never sees the Earth",
            scene_payload(10, |p| {
                segment(p, 9)[4..8].copy_from_slice(&100_000i32.to_le_bytes())
            }),
        ),
    ];
    for (what, payload) in cases {
        let mut s = session();
        feed(&mut s, &nav_at(0, 1_000_000));
        let before: Vec<_> = s.controller.outputs().copied().collect();
        let scene = *s.controller.scene();
        feed(&mut s, &frame(kind::SCENE, 1, 1_010_000, &payload));
        assert_eq!(
            s.controller.counters.get(Fault::InvalidScene),
            1,
            "{what}: not refused as invalid_scene ({:?})",
            s.controller.last_fault
        );
        assert_eq!(s.controller.counters.total(), 1, "{what}");
        assert_eq!(*s.controller.scene(), scene, "{what}");
        assert_eq!(s.controller.outputs().copied().collect::<Vec<_>>(), before);
    }
    // The control case: the same builder without an edit is accepted.
    let mut s = session();
    feed(
        &mut s,
        &frame(kind::SCENE, 1, 1_010_000, &scene_payload(12, |_| {})),
    );
    assert_eq!(s.controller.counters.total(), 0);
    assert_eq!(s.controller.scene().count, 12);
}

/// Whatever stage count a valid scene configures, the reported MTF lies in [0, 1]: past
/// the sinc's first zero the contrast is reversed and weaker, reported as its modulus
/// (at most the first side lobe's 0.2172), not as a negative one and not as 0.
#[test]
fn the_reported_mtf_lies_in_the_unit_interval() {
    let mut scene = Scene::paper_default();
    scene.max_stages = controller::scene::MAX_TDI_STAGES;
    for s in scene.segments.iter_mut().take(10) {
        s.tdi_stages = controller::scene::MAX_TDI_STAGES;
    }
    let mut s = Session::new(Controller::new(Config::default(), scene).unwrap());
    feed(
        &mut s,
        &nav_frame(
            0,
            1_000_000,
            state(97.98f64.to_radians(), 0.3, 800e3),
            roll(25f32.to_radians()),
        ),
    );
    let mtf: Vec<f32> = s.controller.outputs().map(|o| o.mtf).collect();
    assert_eq!(mtf.len(), 10);
    assert!(mtf.iter().all(|m| (0.0..=1.0).contains(m)), "{mtf:?}");
    assert!(
        mtf.iter().any(|&m| m > 0.0 && m <= 0.2172),
        "the far segment is past the first zero: {mtf:?}"
    );
}

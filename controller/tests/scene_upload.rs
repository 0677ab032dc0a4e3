//! What a SCENE upload does to the periods in force (issue 25, item 1): every active
//! segment keeps a record in PERIODS; a segment past the limb keeps its last period,
//! flagged held, across a re-upload of the same geometry; a segment whose geometry
//! changed has no valid last period and is reported as such (ticks 0, held).

mod common;

use common::{feed, frame, nav_frame, periods, roll, state, Registers, H, I0};
use controller::frame::kind;
use controller::report::Periods;
use controller::{Config, Controller, Fault, Scene, SegmentOutput};

fn scene_frame(scene: &Scene, seq: u16, t_us: u64) -> Vec<u8> {
    let mut payload = [0u8; 400];
    let n = scene.encode(&mut payload).unwrap();
    frame(kind::SCENE, seq, t_us, &payload[..n])
}

/// The paper's camera with roll allowed to 1 rad, so that a roll of 55 deg puts the
/// far segments (field up to +17 deg) past the limb (64 deg from 645 km) while the near
/// ones still see the ground.
fn wide_roll_scene() -> Scene {
    let mut scene = Scene::paper_default();
    scene.envelope.max_roll_rad = 1.0;
    scene
}

/// A controller that computed all ten periods at roll 0.4 rad (1 s), then an update at
/// roll 55 deg (1.25 s) that held the far segments.
fn past_the_limb(scene: Scene) -> (Controller, Registers, Vec<SegmentOutput>) {
    let mut c = Controller::new(Config::default(), scene).unwrap();
    let mut regs = Registers::default();
    feed(
        &mut c,
        &nav_frame(1, 1_000_000, state(I0.to_radians(), 0.3, H), roll(0.4)),
    );
    c.advance(1_000_000, &mut regs);
    let good: Vec<_> = c.outputs().copied().collect();
    assert_eq!(good.len(), 10);
    assert!(good.iter().all(|o| !o.held && o.ticks > 0));
    feed(
        &mut c,
        &nav_frame(
            2,
            1_250_000,
            state(I0.to_radians(), 0.3, H),
            roll(55f32.to_radians()),
        ),
    );
    c.advance(1_250_000, &mut regs);
    assert!(c.counters.get(Fault::BeyondLimb) >= 1);
    (c, regs, good)
}

/// The held segments of `p`, by index.
fn held(p: &Periods) -> Vec<u8> {
    p.records()
        .iter()
        .filter(|r| r.held)
        .map(|r| r.index)
        .collect()
}

#[test]
fn a_re_uploaded_scene_keeps_every_record_and_the_held_periods() {
    let scene = wide_roll_scene();
    let (mut c, mut regs, good) = past_the_limb(scene);
    let before = periods(&c);
    let held_before = held(&before);
    assert_eq!(
        before.records().len(),
        10,
        "a record for every active segment"
    );
    assert!(!held_before.is_empty() && held_before.len() < 10);
    // The same scene again, byte for byte: nothing changes, not even the records.
    feed(&mut c, &scene_frame(&scene, 3, 1_260_000));
    assert_eq!(c.counters.get(Fault::InvalidScene), 0, "scene refused");
    assert_eq!(
        periods(&c),
        before,
        "a byte-identical SCENE changed the report"
    );
    // The next update, still past the limb: the far segments still hold the period
    // they had before the roll, flagged held, and every segment has its record.
    regs.writes.clear();
    let beyond = c.counters.get(Fault::BeyondLimb);
    c.advance(1_270_000, &mut regs);
    assert!(c.counters.get(Fault::BeyondLimb) > beyond);
    let after = periods(&c);
    assert_eq!(
        after.records().len(),
        10,
        "records lost after a SCENE upload"
    );
    assert_eq!(held(&after), held_before);
    for r in after.records().iter().filter(|r| r.held) {
        let g = good.iter().find(|g| g.index == r.index).unwrap();
        assert_eq!(r.ticks, g.ticks, "segment {}: held period lost", r.index);
        assert!(regs.writes.iter().all(|w| w.0 != r.index));
    }
}

#[test]
fn a_segment_whose_geometry_changed_has_no_period_to_hold() {
    let scene = wide_roll_scene();
    let (mut c, mut regs, good) = past_the_limb(scene);
    let held_before = held(&periods(&c));
    let moved = *held_before.last().unwrap();
    // The far segment's chip moved along P1 by 1 mm: its old period belongs to another
    // line on the focal plane.
    let mut changed = scene;
    changed.segments[usize::from(moved)].p1_m += 1e-3;
    feed(&mut c, &scene_frame(&changed, 3, 1_260_000));
    assert_eq!(c.counters.get(Fault::InvalidScene), 0, "scene refused");
    regs.writes.clear();
    c.advance(1_270_000, &mut regs);
    let after = periods(&c);
    assert_eq!(
        after.records().len(),
        10,
        "a record for every active segment"
    );
    assert_eq!(held(&after), held_before);
    for r in after.records() {
        let g = good.iter().find(|g| g.index == r.index).unwrap();
        if r.index == moved {
            // No valid period: ticks 0 (never a period), no contrast promised.
            assert_eq!(
                (r.ticks, r.mtf, r.max_stages, r.worst_mismatch),
                (0, 0.0, 0, f32::MAX),
                "segment {}",
                r.index
            );
        } else if r.held {
            assert_eq!(r.ticks, g.ticks, "segment {}: held period lost", r.index);
        }
    }
    assert!(regs.writes.iter().all(|w| w.0 != moved));
    // Back over the ground, the moved segment gets a period of its own again.
    feed(
        &mut c,
        &nav_frame(3, 1_500_000, state(I0.to_radians(), 0.3, H), roll(0.4)),
    );
    c.advance(1_500_000, &mut regs);
    let back = periods(&c);
    assert_eq!(back.records().len(), 10);
    assert!(back.records().iter().all(|r| !r.held && r.ticks > 0));
}

#[test]
fn a_changed_camera_drops_every_held_period() {
    let scene = wide_roll_scene();
    let (mut c, mut regs, _) = past_the_limb(scene);
    let held_before = held(&periods(&c));
    // A new line clock: every old period counts other ticks.
    let mut changed = scene;
    changed.line_clock_hz = 20e6;
    feed(&mut c, &scene_frame(&changed, 3, 1_260_000));
    assert_eq!(c.counters.get(Fault::InvalidScene), 0, "scene refused");
    c.advance(1_270_000, &mut regs);
    let after = periods(&c);
    assert_eq!(after.records().len(), 10);
    assert_eq!(held(&after), held_before);
    for r in after.records() {
        if r.held {
            assert_eq!(
                r.ticks, 0,
                "segment {} kept a period of the old clock",
                r.index
            );
        } else {
            assert!(r.ticks > 0);
        }
    }
}

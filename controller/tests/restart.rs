//! A reset costs lines, not state (issue 25, item 4): the snapshot a controller leaves
//! puts its periods back into the registers, flagged held, and its scene and heights
//! back in force; after the first update on fresh telemetry the restored controller's
//! outputs are those of a controller that was never reset. A snapshot that does not
//! check out changes nothing. STATUS reports the reset's cause and count.

mod common;

use common::{feed, frame, nav_frame, periods, roll, state, Registers, H, I0};
use controller::fault::ResetCause;
use controller::frame::kind;
use controller::report::{encode_status, Status, STATUS_LEN};
use controller::restart::Snapshot;
use controller::{Config, Controller, Fault, Scene};

/// A controller that has flown a while: a scene of its own (staggered heights), a
/// TERRAIN frame, two NAV frames and their updates.
fn flown() -> (Controller, Registers) {
    let mut scene = Scene::paper_default();
    let count = usize::from(scene.count);
    for (k, s) in scene.segments.iter_mut().enumerate().take(count) {
        s.ground_h_m = 100.0 * k as f32;
    }
    let mut c = Controller::new(Config::default(), scene).unwrap();
    let mut regs = Registers::default();
    let mut terrain = [0u8; 128];
    let heights = controller::Terrain {
        heights_m: core::array::from_fn(|k| 250.0 + 40.0 * k as f32),
        count: scene.count,
    };
    let n = heights.encode(&mut terrain).unwrap();
    feed(&mut c, &frame(kind::TERRAIN, 1, 900_000, &terrain[..n]));
    for (seq, t_us) in [(2u16, 1_000_000u64), (3, 1_020_000)] {
        feed(
            &mut c,
            &nav_frame(seq, t_us, state(I0.to_radians(), 0.3, H), roll(0.3)),
        );
        c.advance(t_us, &mut regs);
    }
    assert_eq!(c.counters.total(), 0);
    (c, regs)
}

fn snapshot_of(c: &Controller) -> Snapshot {
    let mut s = Snapshot::EMPTY;
    assert!(c.snapshot_inputs(&mut s));
    assert!(c.snapshot_periods(&mut s.periods));
    s
}

#[test]
fn restore_programs_the_last_periods_held_then_rejoins() {
    let (mut flown, _) = flown();
    let snapshot = snapshot_of(&flown);
    let before: Vec<_> = flown.outputs().copied().collect();
    assert_eq!(before.len(), 10);

    let mut after_reset = Controller::blank(Config::default());
    let mut regs = Registers::default();
    let restored = after_reset.restore(&snapshot, &mut regs).unwrap();
    assert_eq!(restored.periods, 10);
    // The registers get the last periods, each once, before any telemetry.
    let expected: Vec<(u8, u32)> = before.iter().map(|o| (o.index, o.ticks)).collect();
    assert_eq!(regs.writes, expected);
    // The outputs are the last ones, flagged held; scene and heights are back.
    let held: Vec<_> = after_reset.outputs().copied().collect();
    assert_eq!(held.len(), before.len());
    for (h, b) in held.iter().zip(&before) {
        assert!(h.held);
        assert_eq!(controller::SegmentOutput { held: b.held, ..*h }, *b);
    }
    assert_eq!(after_reset.scene(), flown.scene());
    assert_eq!(after_reset.heights_m(), flown.heights_m());
    assert_eq!(periods(&after_reset).records().len(), 10);

    // Fresh telemetry: both controllers see the same frame; the restored one's update
    // must equal the one that was never reset, none held any more.
    let nav = nav_frame(9, 1_040_000, state(I0.to_radians(), 0.31, H), roll(0.3));
    let mut regs_a = Registers::default();
    let mut regs_b = Registers::default();
    feed(&mut flown, &nav);
    flown.advance(1_040_000, &mut regs_a);
    feed(&mut after_reset, &nav);
    after_reset.advance(1_040_000, &mut regs_b);
    let a = periods(&flown);
    let b = periods(&after_reset);
    assert_eq!(a, b);
    assert!(b.records().iter().all(|r| !r.held));
    assert_eq!(regs_a.writes, regs_b.writes);
}

#[test]
fn a_snapshot_that_does_not_check_out_changes_nothing() {
    let (flown, _) = flown();
    let good = snapshot_of(&flown);

    // Cut PERIODS: nothing is written, the controller stays blank.
    let mut cut = good;
    cut.periods.len -= 3;
    let mut c = Controller::blank(Config::default());
    let mut regs = Registers::default();
    assert_eq!(c.restore(&cut, &mut regs), Err(Fault::BadLength));
    assert!(regs.writes.is_empty());
    assert_eq!(c.outputs().count(), 0);

    // Heights out of range: the registers keep what the snapshot held in force, the
    // controller takes no scene and no output.
    let mut high = good;
    let first = controller::scene::TERRAIN_HEADER_LEN;
    high.terrain.bytes[first..first + 4].copy_from_slice(&20_000f32.to_le_bytes());
    let mut c = Controller::blank(Config::default());
    let mut regs = Registers::default();
    assert_eq!(c.restore(&high, &mut regs), Err(Fault::OutOfRange));
    assert_eq!(c.outputs().count(), 0);
    assert_eq!(c.scene().count, Scene::paper_default().count);
    assert_eq!(c.inputs_generation(), 0);

    // A scene payload that is not one.
    let mut garbled = good;
    garbled.scene.len = 7;
    let mut c = Controller::blank(Config::default());
    let mut regs = Registers::default();
    assert!(c.restore(&garbled, &mut regs).is_err());
    assert!(regs.writes.is_empty());
    assert_eq!(c.outputs().count(), 0);

    // An empty snapshot (power-on: nothing kept).
    let mut c = Controller::blank(Config::default());
    assert!(c.restore(&Snapshot::EMPTY, &mut regs).is_err());
}

#[test]
fn status_reports_the_reset() {
    let (mut c, _) = flown();
    let decode = |c: &Controller| {
        let mut buf = [0u8; STATUS_LEN];
        let n = encode_status(c, 0, 0, &mut buf).unwrap();
        assert_eq!(n, STATUS_LEN);
        Status::decode(&buf[..n]).unwrap()
    };
    let s = decode(&c);
    assert_eq!((s.reset_cause, s.resets), (None, 0));
    c.note_boot(ResetCause::Watchdog, 3);
    let s = decode(&c);
    assert_eq!((s.reset_cause, s.resets), (Some(ResetCause::Watchdog), 3));
    c.note_boot(ResetCause::StackOverflow, 300);
    let s = decode(&c);
    assert_eq!(
        (s.reset_cause, s.resets),
        (Some(ResetCause::StackOverflow), 255)
    );
    for cause in ResetCause::ALL {
        assert_eq!(ResetCause::from_u8(cause as u8), Some(cause));
    }
    assert_eq!(ResetCause::from_u8(0), None);
}

/// The time scales survive a reset too (they came with the bus's TIME_SCALES frame, and
/// the bus may send them rarely): without them the C2T after a reset would take
/// UT1 - UTC = 0. A TIME_SCALES frame that changes them is a change of the kept inputs.
#[test]
fn the_time_scales_in_force_survive_a_reset() {
    let (mut c, _) = flown();
    let generation = c.inputs_generation();
    let mut p = [0u8; 8];
    let n = controller::bus::encode_time_scales(19, -0.3125, &mut p).unwrap();
    feed(&mut c, &frame(kind::TIME_SCALES, 4, 1_030_000, &p[..n]));
    assert_eq!(c.counters.total(), 0);
    assert_ne!(c.inputs_generation(), generation);
    let sent = *c.time_scales();
    assert_eq!((sent.gps_utc_s, sent.dut1_s), (19.0, -0.3125));
    // The same values again change nothing that is kept.
    let generation = c.inputs_generation();
    feed(&mut c, &frame(kind::TIME_SCALES, 5, 1_040_000, &p[..n]));
    assert_eq!(c.inputs_generation(), generation);

    let mut after_reset = Controller::blank(Config::default());
    assert_ne!(*after_reset.time_scales(), sent);
    after_reset
        .restore(&snapshot_of(&c), &mut Registers::default())
        .unwrap();
    assert_eq!(*after_reset.time_scales(), sent);

    // A kept TIME_SCALES payload that does not check out is refused like the frame.
    let mut bad = snapshot_of(&c);
    bad.time_scales.len = 7;
    let mut fresh = Controller::blank(Config::default());
    assert_eq!(
        fresh.restore(&bad, &mut Registers::default()),
        Err(Fault::BadLength)
    );
}

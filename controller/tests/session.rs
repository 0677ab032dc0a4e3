//! The session loop shared by the firmware and the host twin: what it sends, when, and
//! that its output does not depend on how the link chunks the bytes.

mod common;

use common::{frame, nav_frame, roll, state, Accept};
use controller::frame::{kind, Decoder, Event};
use controller::report::{Periods, Status};
use controller::session::Session;
use controller::{Config, Controller, Fault, Scene};

/// Two seconds: NAV at 4 Hz, TIME at every other 20 ms tick, a bad CRC, END.
fn uplink() -> Vec<u8> {
    let mut out = Vec::new();
    let i0 = 97.98f64.to_radians();
    let mut seq = 0;
    for k in 0..=100u64 {
        let t = k * 20_000;
        let f = if t % 250_000 == 0 {
            nav_frame(
                seq,
                t,
                state(i0, 0.3 + 1e-3 * t as f64 * 1e-6, 645e3),
                roll(0.1),
            )
        } else {
            frame(kind::TIME, seq, t, &[])
        };
        seq += 1;
        out.extend_from_slice(&f);
        if k == 30 {
            let mut bad = frame(kind::TIME, seq, t + 1, &[]);
            bad[10] ^= 0x10;
            out.extend_from_slice(&bad);
        }
    }
    out.extend_from_slice(&frame(kind::END, seq, 2_000_001, &[]));
    // Ignored: after END.
    out.extend_from_slice(&frame(kind::TIME, seq + 1, 2_100_000, &[]));
    out
}

fn run(bytes: &[u8], chunk: usize) -> (Vec<u8>, bool) {
    let c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut s = Session::new(c);
    let mut out = Vec::new();
    let mut ended = false;
    for part in bytes.chunks(chunk) {
        ended = s.feed(part, &mut Accept, |f| out.extend_from_slice(f));
    }
    assert!(s.is_ended() == ended);
    (out, ended)
}

#[test]
fn periods_after_each_update_status_every_second_and_at_the_end() {
    let (out, ended) = run(&uplink(), 1);
    assert!(ended);
    let mut periods = Vec::new();
    let mut status = Vec::new();
    let mut d = Decoder::new();
    d.feed(&out, |e| match e {
        Event::Frame(f) if f.kind == kind::PERIODS => {
            periods.push((f.time_us, Periods::decode(f.payload).unwrap()))
        }
        Event::Frame(f) if f.kind == kind::STATUS => {
            status.push((f.time_us, Status::decode(f.payload).unwrap()))
        }
        other => panic!("unexpected downlink event {other:?}"),
    });
    // One update per 20 ms tick from 0 to 2 s, each with all ten segments.
    assert_eq!(periods.len(), 101);
    for (k, (t, p)) in periods.iter().enumerate() {
        assert_eq!(*t, k as u64 * 20_000);
        assert_eq!(p.records().len(), 10);
    }
    // STATUS at 0, 1 s, 2 s and the final one after END.
    let times: Vec<u64> = status.iter().map(|(t, _)| *t).collect();
    assert_eq!(times, [0, 1_000_000, 2_000_000, 2_000_000]);
    let last = status.last().unwrap().1;
    assert_eq!(last.count(Fault::BadCrc), 1);
    assert_eq!(last.total(), 1);
    assert_eq!(last.updates, 101);
}

#[test]
fn output_does_not_depend_on_how_the_bytes_arrive() {
    let bytes = uplink();
    let (one, _) = run(&bytes, 1);
    for chunk in [2, 7, 64, 1000, bytes.len()] {
        assert_eq!(run(&bytes, chunk).0, one, "chunks of {chunk}");
    }
}

#[test]
fn an_end_frame_with_a_payload_is_refused() {
    let c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut s = Session::new(c);
    let ended = s.feed(&frame(kind::END, 0, 5, &[1]), &mut Accept, |_| {});
    assert!(!ended);
    assert_eq!(s.controller.counters.get(Fault::BadLength), 1);
}

/// Frames through a transmit queue that drains slower than the session sends: every
/// frame the ground receives is whole, every other one was dropped whole and counted,
/// and STATUS reports the count.
#[test]
fn a_full_transmit_queue_drops_whole_frames_and_status_counts_them() {
    use controller::downlink::FrameQueue;
    use heapless::spsc::Queue;

    let bytes = uplink();
    // The END frame and the TIME frame after it, 18 bytes each.
    let (body, end) = bytes.split_at(bytes.len() - 36);
    let c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut s = Session::new(c);
    let mut q: Queue<u8, 1024> = Queue::new();
    let (producer, mut consumer) = q.split();
    let mut tx = FrameQueue::<1024>::new(producer);
    let mut wire = Vec::new();
    let mut sent = 0u32;
    // 8 bytes leave per byte received: about 210 per 20 ms tick, for 306 sent.
    for &b in body {
        s.feed(&[b], &mut Accept, |f| {
            sent += 1;
            tx.push(f)
        });
        wire.extend((0..8).map_while(|_| consumer.dequeue()));
    }
    // The link catches up before END, so that the final STATUS goes out.
    wire.extend(core::iter::from_fn(|| consumer.dequeue()));
    assert!(s.feed(end, &mut Accept, |f| {
        sent += 1;
        tx.push(f)
    }));
    wire.extend(core::iter::from_fn(|| consumer.dequeue()));

    let mut received = 0u32;
    let mut last_status = None;
    let mut d = Decoder::new();
    d.feed(&wire, |e| match e {
        Event::Frame(f) if f.kind == kind::PERIODS => {
            received += 1;
            assert!(Periods::decode(f.payload).is_some());
        }
        Event::Frame(f) if f.kind == kind::STATUS => {
            received += 1;
            last_status = Some(Status::decode(f.payload).unwrap());
        }
        other => panic!("a frame was cut: {other:?}"),
    });
    assert_eq!(d.skipped_bytes, 0);
    assert_eq!(sent, 105, "101 PERIODS and 4 STATUS");
    assert!(s.downlink_dropped > 0, "the queue never overflowed");
    assert_eq!(s.downlink_dropped, tx.dropped());
    assert_eq!(received + s.downlink_dropped, sent);
    assert_eq!(last_status.unwrap().downlink_dropped, s.downlink_dropped);
}

#[test]
fn a_link_that_takes_every_frame_drops_none() {
    let c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
    let mut s = Session::new(c);
    let mut status = None;
    s.feed(&uplink(), &mut Accept, |f| {
        let mut d = Decoder::new();
        d.feed(f, |e| {
            if let Event::Frame(f) = e {
                if f.kind == kind::STATUS {
                    status = Some(Status::decode(f.payload).unwrap());
                }
            }
        });
        true
    });
    assert_eq!(s.downlink_dropped, 0);
    assert_eq!(status.unwrap().downlink_dropped, 0);
}

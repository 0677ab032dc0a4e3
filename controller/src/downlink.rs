//! The downlink's transmit queue, the loop's end: whole frames into a byte queue that the
//! UART's transmit interrupt drains (the firmware's `tx` module holds the other end).
//!
//! A frame enters the queue whole or not at all: [`FrameQueue::push`] checks the room
//! first and refuses a frame that does not fit, which is then dropped whole and counted
//! ([`FrameQueue::dropped`]; the session reports it in STATUS, docs/telemetry.md). So the
//! ground never sees a frame cut in the middle by a busy transmitter.
//!
//! The queue is `heapless::spsc` (lock-free, one producer and one consumer): the room the
//! producer sees can only grow while it looks, since only the consumer, the interrupt,
//! takes bytes out; so a frame that was found to fit always goes in whole.

use heapless::spsc::Producer;

use crate::frame::MAX_FRAME;
use crate::report::{PERIODS_HEADER_LEN, RECORD_LEN, STATUS_LEN};
use crate::scene::MAX_SEGMENTS;

/// The largest PERIODS frame: header, 8 + 28 bytes per segment for the 16 segments a
/// scene may have, CRC (474 bytes).
pub const MAX_PERIODS_FRAME: usize = frame_len(PERIODS_HEADER_LEN + RECORD_LEN * MAX_SEGMENTS);
/// A STATUS frame (102 bytes).
pub const STATUS_FRAME: usize = frame_len(STATUS_LEN);
/// The most one step of the session sends: one received byte completes at most one
/// frame, which runs at most one update (a PERIODS frame) and sends at most one STATUS
/// (576 bytes).
pub const MAX_STEP_OUTPUT: usize = MAX_PERIODS_FRAME + STATUS_FRAME;

const fn frame_len(payload: usize) -> usize {
    MAX_FRAME - crate::frame::MAX_PAYLOAD + payload
}

const _: () = assert!(MAX_PERIODS_FRAME <= MAX_FRAME && STATUS_FRAME <= MAX_FRAME);

/// The producer's end of a byte queue of `N` slots (`heapless::spsc::Queue<u8, N>`,
/// which holds N - 1 bytes), taking whole frames only.
pub struct FrameQueue<'a, const N: usize> {
    producer: Producer<'a, u8>,
    /// Frames refused for lack of room, dropped whole (saturating).
    dropped: u32,
    /// The most bytes the queue held right after a frame went in.
    high_water: usize,
}

impl<'a, const N: usize> FrameQueue<'a, N> {
    /// The producer of a `Queue<u8, N>`.
    pub fn new(producer: Producer<'a, u8>) -> FrameQueue<'a, N> {
        FrameQueue {
            producer,
            dropped: 0,
            high_water: 0,
        }
    }

    /// True if the producer is of a queue of `N` slots. The producer carries the size as
    /// a slice length, which the optimiser cannot see: after this check it knows it, so
    /// that the queue's index arithmetic (modulo the size) is a mask with no division by
    /// zero, a panic path in the firmware (docs/no-panic.md). Always true when built
    /// with the right `N`.
    fn sized(&self) -> bool {
        N > 0 && self.producer.capacity() == N - 1
    }

    /// Bytes the queue can take now (at least this many: the consumer may be taking
    /// bytes out meanwhile); 0 for a queue of another size than `N`.
    pub fn room(&self) -> usize {
        if !self.sized() {
            return 0;
        }
        self.producer.capacity().saturating_sub(self.producer.len())
    }

    /// Puts `frame` in the queue whole, or, if it does not fit, not at all: then it is
    /// dropped and counted. True if it went in.
    pub fn push(&mut self, frame: &[u8]) -> bool {
        let room = self.room();
        if frame.len() > room {
            self.dropped = self.dropped.saturating_add(1);
            return false;
        }
        // Cannot fail: the room only grows while the interrupt takes bytes out. The size
        // is checked again before each byte: the previous byte's atomic store makes the
        // optimiser read it afresh (`sized`).
        let whole = frame
            .iter()
            .all(|&b| self.sized() && self.producer.enqueue(b).is_ok());
        let held = N.saturating_sub(1).saturating_sub(room) + frame.len();
        self.high_water = self.high_water.max(held);
        whole
    }

    /// Frames dropped so far.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// The most bytes the queue has held.
    pub fn high_water(&self) -> usize {
        self.high_water
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use heapless::spsc::Queue;

    #[test]
    fn frame_sizes() {
        assert_eq!(MAX_PERIODS_FRAME, 16 + 8 + 28 * 16 + 2);
        assert_eq!(STATUS_FRAME, 16 + STATUS_LEN + 2);
    }

    #[test]
    fn a_frame_goes_in_whole_or_not_at_all_and_a_drop_is_counted() {
        // 63 bytes of room.
        let mut q: Queue<u8, 64> = Queue::new();
        let (producer, mut consumer) = q.split();
        let mut tx = FrameQueue::<64>::new(producer);
        let a: [u8; 40] = core::array::from_fn(|i| i as u8);
        let b: [u8; 30] = core::array::from_fn(|i| 100 + i as u8);
        assert!(tx.push(&a));
        assert_eq!((tx.room(), tx.dropped()), (23, 0));
        // 30 bytes do not fit in 23: nothing of them goes in, the drop is counted.
        assert!(!tx.push(&b));
        assert_eq!((tx.room(), tx.dropped()), (23, 1));
        // What fits exactly still goes in.
        let c = [7u8; 23];
        assert!(tx.push(&c));
        assert_eq!(tx.room(), 0);
        assert!(!tx.push(&[1]));
        assert_eq!(tx.dropped(), 2);
        // The consumer sees a, then c, and nothing of b or of the one-byte frame.
        let mut out = [0u8; 63];
        for o in out.iter_mut() {
            *o = consumer.dequeue().expect("a queued byte");
        }
        assert_eq!(consumer.dequeue(), None);
        assert_eq!(&out[..40], &a[..]);
        assert_eq!(&out[40..], &c[..]);
        // Room came back as the consumer took bytes: b fits now, whole.
        assert!(tx.push(&b));
        assert_eq!(tx.dropped(), 2);
        assert_eq!(tx.high_water(), 63);
        let got: [u8; 30] = core::array::from_fn(|_| consumer.dequeue().expect("byte"));
        assert_eq!(got, b);
    }

    #[test]
    fn a_queue_of_another_size_takes_nothing() {
        let mut q: Queue<u8, 8> = Queue::new();
        let (producer, consumer) = q.split();
        let mut tx = FrameQueue::<16>::new(producer);
        assert_eq!(tx.room(), 0);
        assert!(!tx.push(&[1]));
        assert_eq!(tx.dropped(), 1);
        assert!(!consumer.ready());
    }

    #[test]
    fn the_drop_count_saturates() {
        let mut q: Queue<u8, 4> = Queue::new();
        let (producer, _consumer) = q.split();
        let mut tx = FrameQueue::<4>::new(producer);
        tx.dropped = u32::MAX - 1;
        assert!(!tx.push(&[0; 4]));
        assert!(!tx.push(&[0; 4]));
        assert_eq!(tx.dropped(), u32::MAX);
    }
}

//! Received bytes, from the UART's receive interrupt to the telemetry loop, through a
//! lock-free single-producer single-consumer queue (`heapless::spsc::Queue`, split
//! into its two ends):
//!
//! - the interrupt side, the producer: the board's receive interrupt calls
//!   [`Handler::run`], which moves every byte the UART holds into the queue and counts
//!   every receive error the UART reports (overrun, framing, parity, noise);
//! - the loop side, the consumer ([`RxQueue`]): [`RxQueue::read`] takes a byte, or
//!   reports each counted error once, as a [`LinkError`]; [`RxQueue::wait`] sleeps (WFI)
//!   while the queue is empty.
//!
//! A full queue costs no byte the interrupt has read: the interrupt then leaves the
//! byte in the UART and masks its own line (it *stalls*), and the loop unmasks and pends
//! it again as soon as it has taken a byte out. Under QEMU the UART's chardev is
//! flow-controlled, so a stalled UART holds the host back and a pass loses nothing
//! however fast the host sends. On silicon a stalled UART overruns, and the overrun is
//! counted like any receive error. [`LinkError::QueueOverflow`] counts a byte the
//! interrupt read and could not queue: that cannot happen (it reads only when there is
//! room), but it is counted rather than assumed.
//!
//! The interrupt's state (the producer and the UART's receive registers) lives in the
//! board's [`Handler`] static, behind a `critical_section::Mutex`: no `static mut`.

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use embedded_hal_nb::serial::{Error as _, Read};
use heapless::spsc::{Consumer, Producer, Queue};
use static_cell::ConstStaticCell;

use crate::link::LinkError;

/// The queue's slots; it holds one byte fewer (heapless's `spsc::Queue` keeps one slot
/// free): 255 bytes, 22 ms of the link at 115 200 Bd.
pub const QUEUE_SLOTS: usize = 256;

static QUEUE: ConstStaticCell<Queue<u8, QUEUE_SLOTS>> = ConstStaticCell::new(Queue::new());

/// What the interrupt tells the loop, besides the bytes.
struct Shared {
    /// Receive errors, by [`LinkError`] (its discriminant).
    errors: [AtomicU32; LinkError::COUNT],
    /// True while the interrupt has masked its line because the queue was full.
    stalled: AtomicBool,
    /// How many times the interrupt found the queue full.
    stalls: AtomicU32,
    /// The most bytes the queue has held.
    high_water: AtomicU32,
}

static SHARED: Shared = Shared {
    errors: [const { AtomicU32::new(0) }; LinkError::COUNT],
    stalled: AtomicBool::new(false),
    stalls: AtomicU32::new(0),
    high_water: AtomicU32::new(0),
};

/// How the queue went, for the log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RxStats {
    /// The most bytes the queue held.
    pub high_water: u32,
    /// Times the queue was full and the receive interrupt stalled.
    pub stalls: u32,
}

/// The queue's statistics so far.
pub fn stats() -> RxStats {
    RxStats {
        high_water: SHARED.high_water.load(Ordering::Relaxed),
        stalls: SHARED.stalls.load(Ordering::Relaxed),
    }
}

/// The receive interrupt's side: the producer, the UART's receiver and the interrupt
/// line (to mask it when the queue is full).
pub struct RxInterrupt<R, I> {
    producer: Producer<'static, u8>,
    uart: R,
    line: I,
}

impl<R: Read<u8>, I: InterruptNumber> crate::irq::Service for RxInterrupt<R, I> {
    /// Moves every byte the UART holds into the queue, or stalls when it is full.
    fn service(&mut self) {
        // The producer carries the queue's size as a slice length, read from the
        // handler's static here: this check lets the optimiser know it, so that the
        // queue's index arithmetic (modulo the size) is a mask and has no division by
        // zero, a panic path (docs/no-panic.md). Always true: there is one queue.
        if self.producer.capacity() != QUEUE_SLOTS - 1 {
            return;
        }
        loop {
            if !self.producer.ready() {
                NVIC::mask(self.line);
                SHARED.stalled.store(true, Ordering::Release);
                SHARED.stalls.fetch_add(1, Ordering::Relaxed);
                return;
            }
            match self.uart.read() {
                Ok(byte) => {
                    if self.producer.enqueue(byte).is_err() {
                        count(LinkError::QueueOverflow);
                    }
                    let held = self.producer.len() as u32;
                    SHARED.high_water.fetch_max(held, Ordering::Relaxed);
                }
                Err(nb::Error::WouldBlock) => return,
                Err(nb::Error::Other(e)) => count(LinkError::from_kind(e.kind())),
            }
        }
    }
}

fn count(e: LinkError) {
    if let Some(n) = SHARED.errors.get(e as usize) {
        n.fetch_add(1, Ordering::Relaxed);
    }
}

/// A board's receive interrupt state, for a static: empty until [`start`] fills it.
pub type Handler<R, I> = crate::irq::Handler<RxInterrupt<R, I>>;

/// Takes the queue, gives its producer and `uart` (the UART's receiver, read only by
/// the interrupt from now on) to `handler`, and unmasks the receive interrupt `line`,
/// whose handler must call [`Handler::run`] on `handler`. Returns the loop's side;
/// `None` if called twice.
pub fn start<R: Read<u8>, I: InterruptNumber>(
    handler: &'static Handler<R, I>,
    uart: R,
    line: I,
) -> Option<RxQueue<I>> {
    let (producer, consumer) = QUEUE.try_take()?.split();
    handler.install(RxInterrupt {
        producer,
        uart,
        line,
    })?;
    // Pended, so that a byte that arrived before the handler was installed is read.
    NVIC::pend(line);
    // SAFETY: the firmware's critical sections are PRIMASK's (cortex-m's single-core
    // `critical-section`), never an NVIC mask, so unmasking a line breaks none; the
    // line's handler is installed above.
    unsafe { NVIC::unmask(line) };
    Some(RxQueue {
        consumer,
        line,
        reported: [0; LinkError::COUNT],
    })
}

/// The telemetry loop's side: the consumer.
pub struct RxQueue<I> {
    consumer: Consumer<'static, u8>,
    line: I,
    /// The errors already reported, by kind.
    reported: [u32; LinkError::COUNT],
}

impl<I: InterruptNumber> RxQueue<I> {
    /// The next received byte; a receive error the interrupt counted since the last
    /// call is reported first, once (the bytes it cost are gone; the decoder then
    /// drops the broken frame).
    pub fn read(&mut self) -> nb::Result<u8, LinkError> {
        if let Some(e) = self.next_error() {
            return Err(nb::Error::Other(e));
        }
        let Some(byte) = self.consumer.dequeue() else {
            return Err(nb::Error::WouldBlock);
        };
        if SHARED.stalled.load(Ordering::Acquire) {
            // The interrupt masked itself with the queue full; there is room now. Pended
            // too, so that the byte left in the UART is read even if no other comes.
            SHARED.stalled.store(false, Ordering::Relaxed);
            NVIC::pend(self.line);
            // SAFETY: as in `start`.
            unsafe { NVIC::unmask(self.line) };
        }
        Ok(byte)
    }

    /// True if the receive interrupt has masked `line` because the queue was full (the
    /// next [`RxQueue::read`] unmasks it): `line` is this queue's, and it stalled.
    pub fn holds(&self, line: u16) -> bool {
        self.line.number() == line && SHARED.stalled.load(Ordering::Acquire)
    }

    fn next_error(&mut self) -> Option<LinkError> {
        LinkError::ALL
            .into_iter()
            .zip(&SHARED.errors)
            .zip(&mut self.reported)
            .find_map(|((e, n), reported)| {
                (n.load(Ordering::Relaxed) != *reported).then(|| {
                    *reported = reported.wrapping_add(1);
                    e
                })
            })
    }

    /// Sleeps (WFI) until the receive interrupt has run, if the queue is empty. PRIMASK
    /// is set around the check and the WFI, so a byte queued before the check is seen
    /// there, and one that arrives after it pends the interrupt, which ends the WFI
    /// (WFI wakes on a pending interrupt even with PRIMASK set) and runs once PRIMASK is
    /// cleared again.
    pub fn wait(&self) {
        critical_section::with(|_| {
            if !self.consumer.ready() {
                cortex_m::asm::wfi();
            }
        });
    }
}

//! Bytes to send, from the telemetry loop to the UART's transmit interrupt, through a
//! lock-free single-producer single-consumer queue (`heapless::spsc::Queue`, split into
//! its two ends): the transmit side of [`crate::rx`].
//!
//! - the loop side, the producer ([`TxQueue`]): [`TxQueue::send`] puts a whole frame in
//!   the queue, or, if it does not fit, drops it whole and says so
//!   (`controller::downlink::FrameQueue`: the session counts it in STATUS), then pends
//!   the transmit interrupt. It never waits for the UART.
//! - the interrupt side, the consumer: the board's transmit interrupt calls
//!   [`Handler::run`], which writes bytes from the queue to the UART for as long as the
//!   UART takes them, and asks the UART to interrupt again when it can take more
//!   ([`TxPort`]); with the queue empty and the last byte gone it marks the queue drained
//!   and stops asking.
//!
//! The interrupt's state (the consumer and the UART's transmitter) lives in the board's
//! [`Handler`] static, behind a `critical_section::Mutex`: no `static mut`.

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use controller::downlink::FrameQueue;
use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use embedded_hal_nb::serial::Write;
use heapless::spsc::{Consumer, Queue};

use crate::rx::RxQueue;
use static_cell::ConstStaticCell;

/// The queue's slots; it holds one byte fewer: 2 047 bytes, room for two of the largest
/// PERIODS frames (474 bytes each, 16 segments) and, behind them, everything one more
/// byte can make the session send (a PERIODS and a STATUS frame, 576 bytes: 1 524 in
/// all), rounded up to a power of two (the index arithmetic is then a mask). The loop
/// takes the next received byte only when that much room is free (`telemetry`), so a
/// frame is refused only where the loop may not wait for room
/// ([`TxQueue::wait_for_room`]); a queue over 2 x 576 bytes keeps the transmitter busy
/// while the loop refills it.
pub const QUEUE_SLOTS: usize = 2048;

static QUEUE: ConstStaticCell<Queue<u8, QUEUE_SLOTS>> = ConstStaticCell::new(Queue::new());

/// What a UART's transmitter must do for the transmit interrupt, besides `embedded-hal-nb`'s
/// `serial::Write<u8>` (`write` a byte or answer `WouldBlock` while busy; `flush`: done
/// when the last byte has left).
pub trait TxPort: Write<u8> {
    /// Interrupt (again) when the transmitter can take a byte or has finished one
    /// (`true`), or not (`false`). Also acknowledges the interrupt that is being served.
    fn interrupt(&mut self, on: bool);
}

/// What the interrupt tells the loop.
struct Shared {
    /// True while the queue holds bytes or the UART is still sending (false at reset, so
    /// that the static needs no `.data`).
    busy: AtomicBool,
    /// Errors the transmitter reported (each cost a byte).
    errors: AtomicU32,
}

static SHARED: Shared = Shared {
    busy: AtomicBool::new(false),
    errors: AtomicU32::new(0),
};

/// The transmit interrupt's side: the consumer and the UART's transmitter.
pub struct TxInterrupt<T> {
    consumer: Consumer<'static, u8>,
    uart: T,
}

impl<T: TxPort> crate::irq::Service for TxInterrupt<T> {
    /// Writes queued bytes while the UART takes them.
    fn service(&mut self) {
        // As in `rx`: lets the optimiser know the queue's size, so that its index
        // arithmetic has no division by zero (docs/no-panic.md). Always true.
        if self.consumer.capacity() != QUEUE_SLOTS - 1 {
            return;
        }
        while let Some(&byte) = self.consumer.peek() {
            match self.uart.write(byte) {
                Ok(()) => {}
                Err(nb::Error::WouldBlock) => {
                    self.uart.interrupt(true);
                    return;
                }
                // Never expected: counted, and the byte dropped (the ground's decoder
                // then refuses the cut frame).
                Err(nb::Error::Other(_)) => {
                    SHARED.errors.fetch_add(1, Ordering::Relaxed);
                }
            }
            let _ = self.consumer.dequeue();
        }
        // Empty: wait for the last byte to leave, then stop interrupting.
        let done = !matches!(self.uart.flush(), Err(nb::Error::WouldBlock));
        self.uart.interrupt(!done);
        SHARED.busy.store(!done, Ordering::Release);
    }
}

/// A board's transmit interrupt state, for a static: empty until [`start`] fills it.
pub type Handler<T> = crate::irq::Handler<TxInterrupt<T>>;

/// Takes the queue, gives its consumer and `uart` (the UART's transmitter, written only
/// by the interrupt from now on) to `handler`, and unmasks the transmit interrupt `line`,
/// whose handler must call [`Handler::run`] on `handler`. Returns the loop's side;
/// `None` if called twice.
pub fn start<T: TxPort, I: InterruptNumber>(
    handler: &'static Handler<T>,
    uart: T,
    line: I,
) -> Option<TxQueue<I>> {
    let (producer, consumer) = QUEUE.try_take()?.split();
    handler.install(TxInterrupt { consumer, uart })?;
    // SAFETY: as in `rx::start`: the firmware's critical sections are PRIMASK's, never
    // an NVIC mask; the line's handler is installed above.
    unsafe { NVIC::unmask(line) };
    Some(TxQueue {
        frames: FrameQueue::new(producer),
        line,
    })
}

/// The telemetry loop's side: whole frames into the queue.
pub struct TxQueue<I> {
    frames: FrameQueue<'static, QUEUE_SLOTS>,
    line: I,
}

/// How the queue went, for the log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TxStats {
    /// The most bytes the queue held.
    pub high_water: u32,
    /// Frames dropped whole for lack of room.
    pub dropped: u32,
    /// Errors the transmitter reported.
    pub errors: u32,
}

impl<I: InterruptNumber> TxQueue<I> {
    /// Queues `frame` whole and starts the transmitter; or, if it does not fit, drops it
    /// whole. True if it was queued.
    pub fn send(&mut self, frame: &[u8]) -> bool {
        // Set before the frame goes in: the interrupt clears it once the queue is empty
        // and the UART idle.
        SHARED.busy.store(true, Ordering::Release);
        let queued = self.frames.push(frame);
        // The interrupt takes it from here: at once if the UART is idle.
        NVIC::pend(self.line);
        queued
    }

    /// Bytes the queue can take now (at least: the interrupt may be taking bytes out).
    pub fn room(&self) -> usize {
        self.frames.room()
    }

    /// True when everything queued has left the UART.
    pub fn drained(&self) -> bool {
        !SHARED.busy.load(Ordering::Acquire)
    }

    /// Sleeps (WFI) until the transmit interrupt has run, unless the queue has room for
    /// `bytes` bytes; true if the loop may wait so (sleep, then ask again). PRIMASK is
    /// set around the check and the WFI, as in [`crate::rx::RxQueue::wait`], so room
    /// made before the check is seen there, and room made after it comes with an
    /// interrupt, which ends the WFI: while the room is short the queue holds bytes, so
    /// the UART's transmit interrupt is on its way. Unless the receive side `rx` has
    /// masked the line because its queue was full, and the line is this one too (the
    /// STM32F405's USART1): then no interrupt can come before the loop reads a byte
    /// (which unmasks it), so this returns false without sleeping and the loop reads on.
    pub fn wait_for_room<R: InterruptNumber>(&self, bytes: usize, rx: &RxQueue<R>) -> bool {
        critical_section::with(|_| {
            if rx.holds(self.line.number()) {
                return false;
            }
            if self.room() < bytes {
                cortex_m::asm::wfi();
            }
            true
        })
    }

    /// Sleeps (WFI) until the transmit interrupt has run, if the queue is not drained
    /// yet (as [`TxQueue::wait_for_room`]).
    pub fn wait_for_drain(&self) {
        critical_section::with(|_| {
            if !self.drained() {
                cortex_m::asm::wfi();
            }
        });
    }

    pub fn stats(&self) -> TxStats {
        TxStats {
            high_water: self.frames.high_water() as u32,
            dropped: self.frames.dropped(),
            errors: SHARED.errors.load(Ordering::Relaxed),
        }
    }
}

//! The telemetry link as the rest of the firmware sees it: the receiver, an
//! `embedded-hal-nb` serial port of bytes (`serial::Read<u8>`, never blocking: an empty
//! port answers `WouldBlock`), plus [`RxWait`], the one thing those traits lack: a way
//! to sleep until a byte may have arrived; and the transmitter, [`FrameTx`]: whole
//! frames into a transmit queue, never waiting. Both boards read the port from their
//! receive interrupt into a queue ([`crate::rx`]) and write it from their transmit
//! interrupt out of another ([`crate::tx`]), each UART's transmitter behind
//! `serial::Write<u8>` ([`crate::tx::TxPort`]); the loop reads one queue and fills the
//! other. Any board's UART driver, or a host test double, provides it (the boards:
//! [`crate::board`]).

use embedded_hal_nb::serial::{self, ErrorKind, ErrorType, Read};

use cortex_m::interrupt::InterruptNumber;

use crate::rx::RxQueue;
use crate::tx::{TxQueue, TxStats};

/// Sleeping until the receiver may have something. A UART with a receive interrupt
/// sleeps here (WFI); a plain polled link returns at once.
pub trait RxWait {
    fn wait_for_rx(&mut self);
}

/// The downlink: whole frames into a transmit queue that the UART's transmit interrupt
/// drains. Nothing here waits for the UART.
pub trait FrameTx {
    /// Queues `frame` whole, or, if the queue has no room for all of it, drops it whole.
    /// True if it was queued.
    fn send_frame(&mut self, frame: &[u8]) -> bool;
    /// Bytes the queue can take now (at least).
    fn tx_room(&self) -> usize;
    /// Sleeps until the transmit interrupt has run, unless the queue has room for
    /// `bytes` bytes. False if sleeping could not end that way (the receive side holds
    /// the transmit interrupt back until the next byte is read: `tx::TxQueue::wait_for_room`).
    fn wait_for_tx_room(&mut self, bytes: usize) -> bool;
    /// True when everything queued has left the UART.
    fn tx_drained(&self) -> bool;
    /// Sleeps until the transmit interrupt has run, unless everything has left.
    fn wait_for_tx_drained(&mut self);
    /// The transmit queue's statistics so far.
    fn tx_stats(&self) -> TxStats;
}

/// Everything the telemetry loop needs of a link.
pub trait Link: ErrorType<Error = LinkError> + Read<u8> + RxWait + FrameTx {}

impl<T: ErrorType<Error = LinkError> + Read<u8> + RxWait + FrameTx> Link for T {}

/// Why a link lost bytes: what the UART reports, and the receive queue's overflow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkError {
    /// A byte arrived before the previous one was read.
    Overrun,
    FrameFormat,
    Parity,
    Noise,
    /// Any other error the UART reports.
    Other,
    /// The receive interrupt read a byte and the queue had no room for it
    /// ([`crate::rx`]: never expected, it reads only when there is room).
    QueueOverflow,
}

impl LinkError {
    pub const COUNT: usize = 6;
    /// Every error, in discriminant order.
    pub const ALL: [LinkError; LinkError::COUNT] = [
        LinkError::Overrun,
        LinkError::FrameFormat,
        LinkError::Parity,
        LinkError::Noise,
        LinkError::Other,
        LinkError::QueueOverflow,
    ];

    pub fn from_kind(kind: ErrorKind) -> LinkError {
        match kind {
            ErrorKind::Overrun => LinkError::Overrun,
            ErrorKind::FrameFormat => LinkError::FrameFormat,
            ErrorKind::Parity => LinkError::Parity,
            ErrorKind::Noise => LinkError::Noise,
            _ => LinkError::Other,
        }
    }

    /// Its name, for the log.
    pub fn name(self) -> &'static str {
        match self {
            LinkError::Overrun => "overrun",
            LinkError::FrameFormat => "framing error",
            LinkError::Parity => "parity error",
            LinkError::Noise => "noise",
            LinkError::Other => "other",
            LinkError::QueueOverflow => "receive queue overflow",
        }
    }
}

impl serial::Error for LinkError {
    fn kind(&self) -> ErrorKind {
        match self {
            LinkError::Overrun | LinkError::QueueOverflow => ErrorKind::Overrun,
            LinkError::FrameFormat => ErrorKind::FrameFormat,
            LinkError::Parity => ErrorKind::Parity,
            LinkError::Noise => ErrorKind::Noise,
            LinkError::Other => ErrorKind::Other,
        }
    }
}

/// A UART as the loop sees it on either board: the receive queue its receive interrupt
/// (line `R`) fills and the transmit queue its transmit interrupt (line `T`) drains. The
/// registers are the interrupts'; each board's start-up builds one
/// (`board::cmsdk::start_uart`, the STM32F405's `take`).
pub struct QueuedLink<R, T> {
    rx: RxQueue<R>,
    tx: TxQueue<T>,
}

impl<R, T> QueuedLink<R, T> {
    pub fn new(rx: RxQueue<R>, tx: TxQueue<T>) -> Self {
        QueuedLink { rx, tx }
    }
}

impl<R, T> ErrorType for QueuedLink<R, T> {
    type Error = LinkError;
}

impl<R: InterruptNumber, T> Read<u8> for QueuedLink<R, T> {
    fn read(&mut self) -> nb::Result<u8, LinkError> {
        self.rx.read()
    }
}

impl<R: InterruptNumber, T> RxWait for QueuedLink<R, T> {
    fn wait_for_rx(&mut self) {
        self.rx.wait();
    }
}

impl<R: InterruptNumber, T: InterruptNumber> FrameTx for QueuedLink<R, T> {
    fn send_frame(&mut self, frame: &[u8]) -> bool {
        self.tx.send(frame)
    }
    fn tx_room(&self) -> usize {
        self.tx.room()
    }
    fn wait_for_tx_room(&mut self, bytes: usize) -> bool {
        self.tx.wait_for_room(bytes, &self.rx)
    }
    fn tx_drained(&self) -> bool {
        self.tx.drained()
    }
    fn wait_for_tx_drained(&mut self) {
        self.tx.wait_for_drain();
    }
    fn tx_stats(&self) -> TxStats {
        self.tx.stats()
    }
}

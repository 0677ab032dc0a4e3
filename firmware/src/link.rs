//! The telemetry link as the rest of the firmware sees it: an `embedded-hal-nb` serial
//! port of bytes (`serial::Read<u8>` and `serial::Write<u8>`, never blocking: a busy
//! or empty port answers `WouldBlock`), plus [`RxWait`], the one thing those traits
//! lack: a way to sleep until a byte may have arrived. Both boards read the port
//! from their receive interrupt into a queue ([`crate::rx`]); the loop reads the queue.
//! Any board's UART driver, or a host test double, provides it (the boards:
//! [`crate::board`]).

use embedded_hal_nb::serial::{self, ErrorKind, ErrorType, Read, Write};

/// Sleeping until the receiver may have something. A UART with a receive interrupt
/// sleeps here (WFI); a plain polled link returns at once.
pub trait RxWait {
    fn wait_for_rx(&mut self);
}

/// Everything the telemetry loop needs of a link.
pub trait Link: ErrorType<Error = LinkError> + Read<u8> + Write<u8> + RxWait {}

impl<T: ErrorType<Error = LinkError> + Read<u8> + Write<u8> + RxWait> Link for T {}

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

/// How many times [`send_bounded`] polls a busy transmitter for one byte before it
/// gives the frame up. Under QEMU a byte leaves in a few polls unless the host stops
/// reading; on a board size it from the baud rate (one byte at 115 200 Bd is 87 us).
pub const TX_POLL_LIMIT: u32 = 1_000_000;

/// Why a frame was not sent whole.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TxError {
    /// The transmitter stayed busy for [`TX_POLL_LIMIT`] polls: the rest of the frame
    /// was dropped.
    Timeout,
    /// The port reported an error: the rest of the frame was dropped.
    Link,
}

/// Sends `bytes`, polling a busy transmitter at most [`TX_POLL_LIMIT`] times per byte:
/// a link nobody reads costs a bounded delay and the frame, never the main loop.
pub fn send_bounded<L: Write<u8>>(link: &mut L, bytes: &[u8]) -> Result<(), TxError> {
    for &b in bytes {
        let mut polls = 0u32;
        loop {
            match link.write(b) {
                Ok(()) => break,
                Err(nb::Error::WouldBlock) => {
                    polls += 1;
                    if polls >= TX_POLL_LIMIT {
                        return Err(TxError::Timeout);
                    }
                }
                Err(nb::Error::Other(_)) => return Err(TxError::Link),
            }
        }
    }
    Ok(())
}

/// Waits (bounded as [`send_bounded`]) until the transmitter has sent everything; false
/// if it never did, or reported an error.
pub fn flush_bounded<L: Write<u8>>(link: &mut L) -> bool {
    (0..TX_POLL_LIMIT)
        .find_map(|_| match link.flush() {
            Ok(()) => Some(true),
            Err(nb::Error::WouldBlock) => None,
            Err(nb::Error::Other(_)) => Some(false),
        })
        .unwrap_or(false)
}

//! The telemetry link as the rest of the firmware sees it: one byte at a time, never
//! waiting. [`ByteLink`] is all a UART driver has to provide (the mps2-an386's CMSDK
//! UART in [`crate::cmsdk`]; a board's UART, or a host test double, equally).

/// A byte-wide serial link with non-blocking receive and transmit.
pub trait ByteLink {
    /// The received byte, if one is waiting.
    fn read_byte(&mut self) -> Option<u8>;
    /// Queues `byte` for transmission; false (and nothing queued) when the transmitter
    /// is still busy with the previous byte.
    fn try_write_byte(&mut self, byte: u8) -> bool;
    /// True when the transmitter has taken every queued byte.
    fn tx_idle(&mut self) -> bool;
    /// Nothing was received: wait until a byte may have arrived. A UART with a receive
    /// interrupt sleeps here; the default returns at once (plain polling).
    fn wait(&mut self) {}
}

/// How many times [`send_bounded`] polls a busy transmitter for one byte before it
/// gives the frame up. Under QEMU a byte leaves in a few polls unless the host stops
/// reading; on a board size it from the baud rate (one byte at 115 200 Bd is 87 us).
pub const TX_POLL_LIMIT: u32 = 1_000_000;

/// The transmitter stayed busy for [`TX_POLL_LIMIT`] polls: the rest of the frame was
/// dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TxTimeout;

/// Sends `bytes`, polling a busy transmitter at most [`TX_POLL_LIMIT`] times per byte:
/// a link nobody reads costs a bounded delay and the frame, never the main loop.
pub fn send_bounded<L: ByteLink>(link: &mut L, bytes: &[u8]) -> Result<(), TxTimeout> {
    for &b in bytes {
        let mut polls = 0u32;
        while !link.try_write_byte(b) {
            polls += 1;
            if polls >= TX_POLL_LIMIT {
                return Err(TxTimeout);
            }
        }
    }
    Ok(())
}

/// Waits (bounded as [`send_bounded`]) until the transmitter is idle; false if it never
/// became so.
pub fn flush_bounded<L: ByteLink>(link: &mut L) -> bool {
    (0..TX_POLL_LIMIT).any(|_| link.tx_idle())
}

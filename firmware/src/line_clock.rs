//! Line periods out: the controller's [`LinePeriodSink`] on this hardware.
//!
//! Each detector segment has a line clock: a counter on the line clock's frequency
//! that reloads every period (period = RELOAD + 1 ticks). Segment 0's is a real
//! register, the board's timer reload register ([`ReloadRegister`]: the mps2-an386's
//! TIMER0 RELOAD, the STM32F405's TIM2 ARR; written, then read back: a write that does
//! not stick is refused and the controller keeps the segment's last good period); the
//! other segments' counters do not exist on these boards and are a table in RAM. What
//! was programmed also goes to the ground in the PERIODS frame (see
//! [`crate::telemetry`]). Under QEMU neither timer counts a 10 MHz line clock: the point
//! is the register path, not the rate.

use controller::scene::MAX_SEGMENTS;
use controller::sink::{Error, ErrorKind};
use controller::LinePeriodSink;

/// A counter's reload register (the board layer's line clock; embedded-hal 1.0 has no
/// timer traits).
pub trait ReloadRegister {
    fn set_reload(&mut self, value: u32);
    fn reload(&self) -> u32;
}

/// Why a period was not programmed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineClockError {
    /// Zero ticks has no reload value.
    ZeroPeriod,
    /// No segment with that index.
    NoSuchSegment,
    /// The register read back another value than was written.
    Readback,
}

impl Error for LineClockError {
    fn kind(&self) -> ErrorKind {
        match self {
            LineClockError::ZeroPeriod => ErrorKind::InvalidPeriod,
            LineClockError::NoSuchSegment => ErrorKind::NoSuchSegment,
            LineClockError::Readback => ErrorKind::NotApplied,
        }
    }
}

/// The line clocks of all segments.
pub struct LineClocks<R> {
    segment0: R,
    programmed: [u32; MAX_SEGMENTS],
    /// Periods refused by [`LinePeriodSink::write_period`].
    pub errors: u32,
}

impl<R: ReloadRegister> LineClocks<R> {
    pub fn new(segment0: R) -> Self {
        LineClocks {
            segment0,
            programmed: [0; MAX_SEGMENTS],
            errors: 0,
        }
    }

    /// The period (ticks) programmed for segment `index`, 0 if none yet.
    pub fn programmed(&self, index: u8) -> u32 {
        self.programmed
            .get(usize::from(index))
            .copied()
            .unwrap_or(0)
    }

    fn program(&mut self, index: u8, ticks: u32) -> Result<(), LineClockError> {
        let reload = ticks.checked_sub(1).ok_or(LineClockError::ZeroPeriod)?;
        let slot = self
            .programmed
            .get_mut(usize::from(index))
            .ok_or(LineClockError::NoSuchSegment)?;
        if index == 0 {
            self.segment0.set_reload(reload);
            if self.segment0.reload() != reload {
                return Err(LineClockError::Readback);
            }
        }
        *slot = ticks;
        Ok(())
    }
}

impl<R: ReloadRegister> LinePeriodSink for LineClocks<R> {
    type Error = LineClockError;

    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), LineClockError> {
        let r = self.program(index, ticks);
        if r.is_err() {
            self.errors = self.errors.saturating_add(1);
        }
        r
    }
}

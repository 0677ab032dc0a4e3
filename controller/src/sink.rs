//! Where line periods go: [`LinePeriodSink`], the period registers of the camera's line
//! clock (one per segment), the controller's only way out to the hardware.
//!
//! In the manner of embedded-hal 1.0's traits (`embedded_hal::digital::{Error,
//! ErrorKind}`): a sink chooses its own error type, and the bound asks only that the
//! error can be printed and say what kind of failure it was ([`Error::kind`]), so that
//! generic code can tell failures apart without knowing the board. A sink that cannot
//! fail uses [`core::convert::Infallible`].

/// A sink's error: what went wrong, in the board's terms ([`core::fmt::Debug`]) and in
/// the controller's ([`ErrorKind`]).
pub trait Error: core::fmt::Debug {
    /// The kind of this failure.
    fn kind(&self) -> ErrorKind;
}

/// The kinds of failure a sink reports. Whatever the kind, the controller does the same:
/// the register kept its old period, and the segment's output is reported as held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The sink has no register for that segment.
    NoSuchSegment,
    /// The register cannot hold that period (zero ticks, or beyond its width).
    InvalidPeriod,
    /// The write did not take: the register reads back another value.
    NotApplied,
    /// Any other failure.
    Other,
}

impl Error for ErrorKind {
    #[inline]
    fn kind(&self) -> ErrorKind {
        *self
    }
}

impl Error for core::convert::Infallible {
    #[inline]
    fn kind(&self) -> ErrorKind {
        match *self {}
    }
}

/// Where line periods go: small, and the only way out. Implemented by the firmware's line
/// clocks (`firmware/src/line_clock.rs`) and by the host tools' and tests' recorders.
pub trait LinePeriodSink {
    /// Why a period was not programmed.
    type Error: Error;
    /// Programs segment `index`'s line period, in ticks of the scene's line clock.
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), Self::Error>;
}

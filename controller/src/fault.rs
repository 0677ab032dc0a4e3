//! Every reason the controller refuses an input or an output, and their counters.
//! A refusal never changes the line periods in force: the last good ones stay. Also
//! why the core last started ([`ResetCause`]), which STATUS reports.

use core_math::ModelError;

use crate::frame::FrameError;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Fault {
    /// Frame CRC mismatch.
    BadCrc = 0,
    /// A frame cut short by the next one.
    Truncated,
    /// Length field beyond the maximum payload.
    Oversized,
    /// Unknown protocol version.
    UnknownVersion,
    /// Unknown frame kind.
    UnknownKind,
    /// Payload length wrong for its kind.
    BadLength,
    /// A NaN or infinity in a payload.
    NonFinite,
    /// A finite value outside the controller's envelope (altitude, speed, roll, rates,
    /// scene geometry).
    OutOfRange,
    /// Time tag not after the last accepted one.
    TimeWentBackwards,
    /// Pitch, yaw or an attitude rate beyond the roll-only model's configured tolerance.
    AttitudeOutsideModel,
    /// An active segment's line of sight misses the Earth at the commanded roll.
    BeyondLimb,
    /// No valid NAV frame for longer than the configured time.
    Stale,
    /// A computed line period outside the physically possible range.
    PeriodOutOfRange,
    /// A scene upload that does not describe a usable focal plane.
    InvalidScene,
    /// Time tag too far ahead of the controller's clock (more than
    /// `Config::max_time_jump_us`), or beyond the largest tag the clock takes.
    TimeJump,
    /// A quaternion (ATTITUDE, or the mounting in SCENE) whose norm is off 1 by more
    /// than 1e-3.
    BadQuaternion,
    /// A GNSS time of fix or an attitude's time of validity outside the accepted window
    /// (after the last one taken, not after the frame's tag, not older than the data's
    /// staleness limit), or outside the Earth-orientation model's years.
    FixTime,
    /// Leap seconds (GPS - UTC) outside 0..=60 s, or |UT1 - UTC| of 0.9 s or more.
    TimeScales,
    /// A DEM_BEGIN whose grid the camera cannot take: upload id 0, more nodes than
    /// the store holds, a side of fewer than 2 nodes, a spacing not positive, a tile
    /// reaching past 88 deg of latitude or across the antimeridian (`crate::dem`).
    DemGrid,
    /// A DEM frame out of sequence: a chunk of no upload or of another, a chunk missing,
    /// repeated or out of order, a DEM_BEGIN repeating the upload in progress or the
    /// tile in force.
    DemSequence,
    /// A DEM chunk with a height outside -500..9 000 m.
    DemHeight,
    /// A DEM tile whose heights do not have the CRC-32 its DEM_BEGIN announced.
    DemCrc,
}

impl Fault {
    pub const COUNT: usize = 22;
    pub const ALL: [Fault; Fault::COUNT] = [
        Fault::BadCrc,
        Fault::Truncated,
        Fault::Oversized,
        Fault::UnknownVersion,
        Fault::UnknownKind,
        Fault::BadLength,
        Fault::NonFinite,
        Fault::OutOfRange,
        Fault::TimeWentBackwards,
        Fault::AttitudeOutsideModel,
        Fault::BeyondLimb,
        Fault::Stale,
        Fault::PeriodOutOfRange,
        Fault::InvalidScene,
        Fault::TimeJump,
        Fault::BadQuaternion,
        Fault::FixTime,
        Fault::TimeScales,
        Fault::DemGrid,
        Fault::DemSequence,
        Fault::DemHeight,
        Fault::DemCrc,
    ];

    // Out of line: the firmware's log lines name faults in several places, and each
    // inlined copy brought its own table.
    #[inline(never)]
    pub const fn name(self) -> &'static str {
        match self {
            Fault::BadCrc => "bad_crc",
            Fault::Truncated => "truncated",
            Fault::Oversized => "oversized",
            Fault::UnknownVersion => "unknown_version",
            Fault::UnknownKind => "unknown_kind",
            Fault::BadLength => "bad_length",
            Fault::NonFinite => "non_finite",
            Fault::OutOfRange => "out_of_range",
            Fault::TimeWentBackwards => "time_went_backwards",
            Fault::AttitudeOutsideModel => "attitude_outside_model",
            Fault::BeyondLimb => "beyond_limb",
            Fault::Stale => "stale",
            Fault::PeriodOutOfRange => "period_out_of_range",
            Fault::InvalidScene => "invalid_scene",
            Fault::TimeJump => "time_jump",
            Fault::BadQuaternion => "bad_quaternion",
            Fault::FixTime => "fix_time",
            Fault::TimeScales => "time_scales",
            Fault::DemGrid => "dem_grid",
            Fault::DemSequence => "dem_sequence",
            Fault::DemHeight => "dem_height",
            Fault::DemCrc => "dem_crc",
        }
    }
}

impl From<FrameError> for Fault {
    fn from(e: FrameError) -> Self {
        match e {
            FrameError::BadCrc => Fault::BadCrc,
            FrameError::Truncated => Fault::Truncated,
            FrameError::Oversized => Fault::Oversized,
            FrameError::UnknownVersion => Fault::UnknownVersion,
        }
    }
}

impl From<ModelError> for Fault {
    fn from(e: ModelError) -> Self {
        match e {
            ModelError::NonFinite(_) => Fault::NonFinite,
            ModelError::LineOfSightMissesEarth => Fault::BeyondLimb,
            ModelError::NoImageMotion
            | ModelError::NoAlongTrackMotion
            | ModelError::LinePeriodOutOfRange => Fault::PeriodOutOfRange,
            ModelError::NonPositiveAltitude
            | ModelError::NonPositiveEarthRadius
            | ModelError::NonPositiveFocalLength
            | ModelError::NonPositivePixelPitch
            | ModelError::OutOfDomain(_)
            | ModelError::InvalidInput(_)
            | ModelError::InvalidQuaternion(_)
            | ModelError::OutsideDem
            | ModelError::DegenerateState
            | ModelError::SatelliteNotAboveGround => Fault::OutOfRange,
        }
    }
}

/// One counter per fault, saturating.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    counts: [u32; Fault::COUNT],
}

impl Counters {
    // `f as usize` < COUNT for every `Fault`; `get` keeps the optimiser from needing to
    // know it (no panic path, docs/no-panic.md).
    pub fn count(&mut self, f: Fault) {
        if let Some(c) = self.counts.get_mut(f as usize) {
            *c = c.saturating_add(1);
        }
    }
    pub fn get(&self, f: Fault) -> u32 {
        self.counts.get(f as usize).copied().unwrap_or(0)
    }
    // Out of line: its fold over every counter is unrolled, and the firmware's loop
    // called it from two places (docs/target.md, flash).
    #[inline(never)]
    pub fn total(&self) -> u32 {
        self.counts.iter().fold(0u32, |a, &c| a.saturating_add(c))
    }
    pub fn as_array(&self) -> &[u32; Fault::COUNT] {
        &self.counts
    }
}

/// Why the core last started, as STATUS reports it (its byte 2; 0: not reported).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum ResetCause {
    /// Power-on, or a retained record that did not check out.
    PowerOn = 1,
    /// The watchdog: the main loop stopped making progress.
    Watchdog = 2,
    /// The firmware asked for it without noting why.
    Software = 3,
    /// A reset the firmware did not see coming and the board cannot name (the reset
    /// pin, a debugger).
    Unknown = 4,
    /// The stack ran into its guard.
    StackOverflow = 5,
    /// Any other HardFault.
    Fault = 6,
}

impl ResetCause {
    pub const ALL: [ResetCause; 6] = [
        ResetCause::PowerOn,
        ResetCause::Watchdog,
        ResetCause::Software,
        ResetCause::Unknown,
        ResetCause::StackOverflow,
        ResetCause::Fault,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ResetCause::PowerOn => "power-on",
            ResetCause::Watchdog => "watchdog",
            ResetCause::Software => "software",
            ResetCause::Unknown => "unknown",
            ResetCause::StackOverflow => "stack overflow",
            ResetCause::Fault => "hard fault",
        }
    }

    /// The cause of wire value `code` (None for 0, "not reported", and unknown values).
    pub fn from_u8(code: u8) -> Option<ResetCause> {
        ResetCause::ALL.into_iter().find(|c| *c as u8 == code)
    }
}

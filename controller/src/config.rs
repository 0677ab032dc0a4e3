//! The controller's configuration and the fixed limits it works within: the Earth model
//! ([`EARTH`], [`EARTH_RATE_RAD_S`]), the settings a host chooses ([`Config`]) and the
//! largest time tag the clock takes ([`MAX_TIME_TAG_US`]). Everything else in the crate
//! reads these; this module reads nothing of the crate.

use core_math::Ellipsoid;

/// The Earth of the model: WGS 84, a = 6 378 137 m, f = 1/298.257223563.
pub const EARTH: Ellipsoid = Ellipsoid::WGS84;
/// The Earth's rotation rate (rad/s): 7.292 115 9e-5 (IERS), core-math's.
pub const EARTH_RATE_RAD_S: f64 = core_math::EARTH_RATE_RAD_S;

/// How a star tracker's quaternion is blended with the attitude the gyros carried from
/// the last one (`crate::track`; docs/controller.md, "The attitude between frames"): a complementary
/// filter. Each new quaternion q_k is compared with the last estimate turned at its body
/// rates and acceleration to t_k; the estimate moves by `gain` of the difference. The
/// star tracker's noise (white, sigma per axis) leaves sigma sqrt(gain / (2 - gain)) in
/// the estimate: 0.18 sigma at 1/16. A difference above `gate_rad` (a turn the gyros did
/// not see), a gap above `max_gap_us` or `gain` 1 take the quaternion as it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeBlend {
    pub gain: f32,
    pub gate_rad: f32,
    pub max_gap_us: u64,
}

/// Controller settings (defaults: `Config::default()`; rationale in docs/controller.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Time between updates (us). Default 20 ms (docs/controller.md, "The update rate").
    pub update_period_us: u64,
    /// No valid NAV frame for longer than this (us) is a [`Fault::Stale`](crate::Fault::Stale) and stops
    /// updates. It is also how far ahead a NAV frame's attitude is propagated when it
    /// is checked against the scene's envelope.
    pub stale_after_us: u64,
    /// A GNSS fix older than this (us) at an update is stale, as NAV after
    /// `stale_after_us`; also the oldest time of fix a GNSS frame may carry. Two
    /// seconds: one fix of a 1 Hz receiver may be lost.
    pub gnss_stale_after_us: u64,
    /// Largest step (us) a time tag may take ahead of the controller's clock. A tag
    /// further ahead is refused ([`Fault::TimeJump`](crate::Fault::TimeJump)) unless the next frame confirms
    /// the new time line (a re-synchronisation, docs/telemetry.md "Time").
    pub max_time_jump_us: u64,
    /// The mission's altitude band above the ellipsoid (m): NAV frames whose |r| is
    /// outside b + low ..= a + high are refused, and scenes are planned and the period
    /// guard set for it.
    pub altitude_range_m: (f64, f64),
    /// How the star tracker's quaternion is blended with the gyros' propagation.
    /// Default gain 1/16, gate 3e-4 rad (15 sigma of a 4-arcsecond star tracker),
    /// largest gap 0.5 s; [`AttitudeBlend::NONE`] for a bus that sends a filtered
    /// attitude.
    pub attitude_blend: AttitudeBlend,
    /// Evaluates the sample pixels in fixed point (`core_math::EARTH_FIXED`, integers
    /// only) instead of the f32 row form: for a core without an FPU. Off by default;
    /// the mps2-an385 firmware turns it on (docs/controller.md, "Backends").
    #[cfg(feature = "earth-fixed")]
    pub fixed_point_pixels: bool,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            update_period_us: 20_000,
            stale_after_us: 1_000_000,
            gnss_stale_after_us: 2_000_000,
            max_time_jump_us: 5_000_000,
            altitude_range_m: (500e3, 800e3),
            attitude_blend: AttitudeBlend {
                gain: 0.0625,
                gate_rad: 3e-4,
                max_gap_us: 500_000,
            },
            #[cfg(feature = "earth-fixed")]
            fixed_point_pixels: false,
        }
    }
}

/// Largest time tag the clock takes (us, 2^53: 285 years). Up to it every tag is exact
/// in f64, and the schedule's sums cannot overflow.
pub const MAX_TIME_TAG_US: u64 = 1 << 53;

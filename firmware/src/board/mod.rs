//! The board layer: what the application needs from a board, as traits, and the one
//! board module the cargo feature selects (docs/target.md, "Boards").
//!
//! A board hands the application three things ([`Parts`]):
//! - the telemetry link: an `embedded-hal-nb` serial port of bytes that can also sleep
//!   until a byte may have arrived ([`crate::link::Link`]);
//! - segment 0's line clock: a timer's reload register
//!   ([`crate::line_clock::ReloadRegister`], the project's own trait: embedded-hal 1.0
//!   has no timer traits);
//! - time: a [`Monotonic`] microsecond count;
//! - a [`Watchdog`], started, that the loop feeds while it makes progress, and the
//!   reset cause the board's reset controller reports, if it keeps one.
//!
//! Each board module builds these from its hardware and exports the same names: `NAME`,
//! `LINK`, `take()` and the `Link`, `LineClock` and `Clock` types. The controller, the
//! session and the telemetry loop see only the traits. No hardware address appears
//! outside the board modules.
//!
//! | feature | module | link | line clock | clock | watchdog |
//! |---|---|---|---|---|---|
//! | `mps2-an386` (default) | [`mps2`] on [`cmsdk`] | CMSDK UART0 | CMSDK TIMER0 RELOAD | CMSDK TIMER1 | CMSDK APB watchdog |
//! | `mps2-an385` (Cortex-M3, no FPU) | [`mps2`] on [`cmsdk`] | CMSDK UART0 | CMSDK TIMER0 RELOAD | CMSDK TIMER1 | CMSDK APB watchdog |
//! | `stm32f405` | `stm32f405` (stm32f4xx-hal) | USART1 | TIM2 ARR | TIM5 (1 MHz) | IWDG |

#[cfg(any(
    all(feature = "mps2-an386", feature = "stm32f405"),
    all(feature = "mps2-an386", feature = "mps2-an385"),
    all(feature = "mps2-an385", feature = "stm32f405"),
))]
compile_error!(
    "two boards selected: build with `--no-default-features --features <board>` for a board other than the default"
);
#[cfg(not(any(feature = "mps2-an386", feature = "mps2-an385", feature = "stm32f405")))]
compile_error!("no board selected: enable the feature `mps2-an386`, `mps2-an385` or `stm32f405`");

// The CMSDK APB UART, timer and watchdog: every board built on the CMSDK shares them.
#[cfg(any(feature = "mps2-an386", feature = "mps2-an385"))]
pub mod cmsdk;
// The two MPS2 FPGA images differ in their core only (M4F, M3): one module serves both.
#[cfg(any(feature = "mps2-an386", feature = "mps2-an385"))]
pub mod mps2;
#[cfg(any(feature = "mps2-an386", feature = "mps2-an385"))]
pub use mps2::{take, Clock, LineClock, Link, Watchdog as BoardWatchdog, LINK, NAME};

#[cfg(feature = "stm32f405")]
pub mod stm32f405;
#[cfg(feature = "stm32f405")]
pub use stm32f405::{take, Clock, LineClock, Link, Watchdog as BoardWatchdog, LINK, NAME};

/// The controller's configuration on this board: the default, with the sample pixels in
/// fixed point where the core has no FPU (the mps2-an385: docs/controller.md,
/// "Backends").
pub fn controller_config() -> controller::Config {
    controller::Config {
        #[cfg(feature = "mps2-an385")]
        fixed_point_pixels: true,
        ..controller::Config::default()
    }
}

/// The telemetry link's speed (baud), 8N1: the ground link's, the same on every board
/// (QEMU ignores it).
pub const LINK_BAUD: u32 = 115_200;

/// A monotonic time source: microseconds since the board was brought up.
pub trait Monotonic {
    /// Never decreases (between two calls less than one wrap of the board's counter
    /// apart: see each board's `Clock`).
    fn now_us(&mut self) -> u64;
}

/// How long the main loop may go without progress before the watchdog resets the core
/// (ms). Long beside the loop's longest step (an update and its PERIODS frame: well
/// under a millisecond on either core) and beside a host's scheduling gaps under QEMU,
/// whose watchdog runs on the virtual clock; short beside the seconds a camera can go
/// without new line periods (docs/target.md, "Faults and resets").
pub const WATCHDOG_TIMEOUT_MS: u32 = 2_000;

/// How often the core wakes from its sleep even when no byte arrives (ms): the loop
/// then goes round once and feeds the watchdog, so that a quiet link is not taken for a
/// hung loop. (SysTick's 24-bit counter holds it up to a 335 MHz core clock.)
pub const HEARTBEAT_MS: u32 = 50;

/// A started watchdog.
pub trait Watchdog {
    /// Restarts the countdown: call only when the main loop has made progress.
    fn feed(&mut self);
}

/// What a board hands the application.
pub struct Parts<L, C, M, W> {
    pub link: L,
    pub line_clock: C,
    pub clock: M,
    /// The watchdog, started with [`WATCHDOG_TIMEOUT_MS`].
    pub watchdog: W,
    /// Why the core started, as the board's reset controller reports it (None where it
    /// keeps no flags: then the record in retained RAM tells, `crate::retained`).
    pub reset_cause: Option<crate::retained::ResetCause>,
    /// The core clock (Hz), which the heartbeat (SysTick) counts.
    pub core_clock_hz: u32,
    /// The frequency segment 0's timer counts at (Hz). On QEMU neither board can count
    /// at the scene's 10 MHz line clock: the reload register path is real, the rate is
    /// not (docs/target.md).
    pub timer_clock_hz: u32,
}

/// Why a board could not be brought up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoardError {
    /// The peripherals were already taken (`take` called twice).
    Taken,
    /// The HAL refused the serial port's configuration (baud rate out of reach).
    SerialConfig,
    /// The HAL refused a timer's configuration.
    TimerConfig,
}

impl defmt::Format for BoardError {
    fn format(&self, f: defmt::Formatter<'_>) {
        let what = match self {
            BoardError::Taken => "peripherals already taken",
            BoardError::SerialConfig => "serial port configuration refused",
            BoardError::TimerConfig => "timer configuration refused",
        };
        defmt::write!(f, "{=str}", what);
    }
}

/// A free-running counter's readings extended to a 64-bit count, for a [`Monotonic`]:
/// the counter wraps every `modulus` ticks, and each reading adds the ticks since the
/// previous one (so readings must come less than one wrap apart).
pub struct Extended {
    modulus: u64,
    last: u32,
    total: u64,
}

impl Extended {
    /// A counter wrapping after `modulus` ticks (2^32 for a full 32-bit counter), whose
    /// current reading is `now`.
    pub const fn new(modulus: u64, now: u32) -> Extended {
        Extended {
            modulus,
            last: now,
            total: 0,
        }
    }

    /// Ticks since `new`, given the counter's reading `now`.
    pub fn update(&mut self, now: u32) -> u64 {
        let (now64, last64) = (u64::from(now), u64::from(self.last));
        let elapsed = if now64 >= last64 {
            now64 - last64
        } else {
            // Wrapped once: up to the modulus, then from zero.
            self.modulus.saturating_sub(last64).saturating_add(now64)
        };
        self.last = now;
        self.total = self.total.saturating_add(elapsed);
        self.total
    }
}

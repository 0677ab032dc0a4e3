//! Flight firmware of the TDI push-broom camera.
//!
//! The firmware (`src/main.rs`) is the telemetry-driven line-rate controller, one
//! module per step of the story:
//! - telemetry in: [`link`] (an `embedded-hal-nb` serial port, byte by byte, never
//!   waiting; whole frames out) and [`telemetry`] (the loop: bytes through the
//!   `controller` crate's `Session`, frames back out); the UART's interrupts serve the
//!   receive queue ([`rx`]) and the transmit queue ([`tx`]);
//! - scene and math: the `controller` crate (the scene in force, its plan, the updates,
//!   on core-math's real-Earth general form in f32, `GENERAL_F32`; on the Cortex-M3,
//!   feature `mps2-an385`, the pixels in fixed point, `EARTH_FIXED`, and most of the
//!   update in integers); no hardware in it;
//! - line periods out: [`line_clock`] (the `controller::LinePeriodSink`: segment 0's
//!   period into a timer's reload register, the others into a table) and the PERIODS
//!   frames the session sends;
//! - the hardware behind those traits: [`board`], one module per board, chosen by cargo
//!   feature (`mps2-an386`, the default; `mps2-an385`; `stm32f405`); no hardware
//!   address outside it;
//! - [`retained`]: what survives a reset (its cause and count, the controller's
//!   snapshot, the DEM tile memory); [`irq`]: the state an interrupt handler owns;
//!   [`heartbeat`]: the periodic wake-up that lets the loop feed the board's watchdog
//!   while the link is quiet;
//! - [`platform`]: panic/fault handlers, exit by semihosting; `logger`: the global
//!   defmt logger (semihosting, never panics; `defmt-rtt` replaces it on a real board);
//!   [`stack`]: the stack's high-water mark (the firmware's RAM use).
//!
//! The default-scene demo (`src/bin/demo.rs`, `cargo xtask run --demo`) and the
//! benchmark run the same controller without a link: [`synthetic`] primes it with one
//! NAV frame.
//!
//! No function here panics: every refusal is a `Result` (no `unwrap`, `expect` or
//! indexing that can fail).
#![no_std]

pub mod board;
pub mod heartbeat;
pub mod irq;
pub mod line_clock;
pub mod link;
#[cfg(not(feature = "defmt-rtt"))]
pub mod logger;
pub mod platform;
pub mod retained;
pub mod rx;
pub mod stack;
pub mod synthetic;
pub mod telemetry;
pub mod tx;

use core_math::ModelError;

/// Why the firmware could not produce line periods.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FirmwareError {
    /// The model refused an input or a geometry.
    Model(ModelError),
    /// The controller refused the scene or its plan (a layout it cannot sample).
    Layout,
    /// The synthetic NAV frame was not accepted, or no update ran.
    Telemetry,
}

impl From<ModelError> for FirmwareError {
    fn from(e: ModelError) -> Self {
        FirmwareError::Model(e)
    }
}

impl defmt::Format for FirmwareError {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            FirmwareError::Model(e) => defmt::write!(f, "model error: {=str}", e.name()),
            FirmwareError::Layout => defmt::write!(f, "detector layout error"),
            FirmwareError::Telemetry => defmt::write!(f, "telemetry error"),
        }
    }
}

//! Flight firmware of the TDI push-broom camera.
//!
//! The firmware (`src/main.rs`) is the telemetry-driven line-rate controller, one
//! module per step of the story:
//! - telemetry in: [`link`] (the [`link::ByteLink`] trait: a UART, byte by byte, never
//!   waiting) and [`telemetry`] (the loop: bytes through the `controller` crate's
//!   `Session`, frames back out);
//! - scene and math: the `controller` crate (the scene in force, its plan, the updates,
//!   on core-math's `CLOSED_F32`); no hardware in it;
//! - line periods out: [`line_clock`] (the `controller::LinePeriodSink`: segment 0's
//!   period into a timer's reload register, the others into a table) and the PERIODS
//!   frames the session sends;
//! - the hardware behind those traits: [`cmsdk`] (the mps2-an386's UART0 and TIMER0);
//! - [`platform`]: panic/fault handlers, exit by semihosting; [`logger`]: the global
//!   defmt logger (semihosting, never panics);
//!   [`stack`]: the stack's high-water mark (the firmware's RAM use).
//!
//! The default-scene demo (`src/bin/demo.rs`, `cargo xtask run --demo`) and the
//! benchmark use the older one-shot pipeline, no telemetry:
//! - [`scene`]: the built-in default scene ([`scene::SceneSource`], [`scene::NoTelemetry`]);
//! - [`pipeline`]: boot-time pixel constants per sample point
//!   ([`core_math::Backend::pixel`]), then one [`core_math::Backend::update`] and per
//!   sample point one [`core_math::Backend::motion`] plus the line period;
//! - [`output`]: defmt log lines.
//!
//! No function here panics: every refusal is a `Result` (no `unwrap`, `expect` or
//! indexing that can fail).
#![no_std]

pub mod cmsdk;
pub mod line_clock;
pub mod link;
pub mod logger;
pub mod output;
pub mod pipeline;
pub mod platform;
pub mod scene;
pub mod stack;
pub mod telemetry;

use core_math::ModelError;

/// Why the firmware could not produce line periods.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FirmwareError {
    /// The model refused an input or a geometry.
    Model(ModelError),
    /// The detector layout cannot be sampled (no segments, too many, or pixel
    /// offsets out of range).
    Layout,
    /// The scene source failed (no telemetry controller yet: never today).
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

/// One pass of the application: take a scene, compute every segment's line period,
/// hand the results to the output.
pub fn run<S: scene::SceneSource>(source: &mut S) -> Result<(), FirmwareError> {
    let scene = source.scene()?;
    output::log_scene(&scene);
    let plan = pipeline::Plan::new(&scene)?;
    let update = plan.update(&scene.geometry)?;
    for segment in plan.segments() {
        let report = plan.segment_report(&update, segment)?;
        output::log_segment(&report);
    }
    Ok(())
}

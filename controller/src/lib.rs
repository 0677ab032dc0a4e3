//! The line-rate controller of a TDI push-broom camera: telemetry frames in, the imaging
//! scene and its plan, per-segment TDI line periods out. `no_std`, no allocation, no
//! hardware: the firmware feeds it bytes and a clock, and gives it a [`LinePeriodSink`].
//!
//! telemetry in ([`frame`], [`nav`], the bus's own frames: [`bus`]) -> frames to state ([`intake`]; the scene and its
//! plan: [`scene`], [`plan`]) -> the controller's state ([`control`], its settings in
//! [`config`]) -> state to periods (the bus's data carried to the instant: [`track`]; [`update`]: core-math's general real-Earth form) ->
//! line periods out ([`sink`], [`report`]; whole frames into the transmit queue:
//! [`downlink`]).
//!
//! Start reading at [`session`], the loop around a byte link that the firmware and the
//! host tools share. Around the steps: [`fault`] (every refusal typed and counted),
//! [`restart`] (what a reset must not lose), the DEM tile ([`dem`]) and each sample's
//! ground on it ([`dem_ground`]), and the f64 reference of an update (`golden`, feature
//! `reference`). Layout and module graph: `docs/controller.md`.
#![no_std]
#![forbid(unsafe_code)]
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bus;
pub mod bytes;
pub mod config;
pub mod control;
pub mod crc;
pub mod dem;
pub mod dem_ground;
pub mod downlink;
pub mod fault;
pub mod frame;
#[cfg(feature = "reference")]
pub mod golden;
pub mod intake;
pub mod nav;
pub mod plan;
pub mod report;
pub mod restart;
pub mod scene;
pub mod session;
pub mod sink;
pub mod track;
pub mod update;

pub use config::{AttitudeBlend, Config, EARTH};
pub use control::{Controller, Mode, SegmentOutput};
pub use fault::{Counters, Fault};
pub use frame::{Decoder, Event, Frame, FrameError};
pub use scene::{Scene, Terrain};
pub use sink::LinePeriodSink;

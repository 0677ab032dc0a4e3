//! The default-scene demo (`cargo xtask run --demo`): the line-rate controller on the
//! built-in scene (`controller::Scene::paper_default`: 10 segments of 6 000 pixels, 16
//! TDI stages, a 10 MHz line clock) with one synthetic NAV frame at 20 deg of roll and
//! 10 deg of pitch, no UART; one update, every segment's line period logged, exit by
//! semihosting (0, or 1 on an error).
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::synthetic::{controller_with_nav, NoRegisters};
use firmware::{platform, FirmwareError};

/// The demo's attitude (deg).
const ROLL_DEG: f32 = 20.0;
const PITCH_DEG: f32 = 10.0;

fn run() -> Result<(), FirmwareError> {
    let scene = controller::Scene::paper_default();
    let attitude = controller::nav::Attitude {
        roll_rad: ROLL_DEG.to_radians(),
        pitch_rad: PITCH_DEG.to_radians(),
        ..Default::default()
    };
    let mut c = controller_with_nav(scene, false, attitude)?;
    if !c.advance(1_000_000, &mut NoRegisters) {
        return Err(FirmwareError::Telemetry);
    }
    defmt::info!(
        "default scene, roll {=f32} deg, pitch {=f32} deg: {=usize} segments, line clock {=f32} MHz, yaw request {=f32} mrad",
        ROLL_DEG,
        PITCH_DEG,
        c.plan().active().len(),
        c.plan().line_clock_hz * 1e-6,
        c.yaw_request_rad().unwrap_or(f32::NAN) * 1e3
    );
    let us_per_tick = 1e6 / c.plan().line_clock_hz;
    for o in c.outputs() {
        defmt::info!(
            "segment {=u8}: line period {=u32} ticks = {=f32} us, worst mismatch {=f32}, MTF {=f32}, max stages {=u16}, drift {=f32} mrad (worst {=f32}, after yaw steering {=f32})",
            o.index,
            o.ticks,
            o.ticks as f32 * us_per_tick,
            o.worst_mismatch,
            o.mtf,
            o.max_stages,
            o.drift_rad * 1e3,
            o.worst_drift_rad * 1e3,
            o.residual_drift_rad * 1e3
        );
    }
    Ok(())
}

#[entry]
fn main() -> ! {
    defmt::info!(
        "tdi-camera firmware {=str} (demo)",
        env!("CARGO_PKG_VERSION")
    );
    let code = match run() {
        Ok(()) => 0,
        Err(e) => {
            defmt::error!("{}", e);
            1
        }
    };
    platform::exit(code)
}

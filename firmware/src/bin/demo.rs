//! The default-scene demo (`cargo xtask run --demo`): the line-rate controller on the
//! built-in scene (`controller::Scene::paper_default`: 10 segments of 6 000 pixels, 16
//! TDI stages, a 10 MHz line clock) with one synthetic NAV frame at the paper's 25 deg
//! roll, no UART; one update, every segment's line period logged, exit by semihosting
//! (0, or 1 on an error).
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::synthetic::{controller_with_nav, NoRegisters};
use firmware::{platform, FirmwareError};

/// The paper's roll (deg).
const ROLL_DEG: f32 = 25.0;

fn run() -> Result<(), FirmwareError> {
    let scene = controller::Scene::paper_default();
    let mut c = controller_with_nav(scene, false, ROLL_DEG.to_radians())?;
    if !c.advance(1_000_000, &mut NoRegisters) {
        return Err(FirmwareError::Telemetry);
    }
    defmt::info!(
        "default scene, roll {=f32} deg: {=u8} segments, line clock {=f32} MHz",
        ROLL_DEG,
        c.plan().count,
        c.plan().line_clock_hz * 1e-6
    );
    let us_per_tick = 1e6 / c.plan().line_clock_hz;
    for o in c.outputs() {
        defmt::info!(
            "segment {=u8}: line period {=u32} ticks = {=f32} us, worst mismatch {=f32}, MTF {=f32}, max stages {=u16}, drift {=f32} mrad",
            o.index,
            o.ticks,
            o.ticks as f32 * us_per_tick,
            o.worst_mismatch,
            o.mtf,
            o.max_stages,
            o.drift_rad * 1e3
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

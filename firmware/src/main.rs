//! Firmware entry point: the telemetry-driven line-rate controller.
//!
//! telemetry in (UART0, [`firmware::telemetry`]) -> scene and math (the `controller`
//! crate on core-math) -> line periods out ([`firmware::line_clock`]: TIMER0 RELOAD for
//! segment 0, PERIODS frames to the ground). Runs until the link sends END, then exits
//! by semihosting (status 0; 1 if the controller could not start).
#![no_std]
#![no_main]

use controller::{Config, Controller, Scene};
use cortex_m_rt::entry;
use firmware::cmsdk::{Timer, Uart};
use firmware::line_clock::LineClocks;
use firmware::{platform, stack, telemetry};

/// Telemetry link speed (QEMU ignores it; a board's ground-support link would use it).
const BAUD: u32 = 115_200;

#[entry]
fn main() -> ! {
    let painted = stack::paint();
    defmt::info!(
        "tdi-camera firmware {=str}: line-rate controller on UART0",
        env!("CARGO_PKG_VERSION")
    );
    // SAFETY: `main` runs once and is the only user of UART0 and TIMER0.
    let (mut uart, timer) = unsafe { (Uart::uart0(BAUD), Timer::timer0()) };
    let mut clocks = LineClocks::new(timer);
    let code = match Controller::new(Config::default(), Scene::paper_default()) {
        Ok(controller) => {
            let summary = telemetry::run(&mut uart, &mut clocks, controller);
            if summary.tx_dropped == 0 && clocks.errors == 0 {
                0
            } else {
                defmt::error!(
                    "{=u32} downlink frames dropped, {=u32} line clock writes refused",
                    summary.tx_dropped,
                    clocks.errors
                );
                2
            }
        }
        Err(f) => {
            defmt::error!("the default scene was refused: {=str}", f.name());
            1
        }
    };
    defmt::info!(
        "stack high-water mark: {=usize} bytes (controller state {=usize} bytes)",
        painted.peak(),
        core::mem::size_of::<controller::session::Session>()
    );
    platform::exit(code)
}

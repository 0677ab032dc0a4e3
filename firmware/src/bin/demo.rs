//! The default-scene demo (`cargo xtask run --demo`): one evaluation of the built-in
//! scene with no telemetry, every sample point logged, exit by semihosting.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::{platform, scene::NoTelemetry};

#[entry]
fn main() -> ! {
    defmt::info!(
        "tdi-camera firmware {=str} (demo)",
        env!("CARGO_PKG_VERSION")
    );
    let code = match firmware::run(&mut NoTelemetry) {
        Ok(()) => 0,
        Err(e) => {
            defmt::error!("{}", e);
            1
        }
    };
    platform::exit(code)
}

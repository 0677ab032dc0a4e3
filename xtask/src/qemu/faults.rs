//! The faults test (`cargo xtask test`): the firmware's `faults` binary stops feeding the
//! watchdog, then overflows its stack, on purpose; on a machine whose watchdog, MPU and
//! system reset QEMU models, each must reset the core and the next boot must find the
//! cause in retained RAM (docs/target.md, "Faults and resets").

use anyhow::{bail, Result};

use super::board::Board;
use super::build_firmware;
use super::runner::{run_elf, Options};

/// Runs the `faults` binary on `board` and checks both resets and the recovery. Only the
/// MPS2's watchdog (mps2-an386 and mps2-an385) is modelled by QEMU 7.2 (the STM32F405's
/// IWDG is not: there the binary would hang until the runner's time limit).
pub fn faults_test(board: Board) -> Result<()> {
    if !matches!(board, Board::Mps2An386 | Board::Mps2An385) {
        bail!(
            "QEMU does not model the {}'s watchdog: the faults test runs on the MPS2 boards",
            board.name()
        );
    }
    let elf = build_firmware(board, "faults", true, &[], &[])?;
    let options = Options {
        capture: true,
        ..Options::default()
    };
    let outcome = run_elf(&elf, &options)?;
    let boots: Vec<&String> = outcome
        .messages
        .iter()
        .filter(|m| m.starts_with("boot: "))
        .collect();
    let expected = [
        "boot: reset cause power-on, 0 resets since power-on",
        "boot: reset cause watchdog, 1 resets since power-on",
        "boot: reset cause stack overflow, 2 resets since power-on",
    ];
    if outcome.status != 0 || boots != expected {
        bail!(
            "faults test on {}: exit status {} (0 expected), boot lines {boots:?}, expected {expected:?}",
            board.name(),
            outcome.status
        );
    }
    eprintln!(
        "xtask: faults test passed on {}: a hang reset by the watchdog, a stack overflow stopped by its guard, each cause found after its reset",
        board.name()
    );
    Ok(())
}

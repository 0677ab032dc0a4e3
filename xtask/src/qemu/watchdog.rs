//! The watchdog test (`cargo xtask test`): the firmware's `hang` binary stops feeding
//! the watchdog on purpose; on a machine whose watchdog QEMU models, the core must be
//! reset and the next boot must find the cause in retained RAM (docs/target.md,
//! "Faults and resets").

use anyhow::{bail, Result};

use super::board::Board;
use super::build_firmware;
use super::runner::{run_elf, Options};

/// Runs the `hang` binary on `board` and checks the reset and the recovery. Only the
/// mps2-an386's watchdog is modelled by QEMU 7.2 (the STM32F405's IWDG is not: there
/// the binary would hang until the runner's time limit).
pub fn watchdog_test(board: Board) -> Result<()> {
    if board != Board::Mps2An386 {
        bail!(
            "QEMU does not model the {}'s watchdog: the hang test runs on the mps2-an386",
            board.name()
        );
    }
    let elf = build_firmware(board, "hang", true, &[], &[])?;
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
    ];
    if outcome.status != 0 || boots != expected {
        bail!(
            "watchdog test on {}: exit status {} (0 expected), boot lines {boots:?}, expected {expected:?}",
            board.name(),
            outcome.status
        );
    }
    eprintln!(
        "xtask: watchdog test passed on {}: the hung build was reset by the watchdog and found the cause after the reset",
        board.name()
    );
    Ok(())
}

//! `cargo xtask flash`: a firmware binary on a real board through a debug probe, with
//! probe-rs (docs/target.md, "A real board"). Nothing here has run against hardware yet:
//! it builds what a board needs (the board's feature and the RTT logger) and hands the
//! ELF to `probe-rs run`, which flashes it, prints the defmt log from RTT and exits with
//! the firmware's semihosting exit status.

use anyhow::{anyhow, bail, Context, Result};
use std::process::Command;

use super::board::Board;
use super::{build_firmware, exit_like, tools};

/// `cargo xtask flash`'s options.
#[derive(clap::Args)]
pub struct FlashArgs {
    /// The board (the one with a real part, the STM32F405, by default)
    #[arg(long, value_enum, default_value_t = Board::Stm32f405)]
    board: Board,
    /// The binary to flash
    #[arg(long, value_enum, default_value_t = Bin::Firmware)]
    bin: Bin,
    /// The dev profile instead of release
    #[arg(long)]
    debug: bool,
    /// Build, then print the probe-rs command instead of running it
    #[arg(long)]
    print_command: bool,
}

/// The firmware binaries a board can run.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Bin {
    /// The flight binary
    Firmware,
    /// The default-scene demo
    Demo,
}

/// `cargo xtask flash`: build for the board with its RTT logger, then `probe-rs run`.
pub fn flash(args: &FlashArgs) -> Result<()> {
    let board = args.board;
    let bin = match args.bin {
        Bin::Firmware => "firmware",
        Bin::Demo => "demo",
    };
    let release = !args.debug;
    let print_only = args.print_command;
    let chip = board.probe_rs_chip().ok_or_else(|| {
        anyhow!(
            "flash: the {} exists only in QEMU: `cargo xtask run --board {}`",
            board.name(),
            board.name()
        )
    })?;
    super::ensure_target_tools()?;
    let elf = build_firmware(board, bin, release, &["defmt-rtt"], &[])?;
    let probe_rs_args = ["run", "--chip", chip];
    let shown = format!("probe-rs {} {}", probe_rs_args.join(" "), elf.display());
    if print_only {
        println!("{shown}");
        return Ok(());
    }
    if !tools::have("probe-rs") {
        bail!(
            "flash: probe-rs is not installed: `cargo install probe-rs-tools --locked` (about ten minutes), then connect the probe and rerun; the command will be\n  {shown}"
        );
    }
    eprintln!("xtask: {shown}");
    let status = Command::new("probe-rs")
        .args(probe_rs_args)
        .arg(&elf)
        .status()
        .context("cannot start probe-rs")?;
    exit_like(status.code().unwrap_or(1))
}

//! `cargo xtask flash`: a firmware binary on a real board through a debug probe, with
//! probe-rs (docs/target.md, "A real board"). Nothing here has run against hardware yet:
//! it builds what a board needs (the board's feature and the RTT logger) and hands the
//! ELF to `probe-rs run`, which flashes it, prints the defmt log from RTT and exits with
//! the firmware's semihosting exit status.

use std::process::Command;

use super::board::{take_board_arg, Board};
use super::{build_board_bin, exit_like, tools};

const USAGE: &str =
    "usage: flash [--board stm32f405] [--bin firmware|demo] [--debug] [--print-command]";

/// `cargo xtask flash [--board NAME] [--bin firmware|demo] [--debug] [--print-command]`.
/// The board defaults to the one with a real part (the STM32F405); `--print-command`
/// builds and prints the probe-rs command instead of running it.
pub fn flash(args: &[String]) -> Result<(), String> {
    let mut args = args.to_vec();
    if !args.iter().any(|a| a == "--board") {
        args.extend(["--board".into(), Board::Stm32f405.name().into()]);
    }
    let (board, rest) = take_board_arg(&args).map_err(|e| format!("flash: {e}"))?;
    let mut bin = "firmware";
    let mut release = true;
    let mut print_only = false;
    let mut it = rest.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--bin" => {
                bin = match it.next().map(String::as_str) {
                    Some("firmware") => "firmware",
                    Some("demo") => "demo",
                    _ => return Err(format!("flash: --bin takes firmware or demo ({USAGE})")),
                }
            }
            "--debug" => release = false,
            "--print-command" => print_only = true,
            other => return Err(format!("flash: unknown argument `{other}` ({USAGE})")),
        }
    }
    let chip = board.probe_rs_chip().ok_or_else(|| {
        format!(
            "flash: the {} exists only in QEMU: `cargo xtask run --board {}`",
            board.name(),
            board.name()
        )
    })?;
    super::ensure_target_tools()?;
    let elf = build_board_bin(board, "firmware", bin, release, &["defmt-rtt"])?;
    let probe_rs_args = ["run", "--chip", chip];
    let shown = format!("probe-rs {} {}", probe_rs_args.join(" "), elf.display());
    if print_only {
        println!("{shown}");
        return Ok(());
    }
    if !tools::have("probe-rs") {
        return Err(format!(
            "flash: probe-rs is not installed: `cargo install probe-rs-tools --locked` (about ten minutes), then connect the probe and rerun; the command will be\n  {shown}"
        ));
    }
    eprintln!("xtask: {shown}");
    let status = Command::new("probe-rs")
        .args(probe_rs_args)
        .arg(&elf)
        .status()
        .map_err(|e| format!("cannot start probe-rs: {e}"))?;
    exit_like(status.code().unwrap_or(1))
}

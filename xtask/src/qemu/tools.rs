//! Making sure the target toolchain and QEMU are there, installing them where we can.

use anyhow::{anyhow, bail, Context, Result};
use std::process::{Command, Stdio};

use super::board::Board;
use super::TARGET;

/// The Rust target (rustup) and qemu-system-arm with every board's machine. Installs
/// the target with rustup and QEMU with apt-get when running as root; otherwise an
/// error that says what to install.
pub fn ensure_target_tools() -> Result<()> {
    ensure_rust_target(TARGET)?;
    // The fixed-point backend must build for FPU-less cores (docs/fixed-point.md).
    ensure_rust_target(super::NO_FPU_TARGET)?;
    ensure_qemu()
}

/// A Rust target through rustup (or a toolchain that already has its core library).
pub fn ensure_rust_target(target: &str) -> Result<()> {
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output();
    match installed {
        Ok(out) if out.status.success() => {
            if String::from_utf8_lossy(&out.stdout)
                .lines()
                .any(|l| l.trim() == target)
            {
                return Ok(());
            }
            eprintln!("xtask: rustup target add {target}");
            status(Command::new("rustup").args(["target", "add", target]))
        }
        _ => {
            // No rustup: accept a toolchain that already has the target's core library.
            let sysroot = Command::new("rustc").args(["--print", "sysroot"]).output();
            let has_core = sysroot.ok().is_some_and(|o| {
                let root = String::from_utf8_lossy(&o.stdout).trim().to_string();
                std::path::Path::new(&root)
                    .join("lib/rustlib")
                    .join(target)
                    .is_dir()
            });
            if has_core {
                Ok(())
            } else {
                Err(anyhow!(
                    "no rustup, and the toolchain lacks {target}: install rustup and run `rustup target add {target}`"
                ))
            }
        }
    }
}

/// Runs `cmd` with inherited output; an error names it (the program's file name and the
/// arguments) and its exit status.
pub fn status(cmd: &mut Command) -> Result<()> {
    let program = std::path::Path::new(cmd.get_program()).file_name();
    let program = program.unwrap_or_default().to_string_lossy().into_owned();
    let line = std::iter::once(program.clone())
        .chain(cmd.get_args().map(|a| a.to_string_lossy().into_owned()))
        .collect::<Vec<_>>()
        .join(" ");
    let status = cmd
        .status()
        .with_context(|| format!("cannot start `{program}`"))?;
    if !status.success() {
        bail!("`{line}` failed ({status})");
    }
    Ok(())
}

/// True when `program --version` runs.
pub(super) fn have(program: &str) -> bool {
    Command::new(program)
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// Installs Debian packages when root, else explains what to install.
pub(super) fn apt_install(packages: &[&str], why: &str) -> Result<()> {
    let list = packages.join(" ");
    if !is_root() || !have("apt-get") {
        bail!(
            "{why} is missing: install it (Debian/Ubuntu: `sudo apt-get install -y {list}`) and retry"
        );
    }
    eprintln!("xtask: {why} is missing; apt-get update && apt-get install -y {list}");
    status(Command::new("apt-get").arg("update"))?;
    status(
        Command::new("apt-get")
            .args(["install", "-y"])
            .args(packages)
            .env("DEBIAN_FRONTEND", "noninteractive"),
    )
}

fn ensure_qemu() -> Result<()> {
    if !have(super::runner::QEMU) {
        apt_install(&["qemu-system-arm"], "qemu-system-arm")?;
    }
    let machines = Command::new(super::runner::QEMU)
        .args(["-machine", "help"])
        .output()
        .with_context(|| format!("cannot run {}", super::runner::QEMU))?;
    let listed = String::from_utf8_lossy(&machines.stdout);
    let missing: Vec<&str> = Board::ALL
        .iter()
        .map(|b| b.qemu_machine())
        .filter(|m| {
            !listed
                .lines()
                .any(|l| l.split_whitespace().next() == Some(*m))
        })
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(anyhow!(
            "{} lacks the machine(s) {}: QEMU 6.0 or newer is needed",
            super::runner::QEMU,
            missing.join(", ")
        ))
    }
}

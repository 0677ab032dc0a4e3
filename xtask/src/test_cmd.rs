//! `cargo xtask test`: every check CI runs, in the order a failure is cheapest to see.

use anyhow::{Context, Result};
use std::process::Command;

use crate::qemu::cargo;

/// Runs a command with inherited output; an error names it and its status.
pub fn run_step(program: &str, args: &[&str]) -> Result<()> {
    eprintln!("\n==> {program} {}", args.join(" "));
    crate::qemu::status(Command::new(program).args(args))
}

pub fn run() -> Result<()> {
    let t0 = std::time::Instant::now();
    cargo(&["fmt", "--all", "--check"])?;
    // The default members are the host crates; the target crates are linted by
    // `qemu::test_target` for thumbv7em.
    cargo(&["clippy", "--all-targets", "--", "-D", "warnings"])?;
    // The API docs of the math, the controller and these tasks, every feature on: a
    // broken or private intra-doc link fails here rather than rotting unseen.
    eprintln!("xtask: cargo doc --no-deps -p core-math -p controller -p xtask --all-features (RUSTDOCFLAGS=-D warnings)");
    crate::qemu::status(
        crate::qemu::cargo_command()
            .args(["doc", "--no-deps", "--all-features"])
            .args(["--package", "core-math", "--package", "controller"])
            .args(["--package", "xtask"])
            .env("RUSTDOCFLAGS", "-D warnings"),
    )?;
    // Host unit, property and golden tests of the math and the controller, optimised
    // since the property tests evaluate the reference chain tens of thousands of times,
    // but without the flight profile's fat LTO (Cargo.toml, `host-test`: it made this
    // build take eight minutes). xtask's own tests in the dev profile, which reuses the
    // dependencies `cargo xtask` was built with.
    cargo(&[
        "test",
        "--profile",
        "host-test",
        "--package",
        "core-math",
        "--package",
        "controller",
    ])?;
    cargo(&["test", "--package", "xtask"])?;
    no_float_check()?;
    derivation_check()?;
    crate::qemu::test_target()?;
    crate::no_panic::check()?;
    no_fpu_elf_check()?;
    crate::qemu::board::check_flash_budgets()?;
    eprintln!(
        "\nxtask test: all checks passed in {:.0} s",
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The real-Earth fixed-point backend's per-pixel function, built for a core without an
/// FPU, has no floating-point instruction and calls nothing (tools/check-no-float.sh;
/// docs/fixed-point.md).
fn no_float_check() -> Result<()> {
    crate::qemu::ensure_rust_target(crate::qemu::NO_FPU_TARGET)?;
    run_step("sh", &["tools/check-no-float.sh"])
}

/// The Cortex-M3's release flight binary holds no instruction of the FPU it lacks; the
/// same scan must find them in the mps2-an386's (tools/check-no-fpu-elf.sh, issue 24).
fn no_fpu_elf_check() -> Result<()> {
    use crate::qemu::{board::Board, build_firmware};
    let m3 = build_firmware(Board::Mps2An385, "firmware", true, &[], &[])?;
    let m4f = build_firmware(Board::Mps2An386, "firmware", true, &[], &[])?;
    let path = |p: &std::path::Path| p.to_string_lossy().into_owned();
    run_step(
        "sh",
        &["tools/check-no-fpu-elf.sh", &path(&m3), &path(&m4f)],
    )
}

/// The computer-algebra proof of the derivation (tools/derivation/derive.py).
fn derivation_check() -> Result<()> {
    let has_sympy = Command::new("python3")
        .args(["-c", "import sympy, mpmath"])
        .output()
        .map(|o| o.status.success())
        .context("python3 is needed for the derivation check")?;
    if !has_sympy {
        run_step(
            "python3",
            &[
                "-m",
                "pip",
                "install",
                "--quiet",
                "-r",
                "tools/derivation/requirements.txt",
            ],
        )?;
    }
    run_step("python3", &["tools/derivation/derive.py"])
}

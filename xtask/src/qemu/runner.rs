//! QEMU as the cargo runner for thumbv7em-none-eabihf and thumbv7m-none-eabi, with the
//! defmt stream decoded on the host (the `defmt-decoder` crate, pinned to 1.2.x in
//! xtask/Cargo.toml).
//!
//! The machine is the one of the board the ELF was linked for (its memory layout names
//! it: [`Board::of_elf`]): `mps2-an386`, `mps2-an385`, or `netduinoplus2` for the
//! STM32F405, so `cargo run`/`cargo test` with any board's features need no other
//! setting.
//!
//! The firmware logs defmt frames to semihosting stdout (`defmt-semihosting`); QEMU
//! writes them to its stdout (`-semihosting-config target=native`), the UART goes
//! nowhere (`-serial none`) or to a chardev of the caller's (`Options::serial`: the
//! pass player's unix socket), never to stdout, so that no other byte mixes in; QEMU's
//! exit status is the firmware's semihosting exit code.

use anyhow::{anyhow, bail, Context, Result};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use defmt_decoder::{DecodeError, Frame, Location, Table};

use super::board::Board;

pub const QEMU: &str = "qemu-system-arm";
/// Wall-clock limit of one QEMU run unless `TDI_QEMU_TIMEOUT_S` says otherwise: a hung
/// firmware fails the command instead of blocking it.
const DEFAULT_TIMEOUT_S: u64 = 300;

/// How to run one ELF.
#[derive(Default)]
pub struct Options {
    /// Extra QEMU arguments (e.g. `-plugin ...`).
    pub extra_args: Vec<String>,
    /// Keep the decoded messages (without level and location) for the caller.
    pub capture: bool,
    /// QEMU's `-serial` for the first UART (the board's telemetry link: UART0 of the
    /// mps2-an386, USART1 of the STM32F405; None: `none`, nothing connected), e.g.
    /// `chardev:ID` with a `-chardev ...,id=ID` in `extra_args`.
    pub serial: Option<String>,
    /// Echo the decoded log to stderr instead of stdout (for commands whose stdout is
    /// data, e.g. `report --csv`).
    pub log_to_stderr: bool,
    /// Told each time the firmware logs [`LINK_READY`]: from then on its link takes
    /// bytes (the STM32F405's USART drops what arrives before it is enabled).
    pub link_ready: Option<std::sync::mpsc::Sender<()>>,
}

/// The words of the flight firmware's first log line that say its link is up
/// (`firmware::telemetry::READY`).
pub const LINK_READY: &str = "telemetry link ready";

/// What a run gave.
pub struct Outcome {
    /// The firmware's exit status.
    pub status: i32,
    /// The decoded messages, when captured.
    pub messages: Vec<String>,
}

/// `cargo xtask qemu ELF [ARGS]`: the runner cargo calls for `cargo run` / `cargo test`
/// on thumbv7em. Exits with the firmware's status.
pub fn qemu(args: &[String]) -> Result<()> {
    let Some((elf, rest)) = args.split_first() else {
        bail!("qemu: usage: qemu ELF (the cargo runner for thumbv7em-none-eabihf)");
    };
    if !rest.is_empty() {
        eprintln!("xtask qemu: ignoring arguments {rest:?} (the firmware takes none)");
    }
    let outcome = run_elf(Path::new(elf), &Options::default())?;
    super::exit_like(outcome.status)
}

/// Runs `elf` under QEMU, prints its decoded defmt log on stdout and returns its exit
/// status.
pub fn run_elf(elf: &Path, options: &Options) -> Result<Outcome> {
    let bytes = std::fs::read(elf).with_context(|| format!("cannot read {}", elf.display()))?;
    let table =
        Table::parse(&bytes).with_context(|| format!("bad defmt table in {}", elf.display()))?;
    let locations = match &table {
        Some(t) => t.get_locations(&bytes).unwrap_or_default(),
        None => BTreeMap::new(),
    };
    let board = Board::of_elf(&bytes).with_context(|| format!("{}", elf.display()))?;

    let mut cmd = Command::new(QEMU);
    cmd.args(["-cpu", board.qemu_cpu(), "-machine", board.qemu_machine()])
        .args(["-nographic", "-monitor", "none"])
        .arg("-serial")
        .arg(options.serial.as_deref().unwrap_or("none"))
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(&options.extra_args)
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    let mut child = cmd.spawn().map_err(|e| {
        anyhow!("cannot start {QEMU} (run `cargo xtask run` once to install it): {e}")
    })?;
    let stdout = child.stdout.take().context("no stdout from QEMU")?;
    let child = Arc::new(Mutex::new(child));
    let watchdog = spawn_watchdog(Arc::clone(&child), timeout());

    let mut printer = Printer {
        locations: &locations,
        root: super::workspace_root(),
        capture: options.capture,
        log_to_stderr: options.log_to_stderr,
        link_ready: options.link_ready.clone(),
        messages: Vec::new(),
    };
    let read = match &table {
        Some(table) => decode_stream(table, stdout, &mut printer),
        None => copy_raw(stdout),
    };
    let timed_out = watchdog.join().unwrap_or(false);
    let status = lock(&child).wait().context("waiting for QEMU")?;
    read?;
    if timed_out {
        bail!(
            "QEMU timed out after {} s and was killed (set TDI_QEMU_TIMEOUT_S to change the limit)",
            timeout().as_secs()
        );
    }
    let status = status
        .code()
        .with_context(|| format!("QEMU ended without an exit code ({status})"))?;
    Ok(Outcome {
        status,
        messages: printer.messages,
    })
}

fn timeout() -> Duration {
    let secs = std::env::var("TDI_QEMU_TIMEOUT_S")
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(DEFAULT_TIMEOUT_S);
    Duration::from_secs(secs)
}

fn lock(child: &Mutex<Child>) -> std::sync::MutexGuard<'_, Child> {
    child
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Kills QEMU after `limit`; returns whether it had to.
fn spawn_watchdog(child: Arc<Mutex<Child>>, limit: Duration) -> std::thread::JoinHandle<bool> {
    std::thread::spawn(move || {
        let start = Instant::now();
        loop {
            {
                let mut c = lock(&child);
                if let Ok(Some(_)) = c.try_wait() {
                    return false;
                }
                if start.elapsed() > limit {
                    let _ = c.kill();
                    return true;
                }
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    })
}

struct Printer<'a> {
    locations: &'a BTreeMap<u64, Location>,
    root: PathBuf,
    capture: bool,
    log_to_stderr: bool,
    link_ready: Option<std::sync::mpsc::Sender<()>>,
    messages: Vec<String>,
}

impl Printer<'_> {
    /// One plain line per frame: level, message, and for warnings and errors the
    /// source location.
    fn frame(&mut self, frame: &Frame<'_>) {
        let message = frame.display_message().to_string();
        let level = frame.level().map(|l| l.as_str().to_uppercase());
        // `defmt::println!` frames have no level: printed as they are.
        let mut line = match &level {
            Some(level) => format!("{level:<5} {message}"),
            None => message.clone(),
        };
        if matches!(level.as_deref(), Some("WARN" | "ERROR")) {
            if let Some(loc) = self.locations.get(&frame.index()) {
                let file = loc.file.strip_prefix(&self.root).unwrap_or(&loc.file);
                line.push_str(&format!("\n      at {}:{}", file.display(), loc.line));
            }
        }
        if self.log_to_stderr {
            let mut out = std::io::stderr().lock();
            let _ = writeln!(out, "{line}");
        } else {
            let mut out = std::io::stdout().lock();
            let _ = writeln!(out, "{line}");
            let _ = out.flush();
        }
        if message.contains(LINK_READY) {
            // Told at every boot (a reset brings the link up again); the receiver may
            // have given up already, then nothing else is to be told.
            if let Some(ready) = &self.link_ready {
                let _ = ready.send(());
            }
        }
        if self.capture {
            self.messages.push(message);
        }
    }
}

fn decode_stream(table: &Table, mut input: impl Read, printer: &mut Printer<'_>) -> Result<()> {
    let mut decoder = table.new_stream_decoder();
    let mut buf = [0u8; 4096];
    loop {
        let n = match input.read(&mut buf) {
            Ok(0) => return Ok(()),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => bail!("reading QEMU's output: {e}"),
        };
        decoder.received(buf.get(..n).unwrap_or(&[]));
        loop {
            match decoder.decode() {
                Ok(frame) => printer.frame(&frame),
                Err(DecodeError::UnexpectedEof) => break,
                Err(DecodeError::Malformed) => {
                    if table.encoding().can_recover() {
                        eprintln!("xtask qemu: skipped a malformed defmt frame");
                    } else {
                        bail!("malformed defmt frame (raw encoding: cannot resync)");
                    }
                }
            }
        }
    }
}

fn copy_raw(mut input: impl Read) -> Result<()> {
    std::io::copy(&mut input, &mut std::io::stdout().lock())
        .map(|_| ())
        .context("reading QEMU's output")
}

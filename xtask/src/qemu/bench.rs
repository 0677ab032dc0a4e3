//! `cargo xtask bench`: guest instructions per evaluation on the Cortex-M4 under QEMU.
//!
//! Builds the firmware's `bench` binary (release profile) and the `stopwatch` TCG
//! plugin (tools/qemu-stopwatch/stopwatch.c, with gcc), runs the binary under QEMU with
//! the plugin watching the `bench_start` / `bench_stop` markers, and pairs the counts
//! with the `BENCH <label>` lines the binary logs. Counts are exact and repeatable;
//! they are instructions, not cycles (QEMU models no pipeline, no wait states).

use anyhow::{anyhow, bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

use object::{Object, ObjectSymbol};

use super::board::{Board, BoardArg};
use super::profile;
use super::{build_firmware, ensure_target_tools, runner, tools, workspace_root};

const PLUGIN_SOURCE: &str = "tools/qemu-stopwatch/stopwatch.c";
const LABEL_PREFIX: &str = "BENCH ";

/// The counts of one bench run: every region's label and raw count, in the order the
/// firmware ran them, the first being the empty region (the markers' own overhead).
pub struct BenchCounts {
    pub qemu_version: String,
    /// Raw count of the empty region, subtracted by [`BenchCounts::net`].
    pub overhead: u64,
    pub regions: Vec<(String, u64)>,
    /// The bench ELF that was run.
    pub elf: PathBuf,
    /// With a profiled region: each executed address there and its count.
    pub pc_counts: Vec<(u64, u64)>,
}

impl BenchCounts {
    /// Net instructions (raw - overhead) of the region labelled exactly `label`.
    pub fn net(&self, label: &str) -> Option<u64> {
        self.regions
            .iter()
            .find(|(l, _)| l == label)
            .map(|(_, raw)| raw.saturating_sub(self.overhead))
    }
}

/// `cargo xtask bench`'s options.
#[derive(clap::Args)]
pub struct BenchArgs {
    #[command(flatten)]
    board: BoardArg,
    /// Also profile the one region whose label contains this text: its instructions
    /// attributed to functions, inlined ones included (docs/bench.md, "Profile")
    #[arg(long, value_name = "LABEL")]
    profile: Option<String>,
}

/// `cargo xtask bench`: measure on the board's QEMU machine, then print every region
/// (and, with `--profile`, where one region's instructions go).
pub fn bench(args: &BenchArgs) -> Result<()> {
    let board = args.board.board;
    let counts = measure_on(board, false, None)?;
    let overhead = counts.overhead;
    println!();
    println!("guest instructions per region ({} under QEMU {}, board {} ({}), release: opt-level 3, fat LTO, codegen-units 1)", board.qemu_cpu(), counts.qemu_version, board.name(), board.qemu_machine());
    println!("net = raw - {overhead} (the empty region: markers and black_box). Instructions, not cycles.");
    println!();
    println!("{:>8} {:>8}  region", "net", "raw");
    for (label, raw) in &counts.regions {
        println!("{:>8} {:>8}  {label}", raw.saturating_sub(overhead), raw);
    }
    if let Some(text) = &args.profile {
        // A label equal to the text wins: some labels are contained in others.
        let exact = |i: &usize| counts.regions[*i].0 == *text;
        let mut matching: Vec<usize> = (0..counts.regions.len())
            .filter(|&i| counts.regions[i].0.contains(text.as_str()))
            .collect();
        if matching.iter().any(exact) {
            matching.retain(exact);
        }
        let [region] = matching[..] else {
            bail!(
                "--profile `{text}` matches {} regions; give text that one label alone contains or equals",
                matching.len()
            );
        };
        let profiled = measure_on(board, true, Some(region))?;
        if profiled.regions.get(region) != counts.regions.get(region) {
            bail!("the profiled run counted the region differently");
        }
        let (label, raw) = &counts.regions[region];
        println!();
        println!("profile of `{label}` ({raw} raw instructions, markers included)");
        profile::print(&profiled.elf, &profiled.pc_counts, *raw)?;
    }
    Ok(())
}

/// Builds the bench firmware and the plugin, runs the firmware under QEMU and returns
/// the parsed counts. The decoded defmt log is echoed as the firmware runs, to stdout or,
/// with `log_to_stderr`, to stderr.
pub fn measure(board: Board, log_to_stderr: bool) -> Result<BenchCounts> {
    measure_on(board, log_to_stderr, None)
}

/// [`measure`] on `board`; with `profile`, the per-address counts of that region (its
/// index in the run, 0 being the empty region) too.
fn measure_on(board: Board, log_to_stderr: bool, profile: Option<usize>) -> Result<BenchCounts> {
    ensure_target_tools()?;
    let elf = build_firmware(board, "bench", true, &["bench"], &[])?;
    let counts_path = elf.with_file_name("bench-counts.txt");
    let pcs_path = elf.with_file_name("bench-pcs.txt");
    let _ = std::fs::remove_file(&pcs_path);
    let (start, stop) = (|n: &str| n == "bench_start", |n: &str| n == "bench_stop");
    let mut plugin_args = stopwatch(&elf, start, stop, &counts_path)?;
    if let Some(region) = profile {
        plugin_args += &format!(",profile={region},pcs={}", pcs_path.display());
    }

    let options = runner::Options {
        extra_args: vec!["-plugin".into(), plugin_args],
        capture: true,
        serial: None,
        log_to_stderr,
        link_ready: None,
    };
    let outcome = runner::run_elf(&elf, &options)?;
    if outcome.status != 0 {
        bail!("the bench firmware exited with status {}", outcome.status);
    }
    let counts = std::fs::read_to_string(&counts_path)
        .with_context(|| format!("no counts from the plugin ({})", counts_path.display()))?;
    let counts: Vec<u64> = counts
        .lines()
        .map(|l| {
            l.trim()
                .parse::<u64>()
                .map_err(|_| anyhow!("bad plugin output line `{l}`"))
        })
        .collect::<Result<_, _>>()?;
    let labels: Vec<&str> = outcome
        .messages
        .iter()
        .filter_map(|m| m.strip_prefix(LABEL_PREFIX))
        .collect();
    if labels.len() != counts.len() || counts.is_empty() {
        bail!(
            "{} regions logged but {} counts measured",
            labels.len(),
            counts.len()
        );
    }
    let pc_counts = match profile {
        Some(_) => profile::read_counts(&pcs_path)?,
        None => Vec::new(),
    };
    Ok(BenchCounts {
        qemu_version: qemu_version(),
        overhead: counts.first().copied().unwrap_or(0),
        regions: labels.iter().map(|l| l.to_string()).zip(counts).collect(),
        elf,
        pc_counts,
    })
}

/// The `-plugin` argument of the stopwatch plugin (built next to `elf`) counting the
/// guest instructions from the function `start` picks to the one `stop` picks (their
/// mangled names), into `out`.
pub(super) fn stopwatch(
    elf: &Path,
    start: impl Fn(&str) -> bool,
    stop: impl Fn(&str) -> bool,
    out: &Path,
) -> Result<String> {
    let plugin = build_plugin(elf.parent().context("the ELF has no folder")?)?;
    let start = symbol_address(elf, start).context("the start of the count")?;
    let stop = symbol_address(elf, stop).context("the end of the count")?;
    let _ = std::fs::remove_file(out);
    Ok(format!(
        "{},start={start:#x},stop={stop:#x},out={}",
        plugin.display(),
        out.display()
    ))
}

/// Compiles the plugin next to the bench ELF (a few hundred ms with gcc).
fn build_plugin(dir: &Path) -> Result<PathBuf> {
    if !tools::have("gcc") {
        tools::apt_install(&["gcc", "libc6-dev"], "gcc (to build the QEMU plugin)")?;
    }
    let source = workspace_root().join(PLUGIN_SOURCE);
    let out = dir.join("libstopwatch.so");
    let status = Command::new("gcc")
        .args([
            "-shared", "-fPIC", "-O2", "-Wall", "-Wextra", "-Werror", "-o",
        ])
        .arg(&out)
        .arg(&source)
        .status()
        .context("cannot run gcc")?;
    if status.success() {
        Ok(out)
    } else {
        Err(anyhow!(
            "building the QEMU plugin {} failed ({status})",
            source.display()
        ))
    }
}

/// The address of the first instruction of the function whose (mangled) name `is`
/// picks, Thumb bit cleared.
fn symbol_address(elf: &Path, is: impl Fn(&str) -> bool) -> Result<u64> {
    let bytes = std::fs::read(elf).with_context(|| format!("cannot read {}", elf.display()))?;
    let file =
        object::File::parse(&*bytes).with_context(|| format!("cannot parse {}", elf.display()))?;
    let found: Vec<u64> = file
        .symbols()
        .filter(|s| s.name().is_ok_and(&is))
        .map(|s| s.address() & !1)
        .collect();
    match found.as_slice() {
        [a] => Ok(*a),
        [] => bail!("no such function in {}", elf.display()),
        _ => bail!(
            "{} functions of that name in {}",
            found.len(),
            elf.display()
        ),
    }
}

fn qemu_version() -> String {
    Command::new(runner::QEMU)
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| {
            String::from_utf8_lossy(&o.stdout)
                .split_whitespace()
                .nth(3)
                .map(str::to_string)
        })
        .unwrap_or_else(|| "?".into())
}

//! The no-panic proof of the flight binary (docs/no-panic.md), part of `cargo xtask test`.
//!
//! [`check`] builds `firmware` (the flight binary) for the target in release with the
//! firmware's `no-panic-check` feature, under which both panic handlers call a function
//! that is defined nowhere. After fat LTO and the linker's garbage collection a handler
//! survives only if some reachable code can call it, so: the link succeeds if and only
//! if no panic path is left. When it fails, [`check`] links the same build once more
//! with the symbol left unresolved (never to run) and names the panic sites from that
//! ELF: the `core::panic::Location` records still in it (file:line:col of each panic
//! that survived optimisation) and the functions that branch into the panic machinery.

use anyhow::{anyhow, bail, Context, Result};
use std::collections::{BTreeMap, BTreeSet};
use std::process::Stdio;
use std::time::Instant;

use object::{Object, ObjectSection, ObjectSymbol, SectionKind, SymbolKind};

use crate::qemu::{cargo_command as cargo, executable, NO_FPU_TARGET, TARGET};

/// The undefined function the check build's panic handlers call (firmware/src/platform.rs).
const SYMBOL: &str = "NO_PANIC_CHECK__a_panic_path_is_reachable__see_docs_no_panic_md";
/// One link the proof covers: a binary of the firmware crate, the features of its check
/// build (with `no-panic-check`), and extra rustc arguments.
struct Build {
    what: &'static str,
    target: &'static str,
    bin: &'static str,
    features: &'static str,
    rustc_args: &'static [&'static str],
}

/// The flight binary on each board, and the real-Earth general form in f32 (its
/// `pixel`, `update` and `motion`, linked by the footprint binary) until the controller
/// flies it. The features name the board: the builds use no default features.
const BUILDS: [Build; 4] = [
    Build {
        what: "the release flight binary (mps2-an386)",
        target: TARGET,
        bin: "firmware",
        features: "mps2-an386,no-panic-check",
        rustc_args: &[],
    },
    Build {
        what: "the release flight binary (stm32f405, with stm32f4xx-hal)",
        target: TARGET,
        bin: "firmware",
        features: "stm32f405,no-panic-check",
        rustc_args: &[],
    },
    Build {
        what: "GENERAL_F32 (the real-Earth f32 form: pixel, update, motion)",
        target: TARGET,
        bin: "footprint",
        features: "mps2-an386,bench,no-panic-check",
        rustc_args: &["--cfg", "footprint=\"earth-f32\""],
    },
    Build {
        what: "the release flight binary (mps2-an385: Cortex-M3, fixed-point pixels)",
        target: NO_FPU_TARGET,
        bin: "firmware",
        features: "mps2-an385,no-panic-check",
        rustc_args: &[],
    },
];

impl Build {
    fn cargo_args(&self) -> Vec<&'static str> {
        vec![
            "--package",
            "firmware",
            "--bin",
            self.bin,
            "--target",
            self.target,
            "--release",
            "--no-default-features",
            "--features",
            self.features,
            "--color=never",
        ]
    }
}

/// The proof: an error (naming the panic sites when it can) if a covered build still has
/// a path to the panic handler.
pub fn check() -> Result<()> {
    for build in &BUILDS {
        check_one(build)?;
    }
    Ok(())
}

fn check_one(build: &Build) -> Result<()> {
    let t0 = Instant::now();
    let args = build.cargo_args();
    eprintln!(
        "\n==> no-panic proof: cargo rustc {} -- {}",
        args.join(" "),
        build.rustc_args.join(" ")
    );
    let out = cargo()
        .arg("rustc")
        .args(&args)
        .arg("--")
        .args(build.rustc_args)
        .stdout(Stdio::null())
        .output()
        .context("cannot start cargo")?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.success() {
        restore_flight_binary(build);
        eprintln!(
            "xtask: no-panic proof passed: {} links with no path to a panic handler ({:.1} s)",
            build.what,
            t0.elapsed().as_secs_f64()
        );
        return Ok(());
    }
    if !stderr.contains(SYMBOL) {
        eprint!("{stderr}");
        bail!("the no-panic check build failed ({})", out.status);
    }
    let report = match diagnose(build) {
        Ok(report) => report,
        Err(e) => format!("(could not name the panic sites: {e:#})\n"),
    };
    Err(anyhow!(
        "no-panic proof failed: {} can reach the panic handler \
         (link error: undefined symbol {SYMBOL}).\n{report}\
         Remove each path (docs/no-panic.md) and rerun `cargo xtask test`.",
        build.what
    ))
}

/// Links the check build with the symbol unresolved, lists its panic sites, and puts the
/// normal flight binary back in its place.
fn diagnose(build: &Build) -> Result<String> {
    let out = cargo()
        .arg("rustc")
        .args(build.cargo_args())
        .arg("--message-format=json-render-diagnostics")
        .arg("--")
        .args(build.rustc_args)
        .args(["-C", "link-arg=--unresolved-symbols=ignore-all"])
        .stderr(Stdio::null())
        .output()
        .context("cannot start cargo")?;
    let elf = executable(&out.stdout, build.bin);
    let report = match (out.status.success(), elf) {
        (true, Some(elf)) => std::fs::read(&elf)
            .with_context(|| format!("cannot read {}", elf.display()))
            .and_then(|bytes| report(&bytes)),
        _ => Err(anyhow!("the diagnostic link failed ({})", out.status)),
    };
    restore_flight_binary(build);
    report
}

/// Cargo copies the last ELF it linked for a binary to `<target>/<triple>/release/
/// firmware`: after a check build, put that target's normal flight binary back there
/// (cargo finds it up to date, so this only copies): the default board's on the FPU
/// target, the check build's own board on the other.
fn restore_flight_binary(build: &Build) {
    let mut restore = cargo();
    restore
        .args(["build", "--package", "firmware", "--bin", "firmware"])
        .args(["--target", build.target, "--release", "--quiet"]);
    if build.target != TARGET {
        let board = build.features.split(',').next().unwrap_or_default();
        restore.args(["--no-default-features", "--features", board]);
    }
    let restored = restore.status();
    if !restored.is_ok_and(|s| s.success()) {
        eprintln!("xtask: warning: could not rebuild the normal release flight binary");
    }
}

/// What the diagnostic ELF says about its panic paths.
fn report(elf: &[u8]) -> Result<String> {
    let file = object::File::parse(elf).context("cannot parse the ELF")?;
    let mut text = String::new();
    let locations = panic_locations(&file);
    if !locations.is_empty() {
        text.push_str("panic sites left in the binary (core::panic::Location records):\n");
        for l in &locations {
            text.push_str(&format!("  {l}\n"));
        }
    }
    let edges = panic_calls(&file);
    if !edges.is_empty() {
        text.push_str("calls on a path to the panic handler (caller -> callee):\n");
        for (caller, callees) in &edges {
            for callee in callees {
                text.push_str(&format!("  {caller} -> {callee}\n"));
            }
        }
    }
    if text.is_empty() {
        bail!("found neither Location records nor branches to the handler");
    }
    Ok(text)
}

/// `file:line:col` of every `core::panic::Location` in the read-only data: four words
/// (file name pointer and length, line, column) whose pointer and length name UTF-8 text
/// ending in `.rs` in the same data. The check build's panic handler hands the location
/// on, so exactly the locations of surviving panic sites stay in the binary.
fn panic_locations(file: &object::File<'_>) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let sections: Vec<(u64, &[u8])> = file
        .sections()
        .filter(|s| {
            matches!(
                s.kind(),
                SectionKind::ReadOnlyData | SectionKind::ReadOnlyString
            )
        })
        .filter_map(|s| Some((s.address(), s.data().ok()?)))
        .collect();
    let text_at = |addr: u64, len: u64| {
        sections.iter().find_map(|&(start, data)| {
            let from = usize::try_from(addr.checked_sub(start)?).ok()?;
            let to = from.checked_add(usize::try_from(len).ok()?)?;
            std::str::from_utf8(data.get(from..to)?).ok()
        })
    };
    for &(_, data) in &sections {
        let word = |at: usize| {
            data.get(at..at.checked_add(4)?)
                .and_then(|b| b.try_into().ok())
                .map(u32::from_le_bytes)
        };
        // Records are 4-aligned.
        for at in (0..data.len()).step_by(4) {
            let (Some(ptr), Some(len), Some(line), Some(col)) =
                (word(at), word(at + 4), word(at + 8), word(at + 12))
            else {
                break;
            };
            if !(1..=1024).contains(&len)
                || !(1..1 << 20).contains(&line)
                || !(1..1 << 16).contains(&col)
            {
                continue;
            }
            if let Some(name) = text_at(u64::from(ptr), u64::from(len)) {
                if name.ends_with(".rs") {
                    found.insert(format!("{}:{line}:{col}", short_path(name)));
                }
            }
        }
    }
    found
}

/// A source path without the cargo registry's or the toolchain's prefix.
fn short_path(path: &str) -> &str {
    if let Some((_, rest)) = path.split_once("/registry/src/") {
        return rest.split_once('/').map_or(rest, |(_, p)| p);
    }
    if let Some((_, rest)) = path.split_once("/library/") {
        return rest;
    }
    path
}

/// The call graph's edges that lead to a panic handler (`rust_begin_unwind`, defmt's
/// `_defmt_panic`), from every caller outside `core` and the handlers themselves: the
/// code to change. Branch targets come from decoding each function's Thumb-2 branches
/// (`BL`, `B`, `B.W`, `B<c>`, `B<c>.W`, `CB(N)Z`), skipping literal pools (`$d` mapping symbols).
fn panic_calls(file: &object::File<'_>) -> BTreeMap<String, BTreeSet<String>> {
    struct Func<'a> {
        start: u64,
        end: u64,
        name: String,
        code: &'a [u8],
    }
    let mut data_marks: Vec<(u64, bool)> = file
        .symbols()
        .filter_map(|s| {
            let name = s.name().ok()?;
            let is_data = name == "$d" || name.starts_with("$d.");
            let is_code = name == "$t" || name.starts_with("$t.");
            (is_data || is_code).then_some((s.address(), is_data))
        })
        .collect();
    data_marks.sort_unstable();
    let mut funcs: Vec<Func<'_>> = file
        .symbols()
        .filter(|s| s.kind() == SymbolKind::Text && s.size() > 0)
        .filter_map(|s| {
            let start = s.address() & !1;
            let section = file.section_by_index(s.section_index()?).ok()?;
            let data = section.data().ok()?;
            let from = usize::try_from(start.checked_sub(section.address())?).ok()?;
            let to = from.checked_add(usize::try_from(s.size()).ok()?)?;
            Some(Func {
                start,
                end: start + s.size(),
                name: demangle(s.name().ok()?),
                code: data.get(from..to)?,
            })
        })
        .collect();
    funcs.sort_by_key(|f| f.start);
    funcs.dedup_by_key(|f| f.start);
    let func_at = |addr: u64| {
        let i = funcs.partition_point(|f| f.start <= addr).checked_sub(1)?;
        (addr < funcs.get(i)?.end).then_some(i)
    };
    // Is `addr` inside a literal pool (after a `$d` mark, before the next `$t`)?
    let in_data = |addr: u64| {
        let i = data_marks.partition_point(|&(a, _)| a <= addr);
        i.checked_sub(1)
            .and_then(|i| data_marks.get(i))
            .is_some_and(|&(_, d)| d)
    };
    let mut callers: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); funcs.len()];
    for (i, f) in funcs.iter().enumerate() {
        let mut at = 0usize;
        while let Some(hw1) = halfword(f.code, at) {
            let addr = f.start + at as u64;
            let (size, target) = decode_branch(hw1, halfword(f.code, at + 2), addr);
            if let Some(j) = target.filter(|_| !in_data(addr)).and_then(func_at) {
                if let Some(set) = callers.get_mut(j).filter(|_| j != i) {
                    set.insert(i);
                }
            }
            at += size;
        }
    }
    // Every function from which a handler can be reached.
    let is_handler = |name: &str| name.ends_with("rust_begin_unwind") || name == "_defmt_panic";
    let mut reach: BTreeSet<usize> = (0..funcs.len())
        .filter(|&i| funcs.get(i).is_some_and(|f| is_handler(&f.name)))
        .collect();
    let mut todo: Vec<usize> = reach.iter().copied().collect();
    while let Some(j) = todo.pop() {
        for &i in callers.get(j).into_iter().flatten() {
            if reach.insert(i) {
                todo.push(i);
            }
        }
    }
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for &j in &reach {
        for &i in callers.get(j).into_iter().flatten() {
            let (Some(caller), Some(callee)) = (funcs.get(i), funcs.get(j)) else {
                continue;
            };
            let machinery = caller.name.starts_with("core::") || is_handler(&caller.name);
            if !machinery {
                edges
                    .entry(caller.name.clone())
                    .or_default()
                    .insert(callee.name.clone());
            }
        }
    }
    edges
}

fn halfword(code: &[u8], at: usize) -> Option<u16> {
    let b = code.get(at..at.checked_add(2)?)?;
    Some(u16::from_le_bytes([*b.first()?, *b.get(1)?]))
}

/// Decodes the Thumb-2 instruction starting with `hw1` (and `hw2`, its second half if it
/// is a 32-bit one) at `addr`: its size in bytes and, for a direct branch or call, the
/// target address.
fn decode_branch(hw1: u16, hw2: Option<u16>, addr: u64) -> (usize, Option<u64>) {
    let sext = |value: u32, bits: u32| -> i64 {
        let shift = 32 - bits;
        i64::from(((value << shift) as i32) >> shift)
    };
    let pc = addr as i64 + 4;
    let target = |offset: i64| u64::try_from(pc + offset).ok();
    let hw1 = u32::from(hw1);
    if matches!(hw1 >> 11, 0b11101..=0b11111) {
        let Some(hw2) = hw2.map(u32::from) else {
            return (4, None);
        };
        if hw1 >> 11 != 0b11110 || hw2 & 0x8000 == 0 {
            return (4, None);
        }
        let s = (hw1 >> 10) & 1;
        let (j1, j2) = ((hw2 >> 13) & 1, (hw2 >> 11) & 1);
        let imm11 = hw2 & 0x7FF;
        return match hw2 & 0xD000 {
            // BL (T1) and B.W (T4).
            0xD000 | 0x9000 => {
                let (i1, i2) = (!(j1 ^ s) & 1, !(j2 ^ s) & 1);
                let imm =
                    (s << 24) | (i1 << 23) | (i2 << 22) | ((hw1 & 0x3FF) << 12) | (imm11 << 1);
                (4, target(sext(imm, 25)))
            }
            // B<c>.W (T3); condition 111x is not a branch.
            0x8000 if (hw1 >> 6) & 0xE != 0xE => {
                let imm = (s << 20) | (j2 << 19) | (j1 << 18) | ((hw1 & 0x3F) << 12) | (imm11 << 1);
                (4, target(sext(imm, 21)))
            }
            _ => (4, None),
        };
    }
    if hw1 >> 11 == 0b11100 {
        // B (T2).
        return (2, target(sext((hw1 & 0x7FF) << 1, 12)));
    }
    if hw1 >> 12 == 0b1101 && (hw1 >> 8) & 0xE != 0xE {
        // B<c> (T1).
        return (2, target(sext((hw1 & 0xFF) << 1, 9)));
    }
    if hw1 & 0xF500 == 0xB100 {
        // CBZ, CBNZ.
        let imm = (((hw1 >> 9) & 1) << 6) | (((hw1 >> 3) & 0x1F) << 1);
        return (2, target(i64::from(imm)));
    }
    (2, None)
}

/// A readable name for a Rust symbol (legacy or v0 mangling), without the hash;
/// anything else as is.
fn demangle(name: &str) -> String {
    format!("{:#}", rustc_demangle::demangle(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hw(bytes: [u8; 4]) -> (u16, Option<u16>) {
        (
            u16::from_le_bytes([bytes[0], bytes[1]]),
            Some(u16::from_le_bytes([bytes[2], bytes[3]])),
        )
    }

    // Encodings and targets from `llvm-objdump -d` of the firmware.
    #[test]
    fn decodes_thumb2_branches() {
        let (a, b) = hw([0x05, 0xf0, 0x15, 0xfc]); // bl 0x71dc
        assert_eq!(decode_branch(a, b, 0x19ae), (4, Some(0x71dc)));
        let (a, b) = hw([0xfe, 0xf7, 0xf2, 0xbd]); // b.w 0x58e
        assert_eq!(decode_branch(a, b, 0x19a6), (4, Some(0x58e)));
        let (a, b) = hw([0x41, 0xf0, 0x0b, 0x80]); // bne.w 0x1494
        assert_eq!(decode_branch(a, b, 0x47a), (4, Some(0x1494)));
        let (a, b) = hw([0x40, 0xf0, 0xac, 0x80]); // bne.w 0x656
        assert_eq!(decode_branch(a, b, 0x4fa), (4, Some(0x656)));
        assert_eq!(decode_branch(0xd121, None, 0x48c), (2, Some(0x4d2))); // bne
        assert_eq!(decode_branch(0xb3d1, None, 0x490), (2, Some(0x508))); // cbz
        assert_eq!(decode_branch(0xe7fb, None, 0x410), (2, Some(0x40a))); // b
        assert_eq!(decode_branch(0x200e, None, 0x19aa), (2, None)); // movs r0, #14
    }

    #[test]
    fn demangles_both_schemes() {
        assert_eq!(
            demangle("_ZN10controller7control10Controller7segment17h3056d19f2e759753E"),
            "controller::control::Controller::segment"
        );
        assert_eq!(
            demangle("_RNvNtCs7ldSeZOOJos_4core9panicking18panic_bounds_check"),
            "core::panicking::panic_bounds_check"
        );
        assert_eq!(
            demangle("_RNvCsfLfy6EI15iL_7___rustc17rust_begin_unwind"),
            "__rustc::rust_begin_unwind"
        );
        assert_eq!(demangle("_defmt_acquire"), "_defmt_acquire");
    }

    #[test]
    fn shortens_source_paths() {
        assert_eq!(
            short_path("/root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/semihosting-0.1.25/src/fd.rs"),
            "semihosting-0.1.25/src/fd.rs"
        );
        assert_eq!(
            short_path(
                "/rustc/59807616e1fa2540724bfbac14d7976d7e4a3860/library/core/src/slice/index.rs"
            ),
            "core/src/slice/index.rs"
        );
        assert_eq!(
            short_path("controller/src/plan.rs"),
            "controller/src/plan.rs"
        );
    }
}

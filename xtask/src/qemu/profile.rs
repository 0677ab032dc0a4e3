//! `cargo xtask bench --profile LABEL`: where one bench region's instructions go.
//!
//! The stopwatch plugin counts every instruction executed inside the region by address
//! (exact, no sampling); here each address is attributed through the ELF's DWARF
//! (`addr2line`) to the function it was written in, inlined functions included: with
//! fat LTO nearly everything is inlined into the region's one call, so the symbol table
//! alone would name a single function.
//!
//! Two tables: "self", by the innermost function of each address (where the work is
//! written), and "inclusive", by every function on the address's inline stack (what a
//! call costs with everything it inlined).

use anyhow::{anyhow, Context, Result};
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;

use object::{Object, ObjectSection};

/// Rows printed per table.
const ROWS: usize = 25;

/// The plugin's `pcs=` file: "ADDR COUNT" lines (hex, decimal).
pub fn read_counts(path: &Path) -> Result<Vec<(u64, u64)>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("no profile from the plugin ({})", path.display()))?;
    text.lines()
        .map(|line| {
            let bad = || anyhow!("bad profile line `{line}`");
            let (addr, count) = line.split_once(' ').ok_or_else(bad)?;
            Ok((
                u64::from_str_radix(addr, 16).map_err(|_| bad())?,
                count.parse().map_err(|_| bad())?,
            ))
        })
        .collect()
}

/// Prints the self and inclusive tables of `pc_counts` (the region's `raw` count, the
/// markers' own instructions included, is the 100 %).
pub fn print(elf: &Path, pc_counts: &[(u64, u64)], raw: u64) -> Result<()> {
    let bytes = std::fs::read(elf).with_context(|| format!("cannot read {}", elf.display()))?;
    let file =
        object::File::parse(&*bytes).with_context(|| format!("cannot parse {}", elf.display()))?;
    let sections = gimli::DwarfSections::load(|id| -> Result<Cow<[u8]>, gimli::Error> {
        Ok(file
            .section_by_name(id.name())
            .and_then(|s| s.uncompressed_data().ok())
            .unwrap_or(Cow::Borrowed(&[])))
    })
    .with_context(|| format!("DWARF of {}", elf.display()))?;
    let dwarf = sections.borrow(|s| gimli::EndianSlice::new(s, gimli::LittleEndian));
    let context = addr2line::Context::from_dwarf(dwarf)
        .with_context(|| format!("DWARF of {}", elf.display()))?;

    let mut own: HashMap<String, u64> = HashMap::new();
    let mut inclusive: HashMap<String, u64> = HashMap::new();
    let total: u64 = pc_counts.iter().map(|(_, n)| n).sum();
    for &(pc, n) in pc_counts {
        let names = inline_stack(&context, pc);
        *own.entry(names.first().cloned().unwrap_or_else(|| format!("{pc:#x}")))
            .or_default() += n;
        let mut seen: Vec<&String> = Vec::new();
        for name in &names {
            // A recursive or repeated inline counts once per address.
            if !seen.contains(&name) {
                seen.push(name);
                *inclusive.entry(name.clone()).or_default() += n;
            }
        }
    }
    println!("{total} instructions attributed (the region's raw count is {raw})");
    for (title, table) in [
        ("self (innermost function)", own),
        ("inclusive (with what it inlined)", inclusive),
    ] {
        let mut rows: Vec<(String, u64)> = table.into_iter().collect();
        rows.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
        println!();
        println!("{title}");
        println!("{:>8} {:>6}  function", "instr", "%");
        for (name, n) in rows.iter().take(ROWS) {
            println!(
                "{n:>8} {:>6.1}  {name}",
                100.0 * *n as f64 / raw.max(1) as f64
            );
        }
    }
    Ok(())
}

/// The functions at `pc`, innermost first, demangled without their hashes.
fn inline_stack<R: gimli::Reader>(context: &addr2line::Context<R>, pc: u64) -> Vec<String> {
    let mut names = Vec::new();
    let Ok(mut frames) = context.find_frames(pc).skip_all_loads() else {
        return names;
    };
    while let Ok(Some(frame)) = frames.next() {
        if let Some(f) = frame.function {
            if let Ok(raw) = f.raw_name() {
                names.push(format!("{:#}", rustc_demangle::demangle(&raw)));
            }
        }
    }
    names
}

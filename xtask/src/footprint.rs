//! Flash bytes per backend: the `flash_bytes` column of `cargo xtask report`.
//!
//! `firmware/src/bin/footprint.rs` is linked once per variant (`--cfg footprint="..."`,
//! release, fat LTO, the flight profile) and once with "none"; a variant's figure is
//! the difference of the loadable (flash) bytes of the two images: the code and
//! constants its `pixel`, `update` and `motion` bring into a binary, shared support
//! (soft-float routines, libm) included, the runtime and logger excluded.

use std::path::Path;

use crate::target::build_bin_with;

/// Loadable bytes of the footprint binary built for `variant`.
fn image_bytes(variant: &str) -> Result<u64, String> {
    let cfg = format!("footprint=\"{variant}\"");
    let elf = build_bin_with("firmware", "footprint", true, &["bench"], &["--cfg", &cfg])?;
    flash_bytes(&elf)
}

/// Flash bytes of each of `variants` beyond the empty ("none") build.
pub fn variant_bytes(variants: &[&str]) -> Result<Vec<u64>, String> {
    let base = image_bytes("none")?;
    variants
        .iter()
        .map(|v| {
            let with = image_bytes(v)?;
            with.checked_sub(base).ok_or_else(|| {
                format!("footprint: `{v}` ({with} B) is smaller than none ({base} B)")
            })
        })
        .collect()
}

/// Bytes of every section an ELF32 image loads from flash: allocated (`SHF_ALLOC`) and
/// with contents in the file (not `SHT_NOBITS`): vector table, code, constants and the
/// initial image of `.data`.
pub fn flash_bytes(elf: &Path) -> Result<u64, String> {
    let bytes = std::fs::read(elf).map_err(|e| format!("reading {}: {e}", elf.display()))?;
    loadable_bytes(&bytes)
        .ok_or_else(|| format!("{}: not a little-endian ELF32 image", elf.display()))
}

fn loadable_bytes(b: &[u8]) -> Option<u64> {
    const SHF_ALLOC: u32 = 0x2;
    const SHT_NOBITS: u32 = 8;
    // ELF32, little-endian.
    if b.get(..6)? != b"\x7fELF\x01\x01" {
        return None;
    }
    let u16_at = |o: usize| Some(u16::from_le_bytes(b.get(o..o + 2)?.try_into().ok()?));
    let u32_at = |o: usize| Some(u32::from_le_bytes(b.get(o..o + 4)?.try_into().ok()?));
    let shoff = u32_at(0x20)? as usize;
    let shentsize = u16_at(0x2E)? as usize;
    let shnum = u16_at(0x30)? as usize;
    let mut total = 0u64;
    for i in 0..shnum {
        let sh = shoff + i * shentsize;
        let (kind, flags, size) = (u32_at(sh + 4)?, u32_at(sh + 8)?, u32_at(sh + 20)?);
        if flags & SHF_ALLOC != 0 && kind != SHT_NOBITS {
            total += u64::from(size);
        }
    }
    Some(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ELF32 header and three section headers built by hand: a loadable PROGBITS
    /// section, a NOBITS one (.bss) and a non-allocated one (debug info).
    #[test]
    fn only_allocated_sections_with_contents_count() {
        let shoff = 52usize;
        let mut b = vec![0u8; shoff + 3 * 40];
        b[..6].copy_from_slice(b"\x7fELF\x01\x01");
        b[0x20..0x24].copy_from_slice(&(shoff as u32).to_le_bytes());
        b[0x2E..0x30].copy_from_slice(&40u16.to_le_bytes());
        b[0x30..0x32].copy_from_slice(&3u16.to_le_bytes());
        let sections = [(1u32, 0x6u32, 1000u32), (8, 0x3, 500), (1, 0x0, 7000)];
        for (i, (kind, flags, size)) in sections.into_iter().enumerate() {
            let sh = shoff + i * 40;
            b[sh + 4..sh + 8].copy_from_slice(&kind.to_le_bytes());
            b[sh + 8..sh + 12].copy_from_slice(&flags.to_le_bytes());
            b[sh + 20..sh + 24].copy_from_slice(&size.to_le_bytes());
        }
        assert_eq!(loadable_bytes(&b), Some(1000));
        assert_eq!(loadable_bytes(b"not an elf"), None);
    }
}

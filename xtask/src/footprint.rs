//! Flash bytes per backend: the `flash_bytes` column of `cargo xtask report`.
//!
//! `firmware/src/bin/footprint.rs` is linked once per variant (`--cfg footprint="..."`,
//! release, fat LTO, the flight profile) and once with "none"; a variant's figure is
//! the difference of the loadable (flash) bytes of the two images: the code and
//! constants its `pixel`, `update` and `motion` bring into a binary, shared support
//! (soft-float routines, libm) included, the runtime and logger excluded.

use anyhow::{anyhow, Context, Result};
use std::path::Path;

use object::{Object, ObjectSection, SectionFlags};

use crate::qemu::{board::Board, build_firmware};

/// Loadable bytes of the footprint binary built for `variant` on `board`.
fn image_bytes(board: Board, variant: &str) -> Result<u64> {
    let cfg = format!("footprint=\"{variant}\"");
    let elf = build_firmware(board, "footprint", true, &["bench"], &["--cfg", &cfg])?;
    flash_bytes(&elf)
}

/// Flash bytes of each of `variants` beyond the empty ("none") build, on `board`.
pub fn variant_bytes(board: Board, variants: &[&str]) -> Result<Vec<u64>> {
    let base = image_bytes(board, "none")?;
    variants
        .iter()
        .map(|v| {
            let with = image_bytes(board, v)?;
            with.checked_sub(base).ok_or_else(|| {
                anyhow!("footprint: `{v}` ({with} B) is smaller than none ({base} B)")
            })
        })
        .collect()
}

/// Bytes of every section an ELF image loads from flash: allocated (`SHF_ALLOC`) and
/// with contents in the file (not `SHT_NOBITS`): vector table, code, constants and the
/// initial image of `.data`.
pub fn flash_bytes(elf: &Path) -> Result<u64> {
    let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    loadable_bytes(&bytes).with_context(|| format!("{}", elf.display()))
}

fn loadable_bytes(elf: &[u8]) -> Result<u64, object::Error> {
    let file = object::File::parse(elf)?;
    Ok(file
        .sections()
        .filter(|s| {
            let alloc = matches!(s.flags(), SectionFlags::Elf { sh_flags }
                if sh_flags & u64::from(object::elf::SHF_ALLOC) != 0);
            // A NOBITS section (.bss) has no bytes in the file.
            alloc && s.file_range().is_some()
        })
        .map(|s| s.size())
        .sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ARM object with code, initialised data, .bss and debug info: only the first
    /// two load from flash.
    #[test]
    fn only_allocated_sections_with_contents_count() {
        use object::write::Object as Writer;
        use object::{Architecture, BinaryFormat, Endianness, SectionKind};
        let mut elf = Writer::new(BinaryFormat::Elf, Architecture::Arm, Endianness::Little);
        let text = elf.add_section(vec![], b".text".to_vec(), SectionKind::Text);
        elf.append_section_data(text, &[0; 1000], 4);
        let data = elf.add_section(vec![], b".data".to_vec(), SectionKind::Data);
        elf.append_section_data(data, &[1; 24], 4);
        let bss = elf.add_section(vec![], b".bss".to_vec(), SectionKind::UninitializedData);
        elf.append_section_bss(bss, 500, 4);
        let debug = elf.add_section(vec![], b".debug_info".to_vec(), SectionKind::Debug);
        elf.append_section_data(debug, &[2; 7000], 1);
        assert_eq!(loadable_bytes(&elf.write().unwrap()).unwrap(), 1024);
        assert!(loadable_bytes(b"not an elf").is_err());
    }
}

//! Relinks when the memory layout changes. The linker takes `memory.x` from the
//! workspace root (the directory cargo runs rustc and so the linker in; cortex-m-rt's
//! `link.x` INCLUDEs it from there before any search path): see docs/target.md.
fn main() {
    println!("cargo:rerun-if-changed=../memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}

// The board's memory layout for the linker, shared by firmware/build.rs and
// hil-tests/build.rs (each `include!`s this file).
//
// cortex-m-rt's `link.x` does `INCLUDE memory.x`. The linker looks in its working
// directory (the workspace root) first, then along the search path: so no `memory.x`
// may lie at the root, and this puts the selected board's file, as `memory.x`, in the
// build script's OUT_DIR and that folder on the search path.

/// The boards: cargo feature and layout file in `firmware/memory/`.
const BOARDS: [(&str, &str); 3] = [
    ("mps2-an386", "mps2-an386.x"),
    ("mps2-an385", "mps2-an385.x"),
    ("stm32f405", "stm32f405.x"),
];

/// Copies the layout of the one board feature enabled to `$OUT_DIR/memory.x`; stops the
/// build with a message if none or several are enabled.
fn select_memory_x(memory_dir: &std::path::Path) {
    let enabled: Vec<&(&str, &str)> = BOARDS
        .iter()
        .filter(|(feature, _)| {
            let var = format!("CARGO_FEATURE_{}", feature.to_uppercase().replace('-', "_"));
            std::env::var_os(var).is_some()
        })
        .collect();
    let names: Vec<&str> = BOARDS.iter().map(|(f, _)| *f).collect();
    let file = match enabled.as_slice() {
        [(_, file)] => *file,
        [] => panic!("no board feature: enable one of {names:?}"),
        _ => panic!("several board features enabled: enable exactly one of {names:?}"),
    };
    let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let source = memory_dir.join(file);
    std::fs::copy(&source, out.join("memory.x"))
        .unwrap_or_else(|e| panic!("copying {}: {e}", source.display()));
    println!("cargo:rustc-link-search={}", out.display());
    for (_, file) in BOARDS {
        println!("cargo:rerun-if-changed={}", memory_dir.join(file).display());
    }
}

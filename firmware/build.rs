//! Selects the board's memory layout (`memory/select.rs`): see docs/target.md, "Boards".
include!("memory/select.rs");

fn main() {
    select_memory_x(std::path::Path::new("memory"));
    // cortex-m-rt's feature `device` (the MPS2 boards: their vector table is
    // `board::mps2::__INTERRUPTS`) makes `link.x` include a `device.x`, where a device
    // crate names its handlers; the MPS2's all go to `DefaultHandler`, so it is empty.
    if std::env::var_os("CARGO_FEATURE_MPS2_AN386").is_some()
        || std::env::var_os("CARGO_FEATURE_MPS2_AN385").is_some()
    {
        let out =
            std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
        std::fs::write(
            out.join("device.x"),
            "/* The MPS2 boards: every device interrupt goes to DefaultHandler (firmware/build.rs). */\n",
        )
        .expect("writing device.x");
    }
    println!("cargo:rerun-if-changed=memory/select.rs");
    println!("cargo:rerun-if-changed=build.rs");
}

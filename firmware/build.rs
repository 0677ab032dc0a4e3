//! Selects the board's memory layout (`memory/select.rs`): see docs/target.md, "Boards".
include!("memory/select.rs");

fn main() {
    select_memory_x(std::path::Path::new("memory"));
    println!("cargo:rerun-if-changed=memory/select.rs");
    println!("cargo:rerun-if-changed=build.rs");
}

//! Build script of the FMU binary: links it without DWARF debug information (the workspace's
//! release profile keeps `debug = 1` for the jointrom executable's profiles and backtraces;
//! in the shared object packaged into every FMU it would be ~90 % of its ~45 MB). The symbol
//! table stays, so backtraces and valgrind still name functions.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rustc-cdylib-link-arg=-Wl,--strip-debug");
}

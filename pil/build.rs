//! Link setup of the PIL image for QEMU's mps2-an386; a no-op for host builds.
//!
//! The image is laid out by this crate's `mps2-an386.x` (memory map and sections in one
//! file; why not cortex-m-rt's `link.x` plus a `memory.x` is said at its top), copied into
//! `OUT_DIR` and given to the linker; `defmt.x` places the defmt string table.
use std::env;
use std::fs;
use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=mps2-an386.x");
    if env::var("CARGO_CFG_TARGET_OS").unwrap_or_default() != "none" {
        return;
    }
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("mps2-an386.x", out.join("mps2-an386.x")).expect("pil/mps2-an386.x is readable");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tmps2-an386.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}

//! Link setup for the STM32G474RE application; a no-op for host builds.
//!
//! The memory map is the workspace's top-level `memory.x` (embassy-stm32's generated one is
//! disabled so there is exactly one description of the part): its directory goes on the
//! linker search path, and cortex-m-rt's `link.x` includes it. `defmt.x` places the defmt
//! string table. The arguments apply to binaries only, so the library links anywhere.
use std::env;
use std::path::PathBuf;

fn main() {
    let target_os = env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    println!("cargo:rerun-if-changed=build.rs");
    if target_os != "none" {
        return;
    }
    let manifest_dir = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let workspace_root = manifest_dir
        .parent()
        .map(PathBuf::from)
        .unwrap_or(manifest_dir);
    println!(
        "cargo:rerun-if-changed={}",
        workspace_root.join("memory.x").display()
    );
    println!("cargo:rustc-link-search={}", workspace_root.display());
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}

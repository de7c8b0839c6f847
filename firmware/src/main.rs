//! STM32G474RE application (target only).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("the firmware binary runs on the STM32G474RE: build it with `cargo fw`, or `cargo run --release` inside firmware/");
    std::process::exit(2);
}

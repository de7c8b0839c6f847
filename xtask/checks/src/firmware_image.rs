//! Step 5 of `cargo xtask test` (and `cargo xtask fw-size`): the firmware for the
//! STM32G474RE built with warnings denied, and its flash and static-RAM use, read from the
//! ELF's sections, against the budget (written to `target/firmware-size.json`).

use anyhow::{bail, Context, Result};
use object::{Object, ObjectSection, SectionFlags};
use std::path::Path;
use xtask::setup::{ensure_target, TARGET};
use xtask::workspace::target_dir;

/// 96 KiB: an STM32G431xB (128 KiB) still holds the image and the parameter store's pages.
pub const FLASH_BUDGET: u64 = 96 * 1024;
/// Static RAM the firmware may use.
pub const RAM_BUDGET: u64 = 16 * 1024;
/// The STM32G474RE's RAM as `memory.x` describes it. With flip-link the stack has all of
/// it below the statics: at least this less [`RAM_BUDGET`].
pub const FIRMWARE_RAM: u64 = 128 * 1024;

/// Builds the firmware image with warnings denied and checks its size.
pub fn firmware() -> Result<(u64, u64)> {
    ensure_target()?;
    xtask::images::build("firmware (warnings denied)", "firmware")?;
    let target_dir = target_dir();
    let elf = target_dir.join(TARGET).join("release").join("firmware");
    let (flash, ram) = image_size(&elf)?;
    let json = format!(
        "{{\"flash_bytes\": {flash}, \"static_ram_bytes\": {ram}, \"flash_budget_bytes\": {FLASH_BUDGET}, \"ram_budget_bytes\": {RAM_BUDGET}}}\n"
    );
    std::fs::create_dir_all(&target_dir)?;
    std::fs::write(target_dir.join("firmware-size.json"), json)?;
    eprintln!(
        "firmware: flash {flash} B ({:.1} KiB of {} KiB), static RAM {ram} B ({:.1} KiB of {} KiB)",
        flash as f64 / 1024.0,
        FLASH_BUDGET / 1024,
        ram as f64 / 1024.0,
        RAM_BUDGET / 1024
    );
    if flash > FLASH_BUDGET || ram > RAM_BUDGET {
        bail!("the firmware exceeds its flash/RAM budget (see above)");
    }
    Ok((flash, ram))
}

/// Flash = allocated sections with contents (code, read-only data, .data's load image);
/// static RAM = writable allocated sections (.data, .bss, .uninit). Stack is not static.
fn image_size(elf: &Path) -> Result<(u64, u64)> {
    let data = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let file = object::File::parse(&*data).with_context(|| format!("parsing {}", elf.display()))?;
    let (mut flash, mut ram) = (0, 0);
    for s in file.sections() {
        let SectionFlags::Elf { sh_flags } = s.flags() else {
            continue;
        };
        const ALLOC: u64 = 0x2;
        const WRITE: u64 = 0x1;
        if sh_flags & ALLOC == 0 {
            continue;
        }
        let has_contents = s.kind() != object::SectionKind::UninitializedData;
        if sh_flags & WRITE != 0 {
            ram += s.size();
        }
        if has_contents {
            flash += s.size();
        }
    }
    Ok((flash, ram))
}

//! The firmware's own stack paths, run on the Cortex-M4F with the firmware's code and
//! measured one by one ([`crate::stack::depth`]), for the margin the drive's stack must
//! keep. The PIL cannot run the board (embassy, its drivers), but everything the board
//! calls into the control core for:
//!
//! - boot: the controller built from the configuration, the stored parameter table and
//!   the torque feed-forward table loaded from the parameter store (on a RAM flash with the
//!   G474's page and double-word geometry), the controller moved into a static — the
//!   application's `main` up to `control::install`;
//! - the CAN task: a parameter save with its feed-forward table (its deepest command), a
//!   served `SetParameter` and `GetParameter`.
//!
//! The telemetry task's frame logged through defmt and the control interrupt's body are
//! measured in the run itself ([`crate::target`]): the latter bounded by the closed-loop
//! step, which runs the same `Controller::on_current_sample` and the plant besides.

use core::mem::MaybeUninit;

use crate::stack::depth;
use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use firmware::can_protocol::Request;
use firmware::can_server::serve;
use firmware::compensation::record;
use firmware::compensation::Table;
use firmware::param_store::{boot, ParamStore, SPAN, TABLE_LEN};
use firmware::parameters::{self, ParamId};
use firmware::{Config, Controller};

/// The G474's erase page in dual-bank mode. [bytes]
const PAGE: usize = 2048;
/// One slot: whole pages holding a record. [bytes]
const SLOT: usize = SPAN.div_ceil(PAGE) * PAGE;

/// Stack used below the caller by each path. [bytes]
#[derive(Clone, Copy, Default)]
pub struct Depths {
    /// Boot up to the controller's install.
    pub boot: u32,
    /// A parameter save with the feed-forward table.
    pub save: u32,
    /// Served `SetParameter` and `GetParameter`.
    pub serve: u32,
}

/// A RAM flash of two slots with the G4's rules (erase to 0xFF by page, program whole
/// erased double words).
struct RamFlash {
    mem: [u8; 2 * SLOT],
}

#[derive(Debug)]
struct Refused;

impl NorFlashError for Refused {
    fn kind(&self) -> NorFlashErrorKind {
        NorFlashErrorKind::Other
    }
}

impl ErrorType for RamFlash {
    type Error = Refused;
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Refused> {
        let at = offset as usize;
        bytes.copy_from_slice(self.mem.get(at..at + bytes.len()).ok_or(Refused)?);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.mem.len()
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = 8;
    const ERASE_SIZE: usize = PAGE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Refused> {
        self.mem
            .get_mut(from as usize..to as usize)
            .ok_or(Refused)?
            .fill(0xFF);
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Refused> {
        let at = offset as usize;
        let dst = self.mem.get_mut(at..at + bytes.len()).ok_or(Refused)?;
        if at % 8 != 0 || bytes.len() % 8 != 0 || dst.iter().any(|b| *b != 0xFF) {
            return Err(Refused);
        }
        dst.copy_from_slice(bytes);
        Ok(())
    }
}

static mut FLASH: RamFlash = RamFlash {
    mem: [0xFF; 2 * SLOT],
};
static mut CONTROLLER: MaybeUninit<Controller> = MaybeUninit::uninit();

fn store() -> Option<ParamStore<&'static mut RamFlash>> {
    // SAFETY: the PIL is single-threaded and the stores made here never overlap.
    let flash = unsafe { &mut *core::ptr::addr_of_mut!(FLASH) };
    ParamStore::new(flash, 0, SLOT as u32, SLOT as u32).ok()
}

/// Measures every path on `config`; `table` is the feed-forward table saved and loaded.
/// `None` when a path fails (the store refused its layout, the saved table did not load).
pub fn measure(config: &Config, table: &Table) -> Option<Depths> {
    let values = parameters::snapshot(config);
    let (saved, save) =
        depth(|| store().and_then(|mut s| s.save(&values, record::source(table)).ok()));
    saved?;
    let (controller, boot_depth) = depth(|| boot_like_the_firmware(config));
    let controller = controller?;
    let speed_kp = ParamId::SpeedKp.default_value();
    let (served, serve_depth) = depth(|| {
        let set = serve(
            &Request::SetParameter {
                id: ParamId::SpeedKp,
                value: speed_kp,
            },
            controller,
        );
        let get = serve(
            &Request::GetParameter {
                id: ParamId::SpeedKp,
            },
            controller,
        );
        (set, get)
    });
    let _ = served;
    Some(Depths {
        boot: boot_depth,
        save,
        serve: serve_depth,
    })
}

/// The application's boot from the configuration to the installed controller.
#[inline(never)]
fn boot_like_the_firmware(config: &Config) -> Option<&'static mut Controller> {
    let mut controller = Controller::new(config);
    let mut s = store()?;
    boot(&mut s, |v| controller.load_parameters(v).is_ok());
    controller
        .load_compensation_record(TABLE_LEN, |at, buf| s.read_table(at, buf))
        .ok()?;
    // SAFETY: written once, before any reference to it is taken.
    let slot = unsafe { &mut *core::ptr::addr_of_mut!(CONTROLLER) };
    Some(slot.write(controller))
}

//! What the firmware's integration tests share: the power-up the board goes through, and a
//! RAM NOR flash with the G4's page and programming unit for the parameter store's save and
//! boot paths.

use embedded_storage::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};
use firmware::{Controller, Measurements};

/// Power-up as on the board: the current offsets measured at rest (0.05 s at 20 kHz: 0 A,
/// 280 V, 3 MPa), then the encoder index passes (captured at counter 0).
pub fn power_up(c: &mut Controller) {
    let at_rest = Measurements {
        adc_dc_link: 2800,
        adc_pressure: 6554 + 6291,
        ..Measurements::default()
    };
    for _ in 0..1000 {
        c.on_current_sample(&at_rest);
    }
    c.on_current_sample(&Measurements {
        encoder_index: true,
        ..at_rest
    });
}

/// A RAM NOR flash: 2 KiB pages, 8-byte programming unit, erased to 0xFF.
pub struct RamFlash(pub Vec<u8>);

impl ErrorType for RamFlash {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;
    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        let at = offset as usize;
        bytes.copy_from_slice(&self.0[at..at + bytes.len()]);
        Ok(())
    }
    fn capacity(&self) -> usize {
        self.0.len()
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = 8;
    const ERASE_SIZE: usize = 2048;
    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.0[from as usize..to as usize].fill(0xFF);
        Ok(())
    }
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        let at = offset as usize;
        self.0[at..at + bytes.len()].copy_from_slice(bytes);
        Ok(())
    }
}

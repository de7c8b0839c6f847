//! A flash whose reads fail when the flash reported an uncorrectable ECC error while they
//! ran.
//!
//! The G4 programs its flash a double word at a time, with 8 ECC bits per double word. A
//! double word whose programming was cut by a power loss can hold data and ECC bits that
//! disagree in two or more places: reading it sets FLASH_ECCR.ECCD and raises a
//! non-maskable interrupt (RM0440, flash ECC). The board's NMI handler counts such errors
//! and clears the flag; [`EccChecked`] compares that count before and after each read and
//! turns a read that raised one into [`CheckedError::Ecc`], which [`super::ParamStore`]
//! treats like any unreadable record: that copy is refused, the other copy (or the
//! defaults, with fault 16) loads. The record's CRC refuses a torn double word as well
//! when the error goes unreported (the bytes served from the data cache, say); the count
//! makes the refusal certain even where the torn bits happen to read as valid data.

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Why a read, erase or write of an [`EccChecked`] flash failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CheckedError<E> {
    /// The flash driver failed.
    Flash(E),
    /// The flash reported a double-bit ECC error while the read ran.
    Ecc,
}

impl<E: NorFlashError> NorFlashError for CheckedError<E> {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            CheckedError::Flash(e) => e.kind(),
            CheckedError::Ecc => NorFlashErrorKind::Other,
        }
    }
}

/// `flash` with reads checked against `ecc_errors`, the number of uncorrectable ECC errors
/// reported so far (wrapping; it must include every error raised by a read before it
/// returns — on the board, after the barriers that let a pending NMI run).
#[derive(Debug)]
pub struct EccChecked<F, C> {
    flash: F,
    ecc_errors: C,
}

impl<F, C: Fn() -> u32> EccChecked<F, C> {
    /// Wraps `flash`.
    pub fn new(flash: F, ecc_errors: C) -> EccChecked<F, C> {
        EccChecked { flash, ecc_errors }
    }

    /// Gives the flash back.
    pub fn into_inner(self) -> F {
        self.flash
    }
}

impl<F: ErrorType, C> ErrorType for EccChecked<F, C> {
    type Error = CheckedError<F::Error>;
}

impl<F: ReadNorFlash, C: Fn() -> u32> ReadNorFlash for EccChecked<F, C> {
    const READ_SIZE: usize = F::READ_SIZE;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        let before = (self.ecc_errors)();
        self.flash
            .read(offset, bytes)
            .map_err(CheckedError::Flash)?;
        if (self.ecc_errors)() == before {
            Ok(())
        } else {
            Err(CheckedError::Ecc)
        }
    }

    fn capacity(&self) -> usize {
        self.flash.capacity()
    }
}

impl<F: NorFlash, C: Fn() -> u32> NorFlash for EccChecked<F, C> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.flash.erase(from, to).map_err(CheckedError::Flash)
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.flash.write(offset, bytes).map_err(CheckedError::Flash)
    }
}

#[cfg(test)]
mod tests;

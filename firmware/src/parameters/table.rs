//! The whole table at once: a snapshot of every value, a stored table applied at boot
//! (all or nothing, [`TableError`]), and the table's layout fingerprints that tell a
//! stored record of another table apart ([`crate::param_store`]).

use super::cross_check::cross_check;
use super::id::{ParamError, ParamId, COUNT, LEGACY_COUNT};
use crate::config::error::ConfigError;
use crate::config::sections::Config;
use crate::param_crc::CRC;

/// Why a whole stored table was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TableError {
    /// A value outside its own bounds.
    Value(ParamError),
    /// Every value within its bounds, but the configuration fails validation.
    Inconsistent(ConfigError),
}

/// All parameter values of `cfg`, in [`ParamId::ALL`] order.
pub fn snapshot(cfg: &Config) -> [f32; COUNT] {
    ParamId::ALL.map(|p| p.get(cfg))
}

/// Writes every value of `values` (in [`ParamId::ALL`] order) into `cfg` after checking
/// each against its bounds and the result with [`Config::validate`]; on any refusal `cfg`
/// is left as it was. Used at boot for a stored table, whose values may be individually
/// valid and only consistent together.
pub fn apply_all(cfg: &mut Config, values: &[f32; COUNT]) -> Result<(), TableError> {
    let mut next = *cfg;
    for (p, v) in ParamId::ALL.iter().zip(values) {
        p.check(*v).map_err(TableError::Value)?;
        p.write(&mut next, *v);
    }
    cross_check(&next).map_err(TableError::Inconsistent)?;
    *cfg = next;
    Ok(())
}

/// CRC-32 of the table's ids and names in order: changes whenever a parameter is added,
/// removed, renumbered or renamed, so a stored record of another table is recognised.
/// Computed at compile time (no names walked at run time).
pub const LAYOUT_FINGERPRINT: u32 = fingerprint(COUNT);

/// The fingerprint of the table before ids 64–68 ([`LEGACY_COUNT`] parameters, the first
/// ones of [`ParamId::ALL`]).
pub const LEGACY_FINGERPRINT: u32 = fingerprint(LEGACY_COUNT);

/// CRC-32 of the first `n` parameters' ids and names.
const fn fingerprint(n: usize) -> u32 {
    let mut digest = CRC.digest();
    let mut i = 0;
    while i < n {
        let p = ParamId::ALL[i];
        digest.update(&[p as u8]);
        digest.update(p.spec().name.as_bytes());
        i += 1;
    }
    digest.finalize()
}

//! What `eha compensate` loads into a drive, and the table file that carries it: the
//! angle-indexed q-current table, stored as the drive's table record
//! ([`firmware::compensation::record`]), and, when the pump's ripple was learned, the speed
//! modulation's parameters in the file's trailer ([`flow`]). `eha compensate` learns and
//! writes it ([`crate::compensate`]), a run loads it into the controller as the drive
//! does from flash ([`crate::run::load_compensation`]), `eha simulate --compensation`
//! reads it ([`read_table`]).

pub mod flow;

use crate::output::CliError;
use firmware::compensation::record::{self, RECORD_LEN};
use firmware::compensation::{Compensation, Table};
use flow::FlowParams;
use plant_model::Rig;

/// What `eha compensate` loads into a drive: the torque table and, when the pump's ripple
/// was learned, the speed modulation's parameters ([`flow`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Feedforward {
    /// The angle-indexed q-current table.
    pub table: Table,
    /// The speed modulation against the pump's flow ripple (`None`: off).
    pub flow: Option<FlowParams>,
}

impl Feedforward {
    /// The table alone (no speed modulation).
    pub fn table_only(table: Table) -> Feedforward {
        Feedforward { table, flow: None }
    }

    /// The table file: the drive's table record, then the modulation's parameter trailer
    /// if there is one.
    pub fn file_bytes(&self) -> Vec<u8> {
        let mut bytes = vec![0u8; RECORD_LEN];
        if let Ok(b) = <&mut [u8; RECORD_LEN]>::try_from(bytes.as_mut_slice()) {
            record::Encoder::write_all(&self.table, b);
        }
        if let Some(f) = &self.flow {
            bytes.extend_from_slice(&f.trailer());
        }
        bytes
    }

    /// Checks it against `rig`'s controller configuration as the drive would: the table's
    /// amplitude, the modulation's parameters and depth. The error names the bound.
    pub fn check(&self, rig: &Rig) -> Result<(), String> {
        let mut cfg = closed_loop::controller_config(rig);
        cfg.compensation.enabled = true;
        Compensation::check_amplitude(&self.table, &cfg).map_err(|e| e.to_string())?;
        match &self.flow {
            Some(f) => f.apply(&mut cfg),
            None => Ok(()),
        }
    }
}

/// Longest table file: the record and a trailer of the modulation's parameters. [bytes]
const MAX_FILE_LEN: u64 = RECORD_LEN as u64 + 12 + 8 * flow::FLOW_IDS.len() as u64;

/// Reads a table file written by `eha compensate` and checks it as the drive checks its
/// stored table (size, magic, version, bins, channels, exponents, CRC), then its amplitude
/// against the limit of `rig`'s controller configuration, and the modulation's parameter
/// trailer if there is one ([`flow`]). Bad input names the file.
pub fn read_table(path: &std::path::Path, rig: &Rig) -> Result<Feedforward, CliError> {
    let bad =
        |why: String| CliError::BadInput(format!("compensation table `{}`: {why}", path.display()));
    let len = std::fs::metadata(path)
        .map_err(|e| bad(crate::output::file_kind::describe(&e)))?
        .len();
    if !(RECORD_LEN as u64..=MAX_FILE_LEN).contains(&len) {
        return Err(bad(record::RecordError::Length {
            found: usize::try_from(len).unwrap_or(usize::MAX),
        }
        .to_string()));
    }
    let bytes = std::fs::read(path).map_err(|e| bad(crate::output::file_kind::describe(&e)))?;
    let (rec, trailer) = bytes.split_at(RECORD_LEN.min(bytes.len()));
    let mut table = Table::ZERO;
    record::from_bytes(rec, &mut table).map_err(|e| bad(e.to_string()))?;
    let flow = if trailer.is_empty() {
        None
    } else {
        Some(FlowParams::from_trailer(trailer).map_err(bad)?)
    };
    let ff = Feedforward { table, flow };
    ff.check(rig).map_err(bad)?;
    Ok(ff)
}

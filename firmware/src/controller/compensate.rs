//! The controller's side of the torque feed-forward ([`crate::compensation`]): its table's
//! loading (CAN, flash, host), the amplitude limit held against every change of table,
//! scale or limit, and the bench sweep ([`crate::sweep`]).

use super::command::{Command, CommandError};
use super::drive::Controller;
use crate::compensation::{Compensation, CompensationError, Table};
use crate::config::Config;
use crate::parameters::{ParamError, ParamId};
use crate::supervisor::FaultCode;
use crate::sweep::Sweep;

impl Controller {
    /// The torque feed-forward (its table, whether it acts, its lead).
    pub fn compensation(&self) -> &Compensation {
        &self.compensation
    }

    /// The feed-forward's q current of the last period (0 outside Speed and Pressure). [A]
    pub fn compensation_current(&self) -> f32 {
        self.iq_ff
    }

    /// Boot and host entry point: reads a table record of `len` bytes through `read`
    /// ([`crate::compensation::record::read`]) into the feed-forward and checks its
    /// amplitude against the live parameters. A refused table leaves the feed-forward
    /// empty (the drive runs uncompensated); the caller latches
    /// [`Controller::report_compensation_invalid`] (boot) or reports the error (host).
    pub fn load_compensation_record(
        &mut self,
        len: usize,
        read: impl FnMut(usize, &mut [u8]) -> bool,
    ) -> Result<(), CompensationError> {
        self.compensation.load_record(len, read, &self.cfg)
    }

    /// Replaces the feed-forward's table with `table` (checked against the amplitude
    /// limit; a refused one leaves the table empty).
    pub fn install_compensation(&mut self, table: &Table) -> Result<(), CompensationError> {
        self.compensation.install(table, &self.cfg)
    }

    /// The stored feed-forward table was refused at boot (wrong size, version, CRC or
    /// amplitude): latches [`FaultCode::CompensationTableInvalid`]; the drive runs
    /// uncompensated once it is cleared.
    pub fn report_compensation_invalid(&mut self) {
        self.sup.trip(FaultCode::CompensationTableInvalid);
    }

    /// The feed-forward's commands.
    pub(super) fn apply_compensation(&mut self, c: Command) -> Result<(), CommandError> {
        let cfg = self.cfg;
        match c {
            Command::CompensationHeader { exponents, bins } => {
                self.compensation.begin(exponents, bins, &cfg)
            }
            Command::CompensationBin { bin, raw } => self.compensation.bin(bin, raw),
            Command::CompensationCommit { crc } => self.compensation.commit(crc, &cfg),
            Command::CompensationSweep { speed_rad_s, leg_s } => {
                let sweep = Sweep::plan(
                    self.sup.mode(),
                    speed_rad_s,
                    leg_s,
                    cfg.speed.speed_limit_rad_s,
                    cfg.rates.pwm_hz,
                )
                .map_err(CommandError::StepTest)?;
                self.step = None;
                self.sweep = Some(sweep);
                return Ok(());
            }
            _ => return Ok(()),
        }
        .map_err(CommandError::Compensation)
    }

    /// Setting parameter `id` to `value` keeps the speed modulation's depth
    /// `scale·flow_ratio` within `compensation.max_flow_ratio`; otherwise the refusal
    /// names the bound: the largest ratio or scale, or the smallest limit, the others
    /// allow. (A value outside its own bounds is left to [`ParamId::set`].)
    pub(super) fn check_flow_depth(&self, id: ParamId, value: f32) -> Result<(), ParamError> {
        let c = &self.cfg.compensation;
        let (scale, ratio, max) = match id {
            ParamId::CompensationScale => (value, c.flow_ratio, c.max_flow_ratio),
            ParamId::CompensationFlowRatio => (c.scale, value, c.max_flow_ratio),
            ParamId::CompensationMaxFlowRatio => (c.scale, c.flow_ratio, value),
            _ => return Ok(()),
        };
        if id.check(value).is_err() || scale * ratio <= max {
            return Ok(());
        }
        Err(match id {
            ParamId::CompensationMaxFlowRatio => ParamError::BelowMinimum {
                id,
                min: scale * ratio,
            },
            ParamId::CompensationScale => ParamError::AboveMaximum {
                id,
                max: max / ratio,
            },
            _ => ParamError::AboveMaximum {
                id,
                max: max / scale,
            },
        })
    }

    /// A change of parameter `id` giving the configuration `next` keeps the feed-forward's
    /// amplitude within its limit; otherwise the refusal names the bound: the largest
    /// scale, or the smallest limit, the present table allows.
    pub(super) fn check_compensation_parameter(
        &self,
        id: ParamId,
        next: &Config,
    ) -> Result<(), ParamError> {
        let table = self.compensation.table();
        let Err(CompensationError::Amplitude {
            amplitude_a,
            limit_a,
        }) = Compensation::check_amplitude(table, next)
        else {
            return Ok(());
        };
        match id {
            ParamId::CompensationMaxCurrent => Err(ParamError::BelowMinimum {
                id,
                min: amplitude_a,
            }),
            // The amplitude is proportional to the scale.
            ParamId::CompensationScale => Err(ParamError::AboveMaximum {
                id,
                max: next.compensation.scale * limit_a / amplitude_a,
            }),
            // The per-current channel's share grows with the q-current limit.
            ParamId::SpeedIqLimit => {
                let [c0, cp, ci] = table.peak();
                let p = next.limits.over_pressure_pa;
                let room = limit_a / next.compensation.scale.max(f32::MIN_POSITIVE) - c0 - cp * p;
                Err(ParamError::AboveMaximum {
                    id,
                    max: if ci > 0.0 { room / ci } else { 0.0 },
                })
            }
            // Nothing else moves the amplitude (enabling does not: the table was checked
            // at its commit).
            _ => Ok(()),
        }
    }
}

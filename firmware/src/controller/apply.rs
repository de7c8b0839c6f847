//! How a command is applied between control steps: mode changes, setpoints, live
//! parameters (retuning every loop bumplessly) and step tests.

use super::calibration_state::Calibration;
use super::command::{Command, CommandError};
use super::drive::Controller;
use crate::parameters::{ParamError, ParamId};
use crate::pi::saturate;
use crate::step_test::{self, ActiveStep, StepLoop, StepTestError};
use crate::supervisor::{FaultCode, Mode};

impl Controller {
    /// Takes a command. Any command (accepted or not) restarts the command timeout; a
    /// refusal's code shows in telemetry until the next accepted command.
    pub fn command(&mut self, c: Command) -> Result<(), CommandError> {
        self.since_command = 0;
        let result = self.apply(c);
        self.command_status = match &result {
            Ok(()) => 0,
            Err(e) => e.code(),
        };
        result
    }

    pub(super) fn apply(&mut self, c: Command) -> Result<(), CommandError> {
        if matches!(
            c,
            Command::SetPressure { .. } | Command::SetSpeed { .. } | Command::SetMode(_)
        ) {
            // A new setpoint or mode supersedes a running step test or sweep; the new
            // value wins, so the test ends without restoring its base.
            self.step = None;
            self.sweep = None;
        }
        match c {
            Command::Heartbeat => Ok(()),
            Command::SetParameter { id, value } => {
                if id.needs_disabled() && self.sup.mode() != Mode::Disabled {
                    return Err(CommandError::Parameter(ParamError::NotWhileRunning { id }));
                }
                self.check_flow_depth(id, value)
                    .map_err(CommandError::Parameter)?;
                let mut next = self.cfg;
                id.set(&mut next, value).map_err(CommandError::Parameter)?;
                self.check_compensation_parameter(id, &next)
                    .map_err(CommandError::Parameter)?;
                self.cfg = next;
                if id == ParamId::CompensationClear && value == 1.0 {
                    self.compensation.clear(&self.cfg);
                }
                self.retune(id);
                Ok(())
            }
            Command::CompensationHeader { .. }
            | Command::CompensationBin { .. }
            | Command::CompensationCommit { .. }
            | Command::CompensationSweep { .. } => self.apply_compensation(c),
            Command::StepTest {
                target,
                amplitude,
                duration_s,
            } => self.start_step(target, amplitude, duration_s),
            Command::SetPressure { pa } => {
                let p = &self.cfg.pressure;
                if pa.is_nan() || pa < p.setpoint_min_pa || pa > p.setpoint_max_pa {
                    return Err(CommandError::PressureOutOfRange {
                        min_pa: p.setpoint_min_pa,
                        max_pa: p.setpoint_max_pa,
                    });
                }
                self.pressure_target = Some(pa);
                self.pressure.set_target(pa);
                Ok(())
            }
            Command::SetSpeed { rad_s } => {
                let max = self.cfg.speed.speed_limit_rad_s;
                if rad_s.is_nan() || rad_s.abs() > max {
                    return Err(CommandError::SpeedOutOfRange { max_rad_s: max });
                }
                self.speed_setpoint = rad_s;
                Ok(())
            }
            Command::Commission => {
                self.apply(Command::SetMode(Mode::Calibrating))?;
                self.commission_requested = true;
                Ok(())
            }
            Command::ClearFaults => {
                let cleared = self.sup.fault();
                self.sup.clear().map_err(CommandError::CausePresent)?;
                if matches!(
                    cleared,
                    Some(FaultCode::EncoderJump | FaultCode::EncoderIndexLost)
                ) {
                    // Counts may have been lost: the counter's tie to the rotor is gone.
                    self.encoder.forget_reference();
                }
                self.encoder.rearm();
                Ok(())
            }
            Command::SetMode(mode) => {
                let from = self.sup.mode();
                self.sup.set_readiness(self.readiness());
                self.sup.request(mode).map_err(CommandError::Mode)?;
                if from != mode && mode == Mode::Pressure && from == Mode::Speed {
                    // Bumpless hand-over: the pressure loop starts from the present speed
                    // reference.
                    self.pressure.reset(self.p_pa, self.speed_ref);
                    self.pressure
                        .set_target(self.pressure_target.unwrap_or(self.p_pa));
                }
                if from != mode && mode == Mode::Calibrating {
                    self.calibration = Calibration::START;
                }
                self.commission_requested = false;
                Ok(())
            }
        }
    }

    /// Brings the loops to the configuration after parameter `id` changed. Every loop is
    /// retuned (cheap, and a no-op for an unchanged value); gains and limits move without
    /// resetting any state, so the outputs do not jump.
    pub(super) fn retune(&mut self, id: ParamId) {
        self.current.retune(&self.cfg);
        self.speed.retune(&self.cfg);
        self.observer
            .set_bandwidth(self.cfg.speed.observer_bandwidth_rad_s);
        self.pressure.retune(&self.cfg);
        self.compensation.retune(&self.cfg);
        if id == ParamId::EncoderOffset {
            self.encoder.set_offset(self.cfg.sensors.encoder_offset_rad);
        }
        // Setpoints held from before a limit change stay within the new limits.
        let p = &self.cfg.pressure;
        if let Some(t) = self.pressure_target {
            let t = saturate(t, p.setpoint_min_pa, p.setpoint_max_pa);
            self.pressure_target = Some(t);
            self.pressure.set_target(t);
        }
        let w = self.cfg.speed.speed_limit_rad_s;
        self.speed_setpoint = saturate(self.speed_setpoint, -w, w);
    }

    /// Starts a step test (ending a running one first, with its base restored).
    pub(super) fn start_step(
        &mut self,
        target: StepLoop,
        amplitude: f32,
        duration_s: f32,
    ) -> Result<(), CommandError> {
        let required = target.mode();
        if self.sup.mode() != required {
            return Err(CommandError::StepTest(StepTestError::WrongMode {
                required,
            }));
        }
        if let Some(s) = self.step {
            self.end_step(s);
        }
        let (reference, lo, hi) = match target {
            StepLoop::Current => {
                let l = self.cfg.speed.iq_limit_a;
                (self.iq_ref, -l, l)
            }
            StepLoop::Speed => {
                let l = self.cfg.speed.speed_limit_rad_s;
                (self.speed_setpoint, -l, l)
            }
            StepLoop::Pressure => {
                let p = &self.cfg.pressure;
                let now = self.pressure_target.unwrap_or(self.pressure.setpoint());
                (now, p.setpoint_min_pa, p.setpoint_max_pa)
            }
        };
        let s = step_test::plan(
            target,
            amplitude,
            duration_s,
            reference,
            (lo, hi),
            self.cfg.rates.pwm_hz,
        )
        .map_err(CommandError::StepTest)?;
        self.set_step_reference(target, s.stepped);
        self.step = Some(s);
        Ok(())
    }

    /// Counts a running step test down at the start of a period (this period is stepped
    /// while any remain); ends it when its time is up or its mode was left.
    #[inline]
    pub(super) fn advance_step(&mut self, step: ActiveStep, mode: Mode) {
        if mode != step.target.mode() || step.remaining == 0 {
            self.end_step(step);
        } else {
            self.step = Some(ActiveStep {
                remaining: step.remaining - 1,
                ..step
            });
        }
    }

    /// Ends a step test and restores the reference it stepped from.
    pub(super) fn end_step(&mut self, step: ActiveStep) {
        self.step = None;
        match step.target {
            // The speed loop resumes from the stepped current: its integral takes it.
            StepLoop::Current => self.speed.set_integral(step.stepped),
            target => self.set_step_reference(target, step.base),
        }
    }

    pub(super) fn set_step_reference(&mut self, target: StepLoop, value: f32) {
        match target {
            StepLoop::Current => self.iq_ref = value,
            StepLoop::Speed => self.speed_setpoint = value,
            StepLoop::Pressure => {
                self.pressure_target = Some(value);
                self.pressure.set_target(value);
            }
        }
    }
}

//! What the controller tells its callers (configuration, mode, fault, readiness, the
//! calibration's and commissioning's results, telemetry), the live parameter table as a
//! whole, and the faults the application reports to it (a hardware break, an overrun, an
//! unusable parameter store, a watchdog reset).

use super::drive::Controller;
use crate::commissioning::{Commissioning, CommissioningResult};
use crate::config::Config;
use crate::parameters::{self, ParamId, TableError, COUNT};
use crate::step_test::ActiveStep;
use crate::supervisor::{Conditions, FaultCode, Mode, Readiness};
use crate::telemetry::TelemetryFrame;

impl Controller {
    /// Replaces the whole live table (boot: the stored table, in
    /// [`ParamId::ALL`] order): every value checked against its bounds, the whole against
    /// [`crate::parameters::cross_check()`], then applied like [`Command::SetParameter`].
    /// On a refusal nothing changes. Cheaper in flash than building the controller from a
    /// run-time configuration: [`Controller::new`] on the constant nominal configuration
    /// folds away at compile time.
    ///
    /// [`Command::SetParameter`]: super::command::Command::SetParameter
    pub fn load_parameters(&mut self, values: &[f32; COUNT]) -> Result<(), TableError> {
        parameters::apply_all(&mut self.cfg, values)?;
        self.retune(ParamId::EncoderOffset);
        Ok(())
    }

    /// Value of a live parameter. [the parameter's unit]
    pub fn parameter(&self, id: ParamId) -> f32 {
        id.get(&self.cfg)
    }

    /// PWM periods per telemetry frame the application should log at now: 1 while a step
    /// test runs, else `rates.telemetry_decimation`.
    pub fn telemetry_decimation(&self) -> u32 {
        if self.step.is_some_and(|s| s.remaining > 0) {
            1
        } else {
            self.cfg.rates.telemetry_decimation
        }
    }

    /// The running step test, if any.
    pub fn step_test(&self) -> Option<ActiveStep> {
        self.step
    }

    /// Boot entry point: the stored parameter table could not be used and the defaults
    /// were loaded. Latches [`FaultCode::ParameterStoreInvalid`], so the drive will not
    /// start until the operator has seen it and cleared it.
    pub fn report_parameter_store_invalid(&mut self) {
        self.sup.trip(FaultCode::ParameterStoreInvalid);
    }

    /// Board entry point: the power stage's hardware break cut the bridge (gate-driver
    /// fault line, phase-current comparator, or a break the firmware forced). Latches
    /// [`FaultCode::HardwareBreak`] and drops to Disabled, so the bridge comes back only
    /// after the operator cleared it.
    pub fn report_hardware_break(&mut self) {
        self.sup.trip(FaultCode::HardwareBreak);
    }

    /// Boot entry point: the flash is not in the layout the parameter store needs, so
    /// nothing was loaded. Latches [`FaultCode::ParameterFlashLayout`].
    pub fn report_parameter_flash_layout(&mut self) {
        self.sup.trip(FaultCode::ParameterFlashLayout);
    }

    /// Boot entry point: the previous run ended in an independent-watchdog reset (a
    /// stalled loop, a panic or a HardFault). Latches [`FaultCode::Watchdog`], so the
    /// operator sees it before the drive runs again.
    pub fn report_watchdog_reset(&mut self) {
        self.sup.trip(FaultCode::Watchdog);
    }

    /// Configuration in use.
    pub fn config(&self) -> &Config {
        &self.cfg
    }

    /// Current mode.
    pub fn mode(&self) -> Mode {
        self.sup.mode()
    }

    /// Latched fault.
    pub fn fault(&self) -> Option<FaultCode> {
        self.sup.fault()
    }

    /// Fault conditions present in the last sample (latched or not).
    pub fn conditions(&self) -> Conditions {
        self.sup.conditions()
    }

    /// What the drive is ready for: the current offsets measured since power-up, the rotor
    /// angle known (encoder index seen or alignment run in this power cycle).
    pub fn readiness(&self) -> Readiness {
        Readiness {
            current_offsets: self.offsets_measured,
            rotor_angle: self.encoder.angle_known(),
        }
    }

    /// True once a calibration has completed.
    pub fn is_calibrated(&self) -> bool {
        self.calibrated
    }

    /// True once the current offsets in use were measured in this power cycle (at boot or
    /// by a calibration's first phase), or the configuration trusts its zero.
    pub fn offsets_measured(&self) -> bool {
        self.offsets_measured
    }

    /// Zero-current ADC results in use. [counts]
    pub fn current_offsets(&self) -> [f32; 3] {
        self.current.offsets()
    }

    /// The last completed commissioning's result (identified motor, derived gains).
    pub fn commissioning_result(&self) -> Option<CommissioningResult> {
        self.commissioning.result()
    }

    /// The commissioning sequence's state (progress, intermediate values).
    pub fn commissioning(&self) -> &Commissioning {
        &self.commissioning
    }

    /// Encoder electrical offset in use, relative to the index. [rad]
    pub fn encoder_offset(&self) -> f32 {
        self.encoder.offset()
    }

    /// Counter value at the encoder index, once the index has been seen (or at once for a
    /// counter referenced from the start). [counts]
    pub fn encoder_index_count(&self) -> Option<u32> {
        self.encoder.index_count()
    }

    /// The live table (and a later save) holds an offset the encoder has just tied to the
    /// index (an alignment's, or one converted at the first index).
    pub(super) fn take_learned_encoder_offset(&mut self) {
        if let Some(offset) = self.encoder.take_learned_offset() {
            self.cfg.sensors.encoder_offset_rad = offset;
        }
    }

    /// Watchdog entry point: the application calls this when a control loop overran. The
    /// fault latches at once and the mode drops to Disabled; the next
    /// [`Controller::on_current_sample`] returns disabled PWM (the application should also
    /// disable the bridge itself).
    pub fn report_overrun(&mut self) {
        self.sup.trip(FaultCode::Watchdog);
    }

    /// Telemetry of the last sample.
    pub fn telemetry(&self) -> TelemetryFrame {
        let mode = self.sup.mode();
        let p_ref = match (mode, self.pressure_target) {
            (Mode::Pressure, _) => self.pressure.setpoint(),
            (_, Some(t)) => t,
            (_, None) => 0.0,
        };
        TelemetryFrame {
            // The instant the frame's measurements were sampled (the first sample is t = 0),
            // the same clock as the plant's in a simulated bench log.
            t_s: self.samples.saturating_sub(1) as f64 / self.d.pwm_hz,
            p_ref_pa: p_ref,
            p_pa: self.p_pa,
            speed_rad_s: self.speed.speed(),
            iq_a: self.state.i_dq.q,
            id_a: self.state.i_dq.d,
            theta_m_rad: self.theta_m,
            speed_ref_rad_s: self.speed_ref,
            iq_ref_a: self.iq_ref + self.iq_ff,
            ud_v: self.state.u_dq.d,
            uq_v: self.state.u_dq.q,
            udc_v: self.state.u_dc,
            mode,
            fault: self.sup.fault(),
            command_status: self.command_status,
        }
    }
}

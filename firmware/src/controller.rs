//! The controller façade: one call per PWM period ([`Controller::on_current_sample`]) runs
//! the current loop, the speed and pressure loops at their divided rates, the calibration
//! sequence and the supervisor checks; [`Controller::command`] takes the commands.
//!
//! Order inside one call: encoder decode and speed observer → pressure loop (on its tick) → speed loop (on its
//! tick) → current loop → fault conditions → supervisor. A fault found in a call returns
//! disabled PWM from that same call.
//!
//! Start-up: in Disabled, with the bridge off, the first `calibration.offset_time_s` of
//! samples measure the phase-current offsets; no active mode is granted before
//! ([`crate::supervisor::Readiness`]). The encoder offset is the table's
//! `sensors.encoder_offset_rad`, relative to the index: on an incremental counter Speed
//! and Pressure wait until the index has been seen (or Calibrating has aligned the rotor)
//! in this power cycle. A configuration for a counter referenced from the start and
//! trusted offsets (`sensors.encoder_referenced_at_start`, `calibration.offsets_at_boot`
//! off: the simulator's) may enter Speed and Pressure straight from Disabled. Calibrating
//! measures both offsets again and replaces them; it ends in Disabled.
//!
//! Parameters ([`Command::SetParameter`]) and step tests ([`Command::StepTest`]) are
//! applied inside [`Controller::command`], which never runs during a control step: on the
//! target the command path and the current-loop interrupt share one critical-section
//! mutex, on the host they are sequential calls. A change therefore takes effect at the
//! start of the next step, with no pending-change buffer to keep; gains move bumplessly
//! ([`crate::pi::Pi::set_gains`]: the integral absorbs the change of the proportional term).
//!
//! Entering Pressure holds the measured pressure until a pressure setpoint is commanded;
//! the pressure loop starts bumplessly from the present speed reference. Entering Speed
//! uses the last commanded speed setpoint (0 if none).

use crate::commissioning::{Commissioning, CommissioningResult};
use crate::compensation::{Compensation, CompensationError, Exponent, CHANNELS};
use crate::config::{whole_ratio, Config};
use crate::current_loop::{CurrentLoop, CurrentLoopState};
use crate::encoder::{max_step_counts, Encoder, EncoderEvent};
use crate::io::{Measurements, Outputs};
use crate::parameters::{self, ParamError, ParamId, TableError, COUNT};
use crate::pi::saturate;
use crate::plausibility::{current_sum_off, StallMonitor};
use crate::pressure_loop::PressureLoop;
use crate::speed_loop::SpeedLoop;
use crate::speed_observer::SpeedObserver;
use crate::step_test::{self, ActiveStep, StepLoop, StepTestError};
use crate::supervisor::{Conditions, FaultCode, Mode, ModeRefusal, Readiness, Supervisor};
use crate::sweep::Sweep;
use crate::telemetry::TelemetryFrame;
use crate::transforms::Dq;
use calibrate::{Calibration, OffsetAverage};
use core::fmt;

/// A command to the drive (CAN or host).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Requests a mode.
    SetMode(Mode),
    /// Pressure setpoint (gauge). [Pa]
    SetPressure {
        /// Setpoint. [Pa]
        pa: f32,
    },
    /// Speed setpoint. [rad/s]
    SetSpeed {
        /// Setpoint. [rad/s]
        rad_s: f32,
    },
    /// Clears a latched fault once its cause is gone.
    ClearFaults,
    /// Keeps the command timeout from expiring.
    Heartbeat,
    /// Enters Calibrating and runs the commissioning sequence after the current offsets
    /// (motor identification and gain design, [`crate::commissioning`]) instead of the
    /// plain encoder alignment.
    Commission,
    /// Sets one parameter of the live table (bounds: [`ParamId::min`], [`ParamId::max`]).
    SetParameter {
        /// The parameter.
        id: ParamId,
        /// New value. [the parameter's unit]
        value: f32,
    },
    /// Steps one loop's reference for a while with telemetry at full rate
    /// ([`crate::step_test`]).
    StepTest {
        /// The stepped loop.
        target: StepLoop,
        /// Step added to the present reference. [A, rad/s or Pa]
        amplitude: f32,
        /// How long the step is held. [s]
        duration_s: f32,
    },
    /// Starts loading the torque feed-forward's table ([`crate::compensation`]): the
    /// feed-forward is off until the commit.
    CompensationHeader {
        /// LSB exponent e per channel (values are i16 · 2^−e). [1]
        exponents: [Exponent; CHANNELS],
        /// Bins per revolution of the table sent (must be [`crate::compensation::BINS`]).
        bins: u16,
    },
    /// The next bin of the table being loaded (in order from 0).
    CompensationBin {
        /// Bin index.
        bin: u16,
        /// The three channels' raw values.
        raw: [i16; CHANNELS],
    },
    /// Ends a table load: the CRC of the record the bins make; the table is checked
    /// against the amplitude limit and takes effect.
    CompensationCommit {
        /// CRC-32 of the table's record ([`crate::compensation::record`]).
        crc: u32,
    },
    /// The feed-forward's bench procedure ([`crate::sweep`]): a constant-speed sweep in
    /// both directions, in Speed mode.
    CompensationSweep {
        /// Speed of the first leg. [rad/s]
        speed_rad_s: f32,
        /// Duration of each leg. [s]
        leg_s: f32,
    },
}

/// Why a command was refused. Its [`CommandError::code`] shows in telemetry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CommandError {
    /// Pressure setpoint outside `[min_pa, max_pa]` (`pressure.setpoint_min_pa`,
    /// `pressure.setpoint_max_pa`), or not finite.
    PressureOutOfRange {
        /// Lower bound. [Pa]
        min_pa: f32,
        /// Upper bound. [Pa]
        max_pa: f32,
    },
    /// Speed setpoint magnitude above `max_rad_s` (`speed.speed_limit_rad_s`), or not
    /// finite.
    SpeedOutOfRange {
        /// Bound on the magnitude. [rad/s]
        max_rad_s: f32,
    },
    /// Mode request refused.
    Mode(ModeRefusal),
    /// ClearFaults refused: the fault's cause is still present.
    CausePresent(FaultCode),
    /// Parameter value refused.
    Parameter(ParamError),
    /// Step test (or feed-forward sweep) refused.
    StepTest(StepTestError),
    /// Feed-forward table refused.
    Compensation(CompensationError),
}

impl CommandError {
    /// Status code for telemetry and CAN replies (0 means accepted).
    pub fn code(&self) -> u8 {
        match self {
            CommandError::PressureOutOfRange { .. } => 1,
            CommandError::SpeedOutOfRange { .. } => 2,
            CommandError::Mode(ModeRefusal::Faulted(_)) => 3,
            CommandError::Mode(ModeRefusal::ConditionPresent(_)) => 4,
            CommandError::Mode(ModeRefusal::Transition { .. }) => 5,
            CommandError::Mode(ModeRefusal::NotReady(_)) => 9,
            CommandError::CausePresent(_) => 6,
            CommandError::Parameter(_) => 7,
            CommandError::StepTest(_) => 8,
            CommandError::Compensation(_) => 10,
        }
    }
}

impl fmt::Display for CommandError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CommandError::PressureOutOfRange { min_pa, max_pa } => write!(
                f,
                "pressure setpoint outside [{min_pa} Pa, {max_pa} Pa] (pressure.setpoint_min_pa..=pressure.setpoint_max_pa)"
            ),
            CommandError::SpeedOutOfRange { max_rad_s } => write!(
                f,
                "speed setpoint magnitude above {max_rad_s} rad/s (speed.speed_limit_rad_s)"
            ),
            CommandError::Mode(ModeRefusal::Faulted(x)) => {
                write!(f, "mode refused: {x} is latched (clear it first)")
            }
            CommandError::Mode(ModeRefusal::ConditionPresent(x)) => {
                write!(f, "mode refused: condition present ({x})")
            }
            CommandError::Mode(ModeRefusal::Transition { from, to }) => {
                write!(f, "mode refused: {from:?} -> {to:?} (go through Disabled)")
            }
            CommandError::Mode(ModeRefusal::NotReady(r)) => {
                write!(f, "mode refused: not ready, {r}")
            }
            CommandError::CausePresent(x) => write!(f, "clear refused: cause still present ({x})"),
            CommandError::Parameter(e) => write!(f, "parameter refused: {e}"),
            CommandError::StepTest(StepTestError::WrongMode { required }) => {
                write!(f, "step test refused: needs mode {required:?}")
            }
            CommandError::StepTest(StepTestError::BelowMinimum { min }) => {
                write!(f, "step test refused: amplitude below {min} (loop limit)")
            }
            CommandError::StepTest(StepTestError::AboveMaximum { max }) => {
                write!(f, "step test refused: amplitude above {max} (loop limit)")
            }
            CommandError::StepTest(StepTestError::Duration { bound_s }) => {
                write!(f, "step test refused: duration beyond {bound_s} s")
            }
            CommandError::Compensation(e) => write!(f, "{e}"),
        }
    }
}

/// Constants derived once from the configuration.
#[derive(Clone, Copy, Debug)]
struct Derived {
    pwm_hz: f64,
    speed_div: u32,
    pressure_div: u32,
    timeout_calls: u32,
    offset_calls: u32,
    precharge_calls: u32,
    align_calls: u32,
    pole_pairs: f32,
}

/// The drive controller.
#[derive(Clone, Debug)]
pub struct Controller {
    cfg: Config,
    d: Derived,
    current: CurrentLoop,
    speed: SpeedLoop,
    observer: SpeedObserver,
    pressure: PressureLoop,
    encoder: Encoder,
    sup: Supervisor,
    calibration: Calibration,
    active_last_call: bool,
    samples: u64,
    speed_tick: u32,
    pressure_tick: u32,
    p_sum: u32,
    p_n: u32,
    since_command: u32,
    speed_setpoint: f32,
    pressure_target: Option<f32>,
    speed_ref: f32,
    iq_ref: f32,
    id_ref: f32,
    p_pa: f32,
    theta_m: f32,
    state: CurrentLoopState,
    command_status: u8,
    calibrated: bool,
    /// The phase-current offsets in use were measured in this power cycle (or the
    /// configuration trusts its zero: `calibration.offsets_at_boot` off).
    offsets_measured: bool,
    boot_offsets: OffsetAverage,
    /// Bootstrap-precharge periods left before the bridge's first switching period.
    precharge_left: u32,
    commissioning: Commissioning,
    commission_requested: bool,
    /// Open-loop voltage commissioning asked for this period. [V]
    open_loop_voltage: Option<Dq>,
    commission_speed_on: bool,
    /// The current loop runs at a forced angle this period (no speed decoupling).
    forced_frame: bool,
    step: Option<ActiveStep>,
    /// The torque feed-forward (table, gain, lead).
    compensation: Compensation,
    /// The feed-forward's q current this period. [A]
    iq_ff: f32,
    /// The feed-forward's bench sweep, while it runs.
    sweep: Option<Sweep>,
    stall: StallMonitor,
}

impl Controller {
    /// From an already validated configuration (see [`Config::validate`]).
    pub fn new(config: &Config) -> Controller {
        let r = &config.rates;
        let pwm = r.pwm_hz.max(1.0);
        let calls = |s: f32| ((s * pwm) as u32).max(1);
        let precharge_calls = (config.calibration.bootstrap_precharge_s * pwm + 0.5) as u32;
        let max_step = max_step_counts(
            config.limits.encoder_plausible_speed_rad_s,
            pwm,
            config.sensors.encoder_counts_per_rev,
        );
        Controller {
            cfg: *config,
            d: Derived {
                pwm_hz: pwm as f64,
                speed_div: whole_ratio(pwm, r.speed_loop_hz).unwrap_or(1),
                pressure_div: whole_ratio(pwm, r.pressure_loop_hz).unwrap_or(1),
                timeout_calls: calls(config.limits.command_timeout_s),
                offset_calls: calls(config.calibration.offset_time_s),
                precharge_calls,
                align_calls: calls(config.calibration.alignment_time_s),
                pole_pairs: config.motor.pole_pairs as f32,
            },
            current: CurrentLoop::new(config),
            speed: SpeedLoop::new(config),
            observer: SpeedObserver::new(
                config.speed.observer_bandwidth_rad_s,
                pwm,
                config.sensors.encoder_counts_per_rev,
            ),
            pressure: PressureLoop::new(config),
            encoder: {
                let e = Encoder::new(
                    config.sensors.encoder_counts_per_rev,
                    config.motor.pole_pairs,
                    config.sensors.encoder_offset_rad,
                    max_step,
                );
                if config.sensors.encoder_referenced_at_start {
                    e
                } else {
                    e.with_unknown_reference()
                }
            },
            sup: Supervisor::new(),
            calibration: Calibration::START,
            active_last_call: false,
            samples: 0,
            speed_tick: 0,
            pressure_tick: 0,
            p_sum: 0,
            p_n: 0,
            since_command: 0,
            speed_setpoint: 0.0,
            pressure_target: None,
            speed_ref: 0.0,
            iq_ref: 0.0,
            id_ref: 0.0,
            p_pa: 0.0,
            theta_m: 0.0,
            state: CurrentLoopState::default(),
            command_status: 0,
            calibrated: false,
            offsets_measured: !config.calibration.offsets_at_boot,
            boot_offsets: OffsetAverage::START,
            precharge_left: precharge_calls,
            commissioning: Commissioning::new(config),
            commission_requested: false,
            open_loop_voltage: None,
            commission_speed_on: false,
            forced_frame: false,
            step: None,
            compensation: Compensation::new(config),
            iq_ff: 0.0,
            sweep: None,
            stall: StallMonitor::new(config.limits.stall_time_s, pwm),
        }
    }

    /// Replaces the whole live table (boot: the stored table, in
    /// [`ParamId::ALL`] order): every value checked against its bounds, the whole against
    /// [`crate::parameters::cross_check`], then applied like [`Command::SetParameter`].
    /// On a refusal nothing changes. Cheaper in flash than building the controller from a
    /// run-time configuration: [`Controller::new`] on the constant nominal configuration
    /// folds away at compile time.
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
    fn take_learned_encoder_offset(&mut self) {
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

    /// Pressure from the ADC result (gauge). [Pa]
    #[inline]
    fn pressure_pa(&self, counts: f32) -> f32 {
        (counts - self.cfg.sensors.pressure_zero_lsb) * self.cfg.sensors.pressure_pa_per_lsb
    }

    /// The current-loop ISR body: infallible, allocation-free.
    pub fn on_current_sample(&mut self, m: &Measurements) -> Outputs {
        self.samples = self.samples.wrapping_add(1);
        self.since_command = self.since_command.saturating_add(1);
        let enc_event =
            self.encoder
                .update(m.encoder_count, m.encoder_index, m.encoder_index_count);
        if m.encoder_index {
            self.take_learned_encoder_offset();
        }
        // An implausible jump is not a shaft movement: the observer coasts over it, so a
        // one-sample glitch does not leave a speed transient behind after it latched its
        // fault.
        if enc_event == EncoderEvent::Jump {
            self.observer.coast();
        } else {
            self.observer.update(self.encoder.position());
        }
        self.theta_m = self.encoder.mechanical_angle(m.encoder_count);
        let mut theta_e = self.encoder.electrical_angle(m.encoder_count);
        self.p_pa = self.pressure_pa(m.adc_pressure as f32);
        self.p_sum = self.p_sum.saturating_add(m.adc_pressure as u32);
        self.p_n += 1;

        let mode = self.sup.mode();
        if mode.is_active() && !self.active_last_call {
            self.on_enter_active(mode);
        }
        if let Some(step) = self.step {
            self.advance_step(step, mode);
        }

        // Pressure loop tick (before the speed loop so it uses the fresh reference).
        self.pressure_tick += 1;
        if self.pressure_tick >= self.d.pressure_div {
            self.pressure_tick = 0;
            let mean = self.pressure_pa(self.p_sum as f32 / self.p_n.max(1) as f32);
            self.p_sum = 0;
            self.p_n = 0;
            if mode == Mode::Pressure {
                if let Some(t) = self.pressure_target {
                    self.pressure.set_target(t);
                }
                self.speed_ref = self.pressure.step(mean);
            }
        }
        if let Some(sweep) = &mut self.sweep {
            match (mode, sweep.advance()) {
                (Mode::Speed, Some(w)) => self.speed_setpoint = w,
                _ => {
                    self.speed_setpoint = 0.0;
                    self.sweep = None;
                }
            }
        }
        // Speed loop tick.
        self.speed_tick += 1;
        if self.speed_tick >= self.d.speed_div {
            self.speed_tick = 0;
            let w = self.speed.measure(self.observer.angle());
            match mode {
                Mode::Speed => {
                    self.speed_ref = self.speed_setpoint;
                    self.iq_ref = match self.step {
                        // A current step suspends the speed loop (its integral is held).
                        Some(ActiveStep {
                            target: StepLoop::Current,
                            stepped,
                            ..
                        }) => stepped,
                        _ => self.speed_step(w),
                    };
                }
                Mode::Pressure => self.iq_ref = self.speed_step(w),
                Mode::Calibrating => self.commission_speed_tick(w),
                _ => {}
            }
        }

        // Current references by mode; calibration may hold the bridge off or force θ_e.
        let mut bridge = mode.is_active();
        let mut conditions = Conditions::default();
        self.iq_ff = 0.0;
        let mut flux_ripple = 0.0;
        match mode {
            Mode::Speed | Mode::Pressure => {
                self.id_ref = 0.0;
                (self.iq_ff, flux_ripple) = self.compensation.current(
                    self.theta_m,
                    self.speed.speed(),
                    self.p_pa,
                    self.iq_ref,
                );
            }
            Mode::Calibrating => {
                let (on, theta, fault) = self.calibrate(m);
                bridge = on;
                theta_e = theta;
                if let Some(f) = fault {
                    conditions.set(f, true);
                }
            }
            Mode::Disabled => {
                if !self.offsets_measured {
                    self.measure_boot_offsets(m);
                }
            }
        }

        let omega_e = if self.forced_frame {
            0.0
        } else {
            self.speed.speed() * self.d.pole_pairs
        };
        // The first periods after the bridge comes on charge the high-side gate drivers'
        // bootstrap capacitors: all three low sides on (zero vector), no current control.
        let precharging = bridge && self.precharge_left > 0;
        if precharging {
            self.open_loop_voltage = None;
        }
        self.state = if bridge && !precharging {
            let i_ref = Dq {
                d: self.id_ref,
                q: self.iq_ref + self.iq_ff,
            };
            match self.open_loop_voltage.take() {
                Some(u) => self.current.apply_voltage(m, theta_e, u),
                None => self.current.step(m, theta_e, i_ref, omega_e, flux_ripple),
            }
        } else {
            CurrentLoopState {
                i_abc: self.current.phase_currents(m),
                u_dc: m.adc_dc_link as f32 * self.cfg.sensors.dc_link_v_per_lsb,
                duties: [0.5; 3],
                ..CurrentLoopState::default()
            }
        };

        // Fault conditions of this sample.
        let l = &self.cfg.limits;
        let s = &self.cfg.sensors;
        // A NaN current counts as over-current (a fold with f32::max would drop the NaN, and
        // costs an fmaxf call per phase on the M4F).
        let over_current = self
            .state
            .i_abc
            .iter()
            .any(|i| i.is_nan() || i.abs() > l.over_current_a);
        conditions.set(FaultCode::PhaseOverCurrent, over_current);
        conditions.set(
            FaultCode::DcLinkOverVoltage,
            self.state.u_dc > l.over_voltage_v,
        );
        conditions.set(
            FaultCode::DcLinkUnderVoltage,
            self.state.u_dc < l.under_voltage_v,
        );
        let open = m.adc_pressure < s.pressure_open_wire_lsb;
        let short = m.adc_pressure > s.pressure_short_lsb;
        conditions.set(FaultCode::PressureSensorOpenWire, open);
        conditions.set(FaultCode::PressureSensorShort, short);
        conditions.set(
            FaultCode::OverPressure,
            !open && !short && self.p_pa > l.over_pressure_pa,
        );
        conditions.set(FaultCode::EncoderJump, enc_event == EncoderEvent::Jump);
        conditions.set(
            FaultCode::EncoderIndexLost,
            enc_event == EncoderEvent::IndexLost,
        );
        conditions.set(
            FaultCode::OverSpeed,
            self.speed.speed().abs() > l.over_speed_rad_s,
        );
        conditions.set(
            FaultCode::CommandTimeout,
            mode.is_active() && self.since_command > self.d.timeout_calls,
        );
        // Until the offsets are measured each channel may be off by the calibration's
        // tolerance.
        // A calibration measures the offsets again: until it has, a bad one is its
        // CurrentOffset, so the sum allows for unmeasured offsets meanwhile.
        let offsets_a = if self.offsets_measured && mode != Mode::Calibrating {
            0.0
        } else {
            3.0 * self.cfg.calibration.offset_max_lsb * s.current_a_per_lsb
        };
        conditions.set(
            FaultCode::PhaseCurrentSum,
            current_sum_off(&self.state.i_abc, l.current_sum_a + offsets_a),
        );
        let sp = &self.cfg.speed;
        let stalled = self.stall.update(
            matches!(mode, Mode::Speed | Mode::Pressure),
            self.iq_ref,
            sp.iq_limit_a,
            self.speed.speed(),
            sp.speed_limit_rad_s,
        );
        conditions.set(FaultCode::Stall, stalled);

        let still_on = self.sup.check(conditions);
        self.active_last_call = self.sup.mode().is_active();
        if still_on && bridge {
            if precharging {
                self.precharge_left -= 1;
                // The current loop starts from rest after the precharge.
                self.current.reset();
                Outputs {
                    duties: [0.0; 3],
                    pwm_enabled: true,
                }
            } else {
                Outputs {
                    duties: self.state.duties,
                    pwm_enabled: true,
                }
            }
        } else {
            self.precharge_left = self.d.precharge_calls;
            if !still_on {
                self.state.u_dq = Dq::default();
                self.state.duties = [0.5; 3];
            }
            Outputs::DISABLED
        }
    }

    /// The speed loop's step on the measured speed `w` [rad/s] in Speed and Pressure: its
    /// reference modulated against the pump's flow ripple and the modulation's
    /// acceleration current added ([`crate::compensation::flow`]; off: the plain step),
    /// within the q-current limit. [A]
    #[inline]
    fn speed_step(&mut self, w: f32) -> f32 {
        let (w_ref, i_acc) = self
            .compensation
            .flow()
            .modulate(self.theta_m, self.speed_ref);
        let lim = self.cfg.speed.iq_limit_a;
        saturate(self.speed.step(w_ref, w) + i_acc, -lim, lim)
    }

    /// Resets the loops for a start from rest in `mode`.
    fn on_enter_active(&mut self, mode: Mode) {
        self.current.reset();
        self.speed.reset(self.observer.angle(), 0.0);
        self.speed_ref = 0.0;
        self.iq_ref = 0.0;
        self.id_ref = 0.0;
        self.speed_tick = 0;
        if mode == Mode::Pressure {
            self.pressure.reset(self.p_pa, 0.0);
            self.pressure
                .set_target(self.pressure_target.unwrap_or(self.p_pa));
        }
        if mode == Mode::Calibrating {
            self.calibration = Calibration::START;
        }
    }

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

    fn apply(&mut self, c: Command) -> Result<(), CommandError> {
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
    fn retune(&mut self, id: ParamId) {
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
    fn start_step(
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
    fn advance_step(&mut self, step: ActiveStep, mode: Mode) {
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
    fn end_step(&mut self, step: ActiveStep) {
        self.step = None;
        match step.target {
            // The speed loop resumes from the stepped current: its integral takes it.
            StepLoop::Current => self.speed.set_integral(step.stepped),
            target => self.set_step_reference(target, step.base),
        }
    }

    fn set_step_reference(&mut self, target: StepLoop, value: f32) {
        match target {
            StepLoop::Current => self.iq_ref = value,
            StepLoop::Speed => self.speed_setpoint = value,
            StepLoop::Pressure => {
                self.pressure_target = Some(value);
                self.pressure.set_target(value);
            }
        }
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

mod calibrate;
mod commission;
mod compensate;
#[cfg(test)]
mod tests;

//! The controller's state and its step: [`Controller::new`] derives the discrete-time
//! constants from a validated configuration, [`Controller::on_current_sample`] runs one
//! PWM period (encoder and speed observer → pressure loop → speed loop → current loop →
//! fault conditions → supervisor; see the [`super`] documentation for the order).

use super::calibration_state::{Calibration, OffsetAverage};
use crate::commissioning::Commissioning;
use crate::compensation::Compensation;
use crate::config::{whole_ratio, Config};
use crate::current_loop::{CurrentLoop, CurrentLoopState};
use crate::encoder::{max_step_counts, Encoder, EncoderEvent};
use crate::io::{Measurements, Outputs};
use crate::pi::saturate;
use crate::plausibility::{current_sum_off, StallMonitor};
use crate::pressure_loop::PressureLoop;
use crate::speed_loop::SpeedLoop;
use crate::speed_observer::SpeedObserver;
use crate::step_test::{ActiveStep, StepLoop};
use crate::supervisor::{Conditions, FaultCode, Mode, Supervisor};
use crate::sweep::Sweep;
use crate::transforms::Dq;

/// Constants derived once from the configuration.
#[derive(Clone, Copy, Debug)]
pub(super) struct Derived {
    pub(super) pwm_hz: f64,
    pub(super) speed_div: u32,
    pub(super) pressure_div: u32,
    pub(super) timeout_calls: u32,
    pub(super) offset_calls: u32,
    pub(super) precharge_calls: u32,
    pub(super) align_calls: u32,
    pub(super) pole_pairs: f32,
}

/// The drive controller.
#[derive(Clone, Debug)]
pub struct Controller {
    pub(super) cfg: Config,
    pub(super) d: Derived,
    pub(super) current: CurrentLoop,
    pub(super) speed: SpeedLoop,
    pub(super) observer: SpeedObserver,
    pub(super) pressure: PressureLoop,
    pub(super) encoder: Encoder,
    pub(super) sup: Supervisor,
    pub(super) calibration: Calibration,
    pub(super) active_last_call: bool,
    pub(super) samples: u64,
    pub(super) speed_tick: u32,
    pub(super) pressure_tick: u32,
    pub(super) p_sum: u32,
    pub(super) p_n: u32,
    pub(super) since_command: u32,
    pub(super) speed_setpoint: f32,
    pub(super) pressure_target: Option<f32>,
    pub(super) speed_ref: f32,
    pub(super) iq_ref: f32,
    pub(super) id_ref: f32,
    pub(super) p_pa: f32,
    pub(super) theta_m: f32,
    pub(super) state: CurrentLoopState,
    pub(super) command_status: u8,
    pub(super) calibrated: bool,
    /// The phase-current offsets in use were measured in this power cycle (or the
    /// configuration trusts its zero: `calibration.offsets_at_boot` off).
    pub(super) offsets_measured: bool,
    pub(super) boot_offsets: OffsetAverage,
    /// Bootstrap-precharge periods left before the bridge's first switching period.
    pub(super) precharge_left: u32,
    pub(super) commissioning: Commissioning,
    pub(super) commission_requested: bool,
    /// Open-loop voltage commissioning asked for this period. [V]
    pub(super) open_loop_voltage: Option<Dq>,
    pub(super) commission_speed_on: bool,
    /// The current loop runs at a forced angle this period (no speed decoupling).
    pub(super) forced_frame: bool,
    pub(super) step: Option<ActiveStep>,
    /// The torque feed-forward (table, gain, lead).
    pub(super) compensation: Compensation,
    /// The feed-forward's q current this period. [A]
    pub(super) iq_ff: f32,
    /// The feed-forward's bench sweep, while it runs.
    pub(super) sweep: Option<Sweep>,
    pub(super) stall: StallMonitor,
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

    /// Pressure from the ADC result (gauge). [Pa]
    #[inline]
    pub(super) fn pressure_pa(&self, counts: f32) -> f32 {
        (counts - self.cfg.sensors.pressure_zero_lsb) * self.cfg.sensors.pressure_pa_per_lsb
    }

    /// The current-loop ISR body: infallible, allocation-free. One PWM period, stage by
    /// stage (each an always-inlined helper, so the ISR compiles to one function).
    pub fn on_current_sample(&mut self, m: &Measurements) -> Outputs {
        self.samples = self.samples.wrapping_add(1);
        self.since_command = self.since_command.saturating_add(1);
        let (enc_event, mut theta_e) = self.track_shaft(m);
        self.sample_pressure(m);

        let mode = self.sup.mode();
        if mode.is_active() && !self.active_last_call {
            self.on_enter_active(mode);
        }
        if let Some(step) = self.step {
            self.advance_step(step, mode);
        }

        // Pressure loop tick (before the speed loop so it uses the fresh reference).
        self.pressure_loop_tick(mode);
        self.advance_sweep(mode);
        self.speed_loop_tick(mode);

        let mut conditions = Conditions::default();
        let (bridge, flux_ripple) = self.current_references(m, mode, &mut theta_e, &mut conditions);
        let precharging = self.current_loop_step(m, theta_e, bridge, flux_ripple);

        // Fault conditions of this sample.
        self.power_stage_faults(&mut conditions);
        self.sensor_faults(m, enc_event, &mut conditions);
        self.operating_faults(mode, &mut conditions);

        let still_on = self.supervise(conditions);
        self.outputs(still_on, bridge, precharging)
    }

    /// Decodes the encoder's sample, learns the index's offset when it passes, moves the
    /// speed observer on and stores the mechanical angle; returns the encoder's event and
    /// the electrical angle θ_e. [rad]
    #[inline(always)]
    fn track_shaft(&mut self, m: &Measurements) -> (EncoderEvent, f32) {
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
        let theta_e = self.encoder.electrical_angle(m.encoder_count);
        (enc_event, theta_e)
    }

    /// Scales the pressure sample and adds it to the pressure loop's running mean.
    #[inline(always)]
    fn sample_pressure(&mut self, m: &Measurements) {
        self.p_pa = self.pressure_pa(m.adc_pressure as f32);
        self.p_sum = self.p_sum.saturating_add(m.adc_pressure as u32);
        self.p_n += 1;
    }

    /// On the pressure loop's tick: the mean pressure since the last tick, and in
    /// Pressure the loop's step on it into the speed reference.
    #[inline(always)]
    fn pressure_loop_tick(&mut self, mode: Mode) {
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
    }

    /// Moves the feed-forward's bench sweep on into the speed setpoint; ends it (setpoint
    /// 0) when it is done or the mode is no longer Speed.
    #[inline(always)]
    fn advance_sweep(&mut self, mode: Mode) {
        if let Some(sweep) = &mut self.sweep {
            match (mode, sweep.advance()) {
                (Mode::Speed, Some(w)) => self.speed_setpoint = w,
                _ => {
                    self.speed_setpoint = 0.0;
                    self.sweep = None;
                }
            }
        }
    }

    /// On the speed loop's tick: the measured speed, and the mode's q-current reference
    /// (Speed, Pressure) or commissioning speed step (Calibrating).
    #[inline(always)]
    fn speed_loop_tick(&mut self, mode: Mode) {
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
    }

    /// The current references by mode: the torque feed-forward in Speed and Pressure;
    /// in Calibrating the sequence, which may hold the bridge off, force `theta_e` and
    /// add its fault to `conditions`; in Disabled the boot offsets' measurement. Returns
    /// whether the bridge switches and the feed-forward's flux ripple.
    #[inline(always)]
    fn current_references(
        &mut self,
        m: &Measurements,
        mode: Mode,
        theta_e: &mut f32,
        conditions: &mut Conditions,
    ) -> (bool, f32) {
        let mut bridge = mode.is_active();
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
                *theta_e = theta;
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
        (bridge, flux_ripple)
    }

    /// The current loop's state of this period: its step (or the commissioning's open-loop
    /// voltage) while the bridge switches, the measured currents and DC link with centred
    /// duties otherwise. Returns whether the period precharges the bootstrap capacitors.
    #[inline(always)]
    fn current_loop_step(
        &mut self,
        m: &Measurements,
        theta_e: f32,
        bridge: bool,
        flux_ripple: f32,
    ) -> bool {
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
        precharging
    }

    /// The power stage's fault conditions: phase over-current, DC-link over- and
    /// under-voltage.
    #[inline(always)]
    fn power_stage_faults(&self, conditions: &mut Conditions) {
        let l = &self.cfg.limits;
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
    }

    /// The sensors' fault conditions: the pressure sensor's open wire and short, the
    /// over-pressure it measures (when plausible), the encoder's jump and lost index.
    #[inline(always)]
    fn sensor_faults(
        &self,
        m: &Measurements,
        enc_event: EncoderEvent,
        conditions: &mut Conditions,
    ) {
        let l = &self.cfg.limits;
        let s = &self.cfg.sensors;
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
    }

    /// The operation's fault conditions: over-speed, command timeout, the phase currents'
    /// sum off zero (allowing for unmeasured offsets), and the stall monitor's update.
    #[inline(always)]
    fn operating_faults(&mut self, mode: Mode, conditions: &mut Conditions) {
        let l = &self.cfg.limits;
        let s = &self.cfg.sensors;
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
    }

    /// The supervisor's check of this sample's `conditions`; notes whether the mode it
    /// leaves is active. Returns whether the drive may still switch.
    #[inline(always)]
    fn supervise(&mut self, conditions: Conditions) -> bool {
        let still_on = self.sup.check(conditions);
        self.active_last_call = self.sup.mode().is_active();
        still_on
    }

    /// The PWM outputs: the current loop's duties, or the zero vector while precharging
    /// (counting the precharge down, the current loop reset); disabled when the bridge is
    /// off or the supervisor tripped (the precharge re-armed; on a trip the voltages
    /// cleared and the duties centred).
    #[inline(always)]
    fn outputs(&mut self, still_on: bool, bridge: bool, precharging: bool) -> Outputs {
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
    pub(super) fn speed_step(&mut self, w: f32) -> f32 {
        let (w_ref, i_acc) = self
            .compensation
            .flow()
            .modulate(self.theta_m, self.speed_ref);
        let lim = self.cfg.speed.iq_limit_a;
        saturate(self.speed.step(w_ref, w) + i_acc, -lim, lim)
    }

    /// Resets the loops for a start from rest in `mode`.
    pub(super) fn on_enter_active(&mut self, mode: Mode) {
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
}

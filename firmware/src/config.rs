//! Controller configuration: SI parameters of the drive, the sensors, the loops, the
//! hydraulics the pressure loop is scheduled from, and the supervisor's limits.
//!
//! [`Config::nominal`] is the nominal rig (`contracts/nominal-rig.md`) with the Table 1
//! gains of the paper (Section 3.1). A configuration is checked once by
//! [`Config::validate`]; the control step then never re-checks it. Configuration is kept
//! apart from controller state: [`crate::Controller::new`] derives its discrete-time
//! constants from a validated `Config` and never mutates it.

pub use crate::commissioning::CommissioningConfig;
pub use crate::compensation::CompensationConfig;
use core::fmt;

/// Sample rates of the three loops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rates {
    /// PWM frequency = current-loop rate (one ADC sample and one control step per PWM
    /// period). 1 kHz..=100 kHz. [Hz]
    pub pwm_hz: f32,
    /// Speed-loop rate; `pwm_hz / speed_loop_hz` must be a whole number. [Hz]
    ///
    /// Default 2 kHz: the speed loop's crossover is about 200 rad/s (K_t·Kp/J), so a
    /// 2 kHz loop (a half-sample hold plus a half-sample measurement window ≈ 0.5 ms)
    /// costs about 6° of phase there. Speed is the difference of the speed observer's angle
    /// over one speed period ([`crate::speed_observer`]), not of the raw count, whose
    /// quantum 2π·f/N = 1.26 rad/s at 2 kHz with 10 000 counts/rev (0.18 A of q-current
    /// reference) would dither the low-speed holding.
    pub speed_loop_hz: f32,
    /// Pressure-loop rate; `pwm_hz / pressure_loop_hz` must be a whole number. [Hz]
    pub pressure_loop_hz: f32,
    /// PWM periods per telemetry frame (1..=10 000); 20 gives 1 kHz at 20 kHz PWM. A step
    /// test forces 1 (full rate) while it runs. [1]
    pub telemetry_decimation: u32,
}

/// Conversion of the raw peripheral readings to SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorScaling {
    /// Phase-current LSB. [A/count]
    pub current_a_per_lsb: f32,
    /// Phase-current ADC result at 0 A before calibration (mid-scale). [counts]
    pub current_zero_lsb: f32,
    /// Shortest low-side conduction before the sampling instant for a valid low-side
    /// shunt reading: dead time, switching ringing, amplifier settling and ADC sampling
    /// ([`crate::shunt`]). Sets the largest readable duty 1 − 2·t·f_PWM; at most 1/4 of a
    /// PWM period. [s]
    pub shunt_settling_s: f32,
    /// DC-link voltage LSB (0 counts = 0 V). [V/count]
    pub dc_link_v_per_lsb: f32,
    /// Pressure LSB of the 16-bit oversampled result. [Pa/count]
    pub pressure_pa_per_lsb: f32,
    /// Pressure ADC result at 0 Pa gauge. [counts]
    pub pressure_zero_lsb: f32,
    /// Below this the transducer loop is open (4–20 mA open wire). [counts]
    pub pressure_open_wire_lsb: u16,
    /// Above this the transducer is shorted. [counts]
    pub pressure_short_lsb: u16,
    /// Encoder counts per mechanical revolution (timer ARR + 1). [counts]
    pub encoder_counts_per_rev: u32,
    /// Electrical angle at the encoder index: θ_e = p_n·θ_m(from the index) − offset.
    /// [rad]
    pub encoder_offset_rad: f32,
    /// The encoder counter reads 0 at the index from the first sample on (an absolute
    /// encoder interface, or the simulated encoder). False for an incremental counter
    /// zeroed wherever the board powered up (the NUCLEO's TIM2): the angle is then known
    /// only once the index has been seen or the alignment has run in this power cycle
    /// ([`crate::encoder`]), and Speed and Pressure wait for it.
    pub encoder_referenced_at_start: bool,
}

/// Motor and inverter (nominal rig; Section 3.1, eq. 1–6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motor {
    /// Pole pairs p_n. [1]
    pub pole_pairs: u32,
    /// Stator resistance R_s. [Ω]
    pub stator_resistance_ohm: f32,
    /// d-axis inductance L_d. [H]
    pub d_inductance_h: f32,
    /// q-axis inductance L_q. [H]
    pub q_inductance_h: f32,
    /// Permanent-magnet flux linkage ψ_f. [Wb]
    pub flux_linkage_wb: f32,
    /// Nominal DC-link voltage U_dc. [V]
    pub dc_link_nominal_v: f32,
}

/// d/q current PIs (Table 1: Pi-Id, Pi-Iq).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentLoopConfig {
    /// d-axis proportional gain. [V/A]
    pub kp_d: f32,
    /// d-axis integral gain. [V/(A·s)]
    pub ki_d: f32,
    /// q-axis proportional gain. [V/A]
    pub kp_q: f32,
    /// q-axis integral gain. [V/(A·s)]
    pub ki_q: f32,
    /// Symmetric output limit of each PI. [V]
    pub voltage_limit_v: f32,
    /// Add the speed-voltage decoupling feed-forward (−ω_e·L_q·i_q, ω_e·(L_d·i_d + ψ_f)).
    pub decoupling: bool,
}

/// Speed PI (Table 1: Speed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedLoopConfig {
    /// Proportional gain. [A/(rad/s)]
    pub kp: f32,
    /// Integral gain. [A/rad]
    pub ki: f32,
    /// Table 1's feedback gain Ba, used as active damping i_q* −= Ba·ω_m (see
    /// [`crate::speed_loop`]). [A/(rad/s)]
    pub active_damping: f32,
    /// Symmetric q-current reference limit. [A]
    pub iq_limit_a: f32,
    /// Largest speed reference magnitude (commands beyond are refused; the pressure loop
    /// is limited to it). [rad/s]
    pub speed_limit_rad_s: f32,
    /// Natural frequency ω_n of the speed observer on the encoder angle (critically
    /// damped PLL, see [`crate::speed_observer`]); at most a quarter of `rates.pwm_hz` in
    /// rad/s·s (ω_n·T ≤ 0.25, where the discrete loop stays close to its design). [rad/s]
    ///
    /// Default 1000 rad/s: five times the speed loop's ≈ 200 rad/s crossover (θ̂ adds −0.8°
    /// there) and low enough to average the count edges: at 5.7 rad/s the speed loop's
    /// estimate ripples by 0.05 rad/s rms instead of 0.63 rad/s (quantum 1.26 rad/s).
    pub observer_bandwidth_rad_s: f32,
}

/// Pressure PI design parameters (see [`crate::pressure_loop`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressureLoopConfig {
    /// Open-loop crossover the gain schedule holds at every operating point. [rad/s]
    pub bandwidth_rad_s: f32,
    /// PI corner ω_i = Ki/Kp as a fraction of the crossover. [1]
    pub integral_corner_ratio: f32,
    /// Corner of the first-order low-pass on the measured pressure. [rad/s]
    pub feedback_filter_rad_s: f32,
    /// Setpoint ramp rate. [Pa/s]
    pub ramp_pa_per_s: f32,
    /// Smallest accepted pressure setpoint (gauge). [Pa]
    pub setpoint_min_pa: f32,
    /// Largest accepted pressure setpoint (gauge). [Pa]
    pub setpoint_max_pa: f32,
}

/// Hydraulic facts the pressure-loop gain schedule is computed from (nominal rig).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hydraulics {
    /// Pump displacement D_p. [m³/rev]
    pub pump_displacement_m3_per_rev: f32,
    /// Oil volume on the pump's high-pressure side (chamber A with lines). [m³]
    pub oil_volume_m3: f32,
    /// Oil bulk modulus β_e. [Pa]
    pub bulk_modulus_pa: f32,
    /// Pulsation-absorber shell volume V_0 (0: no absorber). [m³]
    pub absorber_volume_m3: f32,
    /// Absorber gas precharge p_0 (gauge). [Pa]
    pub absorber_precharge_pa: f32,
    /// Gas polytropic exponent n. [1]
    pub polytropic_exponent: f32,
    /// Total leakage conductance from the high side. [(m³/s)/Pa]
    pub leakage_m3_per_s_pa: f32,
}

/// Supervisor trip levels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultLimits {
    /// Phase over-current trip (any phase, magnitude). [A]
    pub over_current_a: f32,
    /// Hardware over-current trip: a phase current of this size flowing out of the motor
    /// terminal through the low-side switch and its shunt (a short or a shoot-through)
    /// breaks the bridge within the comparator's and the break filter's delay, whatever
    /// the software does. Above `over_current_a`, within the current sensor's range. [A]
    pub hardware_over_current_a: f32,
    /// DC-link over-voltage trip. [V]
    pub over_voltage_v: f32,
    /// DC-link under-voltage trip (checked while the bridge is on). [V]
    pub under_voltage_v: f32,
    /// Over-pressure trip; below the 21 MPa relief valve. [Pa]
    pub over_pressure_pa: f32,
    /// Over-speed trip. [rad/s]
    pub over_speed_rad_s: f32,
    /// Fastest plausible shaft speed: a larger encoder step between two samples is a
    /// fault. [rad/s]
    pub encoder_plausible_speed_rad_s: f32,
    /// Time without any command before the command-timeout fault (active modes only). [s]
    pub command_timeout_s: f32,
    /// Largest magnitude of the sum of the three phase currents (zero in a star without a
    /// neutral): above it a current channel is wrong or current leaves the star through a
    /// short to a rail or earth ([`crate::plausibility`]). Until the current offsets are
    /// measured (a calibration's first phase), three times the offset tolerance
    /// (`calibration.offset_max_lsb`) is allowed besides. [A]
    pub current_sum_a: f32,
    /// Time the q-current reference may sit at its limit with the shaft measured below a
    /// tenth of the speed limit before the stall fault ([`crate::plausibility`]). [s]
    pub stall_time_s: f32,
}

/// Calibration sequence (mode Calibrating).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationConfig {
    /// Current-offset averaging time with PWM off. [s]
    pub offset_time_s: f32,
    /// Measure the phase-current offsets at power-up (bridge off, `offset_time_s`) and
    /// refuse every active mode until they are. False: `sensors.current_zero_lsb` is
    /// trusted until a Calibrating run (the simulated sensors, whose offset is an effect
    /// under study).
    pub offsets_at_boot: bool,
    /// Largest accepted offset from `current_zero_lsb`. [counts]
    pub offset_max_lsb: f32,
    /// d-axis alignment current. [A]
    pub alignment_current_a: f32,
    /// Bootstrap precharge: each time the bridge comes on, all three low sides conduct for
    /// this long (zero vector, no current control) before the first high-side pulse, so
    /// the high-side gate drivers' bootstrap capacitors are charged. 0 for a stage with
    /// isolated gate supplies (or the simulator's ideal switches); at most 10 ms. On a
    /// turning shaft the zero vector brakes: the current rises at most at back-EMF / L.
    /// [s]
    pub bootstrap_precharge_s: f32,
    /// Alignment time at θ_e = 0 (rotor settles on the d axis). [s]
    pub alignment_time_s: f32,
}

/// Whole controller configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Loop rates.
    pub rates: Rates,
    /// Sensor scaling.
    pub sensors: SensorScaling,
    /// Motor.
    pub motor: Motor,
    /// Current loops.
    pub current: CurrentLoopConfig,
    /// Speed loop.
    pub speed: SpeedLoopConfig,
    /// Pressure loop.
    pub pressure: PressureLoopConfig,
    /// Hydraulic model for the pressure-loop schedule.
    pub hydraulics: Hydraulics,
    /// Fault limits.
    pub limits: FaultLimits,
    /// Calibration.
    pub calibration: CalibrationConfig,
    /// Commissioning sequence (motor identification).
    pub commissioning: CommissioningConfig,
    /// Angle-indexed torque feed-forward ([`crate::compensation`]).
    pub compensation: CompensationConfig,
}

/// A configuration field that failed validation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConfigError {
    /// Dotted field path, e.g. `rates.pwm_hz`.
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: &'static str,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "config field `{}`: {}", self.field, self.problem)
    }
}

impl core::error::Error for ConfigError {}

fn err(field: &'static str, problem: &'static str) -> ConfigError {
    ConfigError { field, problem }
}

fn positive(field: &'static str, v: f32) -> Result<(), ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(field, "must be finite and > 0"))
    }
}

fn non_negative(field: &'static str, v: f32) -> Result<(), ConfigError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(err(field, "must be finite and >= 0"))
    }
}

/// Ratio `fast / slow` as a whole number ≥ 1, if it is one (within 1e-4 relative).
pub fn whole_ratio(fast: f32, slow: f32) -> Option<u32> {
    if !(fast.is_finite() && slow.is_finite() && fast > 0.0 && slow > 0.0 && slow <= fast) {
        return None;
    }
    let r = fast / slow;
    let n = (r + 0.5) as u32;
    if n >= 1 && (r - n as f32).abs() <= 1e-4 * r {
        Some(n)
    } else {
        None
    }
}

impl Config {
    /// The nominal rig with the Table 1 gains (`contracts/nominal-rig.md`).
    pub fn nominal() -> Config {
        Config {
            rates: Rates {
                pwm_hz: 20_000.0,
                speed_loop_hz: 2_000.0,
                pressure_loop_hz: 1_000.0,
                telemetry_decimation: 20,
            },
            sensors: SensorScaling {
                current_a_per_lsb: 100.0 / 4096.0,
                current_zero_lsb: 2048.0,
                shunt_settling_s: 2e-6,
                dc_link_v_per_lsb: 0.1,
                pressure_pa_per_lsb: 25e6 / 52428.8,
                pressure_zero_lsb: 6554.0,
                pressure_open_wire_lsb: 3277,
                pressure_short_lsb: 62259,
                encoder_counts_per_rev: 10_000,
                encoder_offset_rad: 0.0,
                encoder_referenced_at_start: false,
            },
            motor: Motor {
                pole_pairs: 4,
                stator_resistance_ohm: 0.958,
                d_inductance_h: 5.25e-3,
                q_inductance_h: 12e-3,
                flux_linkage_wb: 0.1827,
                dc_link_nominal_v: 280.0,
            },
            current: CurrentLoopConfig {
                kp_d: 5.775,
                ki_d: 1053.8,
                kp_q: 13.2,
                ki_q: 1053.8,
                voltage_limit_v: 161.6,
                decoupling: true,
            },
            speed: SpeedLoopConfig {
                kp: 0.14,
                ki: 7.0,
                active_damping: 0.013,
                iq_limit_a: 30.0,
                speed_limit_rad_s: 200.0,
                observer_bandwidth_rad_s: 1000.0,
            },
            pressure: PressureLoopConfig {
                bandwidth_rad_s: 20.0,
                integral_corner_ratio: 0.25,
                feedback_filter_rad_s: 150.0,
                ramp_pa_per_s: 10e6,
                setpoint_min_pa: 0.0,
                setpoint_max_pa: 18e6,
            },
            hydraulics: Hydraulics {
                pump_displacement_m3_per_rev: 1.5e-6,
                oil_volume_m3: 450e-6,
                bulk_modulus_pa: 6.5e8,
                absorber_volume_m3: 400e-6,
                absorber_precharge_pa: 3e6,
                polytropic_exponent: 1.3,
                leakage_m3_per_s_pa: 3e-13,
            },
            limits: FaultLimits {
                over_current_a: 45.0,
                hardware_over_current_a: 47.0,
                over_voltage_v: 360.0,
                under_voltage_v: 200.0,
                over_pressure_pa: 20e6,
                over_speed_rad_s: 260.0,
                encoder_plausible_speed_rad_s: 600.0,
                command_timeout_s: 0.1,
                // A tenth of the q-current limit: 75 times the sum's noise (three
                // channels at 0.02 A rms and a count each, 0.04 A rms) and three times what
                // a 2 % gain mismatch of one channel makes at the 45 A trip.
                current_sum_a: 3.0,
                // Ten times the longest saturated acceleration of the loaded shaft
                // (0 -> 200 rad/s at 30 A: 5 ms).
                stall_time_s: 0.1,
            },
            calibration: CalibrationConfig {
                offset_time_s: 0.05,
                offsets_at_boot: true,
                offset_max_lsb: 200.0,
                alignment_current_a: 5.0,
                bootstrap_precharge_s: 0.5e-3,
                alignment_time_s: 0.5,
            },
            commissioning: CommissioningConfig::nominal(),
            compensation: CompensationConfig::nominal(),
        }
    }

    /// The first power-up on a current-limited bench supply of 24‥48 V
    /// (`docs/bring-up.md`; the firmware's `bring-up` feature): the nominal motor and
    /// loops, with the DC-link window, the PI voltage limit and every current and speed
    /// limit lowered, so a wiring, sign or offset error trips at a few amperes and a few
    /// tens of rad/s instead of the nominal 45 A and 260 rad/s.
    pub fn bring_up() -> Config {
        let mut c = Config::nominal();
        c.motor.dc_link_nominal_v = 48.0;
        // 48 V / √3, the SVPWM linear limit at 48 V.
        c.current.voltage_limit_v = 27.0;
        c.speed.iq_limit_a = 3.0;
        c.speed.speed_limit_rad_s = 30.0;
        c.limits.over_current_a = 6.0;
        c.limits.hardware_over_current_a = 8.0;
        c.limits.under_voltage_v = 18.0;
        c.limits.over_voltage_v = 60.0;
        c.limits.over_speed_rad_s = 40.0;
        c.calibration.alignment_current_a = 2.0;
        let k = &mut c.commissioning;
        k.current_a = 4.0;
        k.spin_current_a = 2.0;
        k.pulse_voltage_v = 12.0;
        // Back-EMF at 20 rad/s: 4 · 20 · 0.1827 = 14.6 V, inside the 27 V limit.
        k.spin_speed_rad_s = 20.0;
        c
    }

    /// The same configuration at another PWM (current-loop) rate, keeping the speed- and
    /// pressure-loop rates (for example 100 kHz, Table 1's 1e-5 s).
    pub fn with_pwm_hz(mut self, pwm_hz: f32) -> Config {
        self.rates.pwm_hz = pwm_hz;
        self
    }

    /// Checks every field; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let r = &self.rates;
        if !(r.pwm_hz.is_finite() && (1_000.0..=100_000.0).contains(&r.pwm_hz)) {
            return Err(err("rates.pwm_hz", "must be within 1 kHz..=100 kHz"));
        }
        positive("rates.speed_loop_hz", r.speed_loop_hz)?;
        if whole_ratio(r.pwm_hz, r.speed_loop_hz).is_none() {
            return Err(err(
                "rates.speed_loop_hz",
                "must divide rates.pwm_hz a whole number of times",
            ));
        }
        positive("rates.pressure_loop_hz", r.pressure_loop_hz)?;
        if whole_ratio(r.pwm_hz, r.pressure_loop_hz).is_none() {
            return Err(err(
                "rates.pressure_loop_hz",
                "must divide rates.pwm_hz a whole number of times",
            ));
        }
        if r.pressure_loop_hz < 10.0 * self.pressure.bandwidth_rad_s / core::f32::consts::TAU {
            return Err(err(
                "rates.pressure_loop_hz",
                "must be at least 10x the pressure-loop bandwidth",
            ));
        }

        if !(1..=10_000).contains(&r.telemetry_decimation) {
            return Err(err(
                "rates.telemetry_decimation",
                "must be within 1..=10000",
            ));
        }

        let s = &self.sensors;
        positive("sensors.current_a_per_lsb", s.current_a_per_lsb)?;
        if !(s.current_zero_lsb.is_finite() && (0.0..=4095.0).contains(&s.current_zero_lsb)) {
            return Err(err("sensors.current_zero_lsb", "must be within 0..=4095"));
        }
        non_negative("sensors.shunt_settling_s", s.shunt_settling_s)?;
        if crate::shunt::max_sampled_duty(s.shunt_settling_s, r.pwm_hz) < 0.5 {
            return Err(err(
                "sensors.shunt_settling_s",
                "must be at most a quarter of the PWM period",
            ));
        }
        positive("sensors.dc_link_v_per_lsb", s.dc_link_v_per_lsb)?;
        positive("sensors.pressure_pa_per_lsb", s.pressure_pa_per_lsb)?;
        if !(s.pressure_zero_lsb.is_finite() && (0.0..=65535.0).contains(&s.pressure_zero_lsb)) {
            return Err(err("sensors.pressure_zero_lsb", "must be within 0..=65535"));
        }
        if s.pressure_open_wire_lsb >= s.pressure_short_lsb {
            return Err(err(
                "sensors.pressure_open_wire_lsb",
                "must be below sensors.pressure_short_lsb",
            ));
        }
        if !(4..=(1 << 24)).contains(&s.encoder_counts_per_rev) {
            return Err(err(
                "sensors.encoder_counts_per_rev",
                "must be within 4..=16777216",
            ));
        }
        if !s.encoder_offset_rad.is_finite() {
            return Err(err("sensors.encoder_offset_rad", "must be finite"));
        }

        let m = &self.motor;
        if !(1..=64).contains(&m.pole_pairs) {
            return Err(err("motor.pole_pairs", "must be within 1..=64"));
        }
        positive("motor.stator_resistance_ohm", m.stator_resistance_ohm)?;
        positive("motor.d_inductance_h", m.d_inductance_h)?;
        positive("motor.q_inductance_h", m.q_inductance_h)?;
        non_negative("motor.flux_linkage_wb", m.flux_linkage_wb)?;
        positive("motor.dc_link_nominal_v", m.dc_link_nominal_v)?;

        let c = &self.current;
        positive("current.kp_d", c.kp_d)?;
        non_negative("current.ki_d", c.ki_d)?;
        positive("current.kp_q", c.kp_q)?;
        non_negative("current.ki_q", c.ki_q)?;
        positive("current.voltage_limit_v", c.voltage_limit_v)?;

        let sp = &self.speed;
        positive("speed.kp", sp.kp)?;
        non_negative("speed.ki", sp.ki)?;
        non_negative("speed.active_damping", sp.active_damping)?;
        positive("speed.iq_limit_a", sp.iq_limit_a)?;
        positive("speed.speed_limit_rad_s", sp.speed_limit_rad_s)?;
        positive(
            "speed.observer_bandwidth_rad_s",
            sp.observer_bandwidth_rad_s,
        )?;
        if sp.observer_bandwidth_rad_s > 0.25 * r.pwm_hz {
            return Err(err(
                "speed.observer_bandwidth_rad_s",
                "must be at most 0.25 * rates.pwm_hz (omega_n * T <= 0.25)",
            ));
        }

        let p = &self.pressure;
        positive("pressure.bandwidth_rad_s", p.bandwidth_rad_s)?;
        if !(p.integral_corner_ratio.is_finite() && (0.0..=1.0).contains(&p.integral_corner_ratio))
        {
            return Err(err(
                "pressure.integral_corner_ratio",
                "must be within 0..=1",
            ));
        }
        positive("pressure.feedback_filter_rad_s", p.feedback_filter_rad_s)?;
        if p.feedback_filter_rad_s < 2.0 * p.bandwidth_rad_s {
            return Err(err(
                "pressure.feedback_filter_rad_s",
                "must be at least 2x pressure.bandwidth_rad_s",
            ));
        }
        positive("pressure.ramp_pa_per_s", p.ramp_pa_per_s)?;
        non_negative("pressure.setpoint_min_pa", p.setpoint_min_pa)?;
        positive("pressure.setpoint_max_pa", p.setpoint_max_pa)?;
        if p.setpoint_min_pa >= p.setpoint_max_pa {
            return Err(err(
                "pressure.setpoint_min_pa",
                "must be below pressure.setpoint_max_pa",
            ));
        }

        let h = &self.hydraulics;
        positive(
            "hydraulics.pump_displacement_m3_per_rev",
            h.pump_displacement_m3_per_rev,
        )?;
        positive("hydraulics.oil_volume_m3", h.oil_volume_m3)?;
        positive("hydraulics.bulk_modulus_pa", h.bulk_modulus_pa)?;
        non_negative("hydraulics.absorber_volume_m3", h.absorber_volume_m3)?;
        non_negative("hydraulics.absorber_precharge_pa", h.absorber_precharge_pa)?;
        if !(h.polytropic_exponent.is_finite() && (1.0..=2.0).contains(&h.polytropic_exponent)) {
            return Err(err(
                "hydraulics.polytropic_exponent",
                "must be within 1..=2",
            ));
        }
        non_negative("hydraulics.leakage_m3_per_s_pa", h.leakage_m3_per_s_pa)?;

        let l = &self.limits;
        positive("limits.over_current_a", l.over_current_a)?;
        if l.over_current_a <= sp.iq_limit_a {
            return Err(err("limits.over_current_a", "must exceed speed.iq_limit_a"));
        }
        positive("limits.hardware_over_current_a", l.hardware_over_current_a)?;
        if l.hardware_over_current_a <= l.over_current_a {
            return Err(err(
                "limits.hardware_over_current_a",
                "must exceed limits.over_current_a",
            ));
        }
        if l.hardware_over_current_a / s.current_a_per_lsb >= s.current_zero_lsb {
            return Err(err(
                "limits.hardware_over_current_a",
                "must be within the current sensor's range below its zero",
            ));
        }
        positive("limits.under_voltage_v", l.under_voltage_v)?;
        positive("limits.over_voltage_v", l.over_voltage_v)?;
        if l.under_voltage_v >= l.over_voltage_v {
            return Err(err(
                "limits.under_voltage_v",
                "must be below limits.over_voltage_v",
            ));
        }
        positive("limits.over_pressure_pa", l.over_pressure_pa)?;
        if l.over_pressure_pa <= p.setpoint_max_pa {
            return Err(err(
                "limits.over_pressure_pa",
                "must exceed pressure.setpoint_max_pa",
            ));
        }
        positive("limits.over_speed_rad_s", l.over_speed_rad_s)?;
        if l.over_speed_rad_s <= sp.speed_limit_rad_s {
            return Err(err(
                "limits.over_speed_rad_s",
                "must exceed speed.speed_limit_rad_s",
            ));
        }
        positive(
            "limits.encoder_plausible_speed_rad_s",
            l.encoder_plausible_speed_rad_s,
        )?;
        if l.encoder_plausible_speed_rad_s <= l.over_speed_rad_s {
            return Err(err(
                "limits.encoder_plausible_speed_rad_s",
                "must exceed limits.over_speed_rad_s",
            ));
        }
        // Half a revolution per sample is the largest step the wrapped difference can tell
        // from its opposite.
        let max_step_rev = l.encoder_plausible_speed_rad_s / core::f32::consts::TAU / r.pwm_hz;
        if max_step_rev >= 0.25 {
            return Err(err(
                "limits.encoder_plausible_speed_rad_s",
                "must be below a quarter revolution per PWM period",
            ));
        }
        positive("limits.command_timeout_s", l.command_timeout_s)?;
        if l.command_timeout_s > 3600.0 {
            return Err(err("limits.command_timeout_s", "must be at most 3600 s"));
        }
        positive("limits.current_sum_a", l.current_sum_a)?;
        positive("limits.stall_time_s", l.stall_time_s)?;
        if l.stall_time_s > 3600.0 {
            return Err(err("limits.stall_time_s", "must be at most 3600 s"));
        }

        let k = &self.calibration;
        positive("calibration.offset_time_s", k.offset_time_s)?;
        if k.offset_time_s * r.pwm_hz < 16.0 || k.offset_time_s > 10.0 {
            return Err(err(
                "calibration.offset_time_s",
                "must cover at least 16 samples and at most 10 s",
            ));
        }
        positive("calibration.offset_max_lsb", k.offset_max_lsb)?;
        positive("calibration.alignment_current_a", k.alignment_current_a)?;
        if k.alignment_current_a >= l.over_current_a {
            return Err(err(
                "calibration.alignment_current_a",
                "must be below limits.over_current_a",
            ));
        }
        non_negative("calibration.bootstrap_precharge_s", k.bootstrap_precharge_s)?;
        if k.bootstrap_precharge_s > 10e-3 {
            return Err(err(
                "calibration.bootstrap_precharge_s",
                "must be at most 10 ms",
            ));
        }
        positive("calibration.alignment_time_s", k.alignment_time_s)?;
        if k.alignment_time_s > 60.0 {
            return Err(err("calibration.alignment_time_s", "must be at most 60 s"));
        }
        self.commissioning.validate(
            l.over_current_a,
            c.voltage_limit_v,
            sp.speed_limit_rad_s,
            r.pwm_hz,
        )?;
        self.compensation.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_is_valid_and_matches_the_rig() {
        let c = Config::nominal();
        assert_eq!(c.validate(), Ok(()));
        // Table 1 gains are pole-zero cancellation at 1100 rad/s on the rig's motor.
        assert!((c.current.kp_q - c.motor.q_inductance_h * 1100.0).abs() < 1e-4);
        assert!((c.current.kp_d - c.motor.d_inductance_h * 1100.0).abs() < 1e-4);
        assert!((c.current.ki_q - c.motor.stator_resistance_ohm * 1100.0).abs() < 1e-2);
        // 161.6 V is U_dc/√3, the SVPWM linear limit.
        assert!((c.current.voltage_limit_v - 280.0 / libm::sqrtf(3.0)).abs() < 0.1);
        assert_eq!(c.sensors.pressure_pa_per_lsb, 476.837_16);
    }

    #[test]
    fn each_bad_field_is_named() {
        type Case = (fn(&mut Config), &'static str);
        let cases: [Case; 25] = [
            (
                |c| c.limits.hardware_over_current_a = 44.0,
                "limits.hardware_over_current_a",
            ),
            // 2048 counts of 0.0244 A: 50 A is the end of the range.
            (
                |c| c.limits.hardware_over_current_a = 50.0,
                "limits.hardware_over_current_a",
            ),
            (
                |c| c.calibration.bootstrap_precharge_s = 0.02,
                "calibration.bootstrap_precharge_s",
            ),
            // 15 µs of a 50 µs period: the largest readable duty would be 0.4.
            (
                |c| c.sensors.shunt_settling_s = 15e-6,
                "sensors.shunt_settling_s",
            ),
            // 0.8 × the 45 A over-current trip is 36 A.
            (
                |c| c.commissioning.current_a = 40.0,
                "commissioning.current_a",
            ),
            (
                |c| c.commissioning.sweep_time_s = 0.01,
                "commissioning.sweep_time_s",
            ),
            // 0.1 × 2π × 20 kHz = 12 566 rad/s.
            (
                |c| c.commissioning.current_bandwidth_rad_s = 13_000.0,
                "commissioning.current_bandwidth_rad_s",
            ),
            (
                |c| c.commissioning.spin_speed_rad_s = 250.0,
                "commissioning.spin_speed_rad_s",
            ),
            (
                |c| c.commissioning.plausible_ratio = f32::NAN,
                "commissioning.plausible_ratio",
            ),
            (|c| c.rates.pwm_hz = 0.0, "rates.pwm_hz"),
            (|c| c.rates.pwm_hz = 200e3, "rates.pwm_hz"),
            (|c| c.rates.speed_loop_hz = 3_000.0, "rates.speed_loop_hz"),
            (
                |c| c.rates.pressure_loop_hz = f32::NAN,
                "rates.pressure_loop_hz",
            ),
            (|c| c.motor.pole_pairs = 0, "motor.pole_pairs"),
            (|c| c.motor.q_inductance_h = -1.0, "motor.q_inductance_h"),
            (|c| c.current.kp_q = 0.0, "current.kp_q"),
            (
                |c| c.speed.observer_bandwidth_rad_s = f32::NAN,
                "speed.observer_bandwidth_rad_s",
            ),
            (
                |c| c.speed.observer_bandwidth_rad_s = 6_000.0,
                "speed.observer_bandwidth_rad_s",
            ),
            (|c| c.speed.iq_limit_a = 50.0, "limits.over_current_a"),
            (
                |c| c.pressure.setpoint_max_pa = 25e6,
                "limits.over_pressure_pa",
            ),
            (
                |c| c.hydraulics.polytropic_exponent = 0.5,
                "hydraulics.polytropic_exponent",
            ),
            (
                |c| c.sensors.pressure_open_wire_lsb = 63000,
                "sensors.pressure_open_wire_lsb",
            ),
            (
                |c| c.limits.command_timeout_s = -1.0,
                "limits.command_timeout_s",
            ),
            (
                |c| c.limits.current_sum_a = f32::NAN,
                "limits.current_sum_a",
            ),
            (|c| c.limits.stall_time_s = 0.0, "limits.stall_time_s"),
        ];
        for (mutate, field) in cases {
            let mut c = Config::nominal();
            mutate(&mut c);
            let e = c.validate().expect_err(field);
            assert_eq!(e.field, field, "{e}");
        }
    }

    #[test]
    fn the_bring_up_configuration_is_valid_and_trips_at_a_few_amperes() {
        let c = Config::bring_up();
        assert_eq!(c.validate(), Ok(()));
        // A 48 V supply sits inside the DC-link window; the nominal 280 V does not.
        assert!(c.limits.under_voltage_v < 24.0 && 48.0 < c.limits.over_voltage_v);
        assert!(c.limits.over_voltage_v < 280.0);
        assert!(c.limits.hardware_over_current_a <= 10.0);
        // Alignment and commissioning stay below the software trip.
        assert!(c.calibration.alignment_current_a < c.limits.over_current_a);
        assert!(c.commissioning.current_a < c.limits.over_current_a);
        // The loops are the nominal ones.
        let n = Config::nominal();
        assert_eq!((c.current.kp_q, c.speed.kp), (n.current.kp_q, n.speed.kp));
    }

    #[test]
    fn rates_at_table1_sample_time_are_valid() {
        let c = Config::nominal().with_pwm_hz(100e3);
        assert_eq!(c.validate(), Ok(()));
        assert_eq!(whole_ratio(100e3, 2e3), Some(50));
        assert_eq!(whole_ratio(20e3, 3e3), None);
    }
}

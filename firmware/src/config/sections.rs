//! The configuration's sections: the SI parameters of the loop rates, the sensors'
//! scaling, the motor, the current, speed and pressure loops, the hydraulics the pressure
//! loop is scheduled from, the supervisor's fault limits and the calibration, gathered in
//! [`Config`] with the commissioning's and the torque feed-forward's own sections.

use crate::commissioning::config::CommissioningConfig;
use crate::compensation::config::CompensationConfig;

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

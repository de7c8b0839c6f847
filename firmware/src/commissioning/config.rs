//! Settings of the commissioning sequence ([`super`]): current levels, times, the pulse
//! voltage, the spin, the loop designs the gains are derived for, and the plausibility
//! window. Validated once with the rest of [`crate::Config`].

use crate::config::error::ConfigError;

/// Commissioning sequence settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommissioningConfig {
    /// Largest current of the standstill steps: alignment and the inductance bias at
    /// 0.8×, the resistance levels at 0.4× and 0.8×, the inductance pulses swing ±0.4×
    /// around their bias. [A]
    pub current_a: f32,
    /// Time each current level settles before its average starts. [s]
    pub settle_time_s: f32,
    /// Averaging window of each level and of the spin. [s]
    pub average_time_s: f32,
    /// Time of one alignment sweep (one electrical turn of the current vector). [s]
    pub sweep_time_s: f32,
    /// Active damping while aligning: q-current per shaft speed, so the rotor settles on
    /// the d axis instead of ringing on the current's torque stiffness. [A/(rad/s)]
    pub alignment_damping_a_per_rad_s: f32,
    /// Voltage step of the inductance pulses. [V]
    ///
    /// As large as the PI's headroom allows: the q pulses turn the rotor a little, and the
    /// back-EMF of that motion, unaccounted for (ψ_f is not known yet), biases L_q low by
    /// a share that falls with the square of the voltage (pulse length ∝ 1/U, speed and
    /// time both ∝ pulse length): about −1 % at 80 V against −1.8 % at 60 V.
    pub pulse_voltage_v: f32,
    /// Pulse cycles (+, −, + each) per axis that enter the estimate. [1]
    pub pulse_cycles: u32,
    /// Shaft speed of the back-EMF measurement. [rad/s]
    pub spin_speed_rad_s: f32,
    /// q-current of the acceleration and deceleration the inertia is measured from. [A]
    pub spin_current_a: f32,
    /// Longest time a step that waits for the motor (a pulse reaching its current, the
    /// shaft reaching its speed) may take before it faults. [s]
    pub step_timeout_s: f32,
    /// Current-loop bandwidth ω_c the current gains are designed for. [rad/s]
    pub current_bandwidth_rad_s: f32,
    /// Natural frequency of the designed speed loop. [rad/s]
    pub speed_natural_frequency_rad_s: f32,
    /// Damping ratio of the designed speed loop. [1]
    pub speed_damping_ratio: f32,
    /// An identified value outside [nameplate / ratio, nameplate · ratio] is implausible
    /// (fault 14). [1]
    pub plausible_ratio: f32,
}

impl CommissioningConfig {
    /// Defaults for the nominal rig. The speed-loop design (ω_n = 97.9 rad/s, ζ = 1.07) is
    /// the one Table 1's speed gains place on J = 8.0e-4 kg·m² (see
    /// [`crate::speed_loop`]), so a rig with the nominal inertia gets Table 1 back.
    pub const fn nominal() -> CommissioningConfig {
        CommissioningConfig {
            current_a: 10.0,
            settle_time_s: 0.1,
            average_time_s: 0.2,
            sweep_time_s: 0.3,
            alignment_damping_a_per_rad_s: 0.1,
            pulse_voltage_v: 80.0,
            pulse_cycles: 48,
            spin_speed_rad_s: 100.0,
            spin_current_a: 4.0,
            step_timeout_s: 0.5,
            current_bandwidth_rad_s: 1100.0,
            speed_natural_frequency_rad_s: 97.9,
            speed_damping_ratio: 1.07,
            plausible_ratio: 3.0,
        }
    }

    /// Checks every field against the drive's limits: `over_current_a` [A], the PI
    /// voltage limit `voltage_limit_v` [V], `speed_limit_rad_s` [rad/s] and the PWM rate
    /// `pwm_hz` [Hz].
    pub fn validate(
        &self,
        over_current_a: f32,
        voltage_limit_v: f32,
        speed_limit_rad_s: f32,
        pwm_hz: f32,
    ) -> Result<(), ConfigError> {
        let pos = |v: f32| v.is_finite() && v > 0.0;
        let time = |t: f32| t.is_finite() && t * pwm_hz >= 16.0 && t <= 10.0;
        const TIME: &str = "must cover at least 16 PWM periods and at most 10 s";
        // A tenth of the sampling rate keeps the sample delay's phase loss below 27°.
        let w_max = 0.1 * core::f32::consts::TAU * pwm_hz;
        // One table, checked in order (compact on the target: one loop, no branch per
        // field).
        let checks: [(&'static str, bool, &'static str); 14] = [
            (
                "commissioning.current_a",
                pos(self.current_a) && self.current_a < 0.8 * over_current_a,
                "must be > 0 and below 0.8 * limits.over_current_a",
            ),
            (
                "commissioning.settle_time_s",
                time(self.settle_time_s),
                TIME,
            ),
            (
                "commissioning.average_time_s",
                time(self.average_time_s),
                TIME,
            ),
            // The open-phase check runs in the sweep's first 10 ms.
            (
                "commissioning.sweep_time_s",
                time(self.sweep_time_s) && self.sweep_time_s >= 0.02,
                "must be within 0.02 s..=10 s",
            ),
            (
                "commissioning.step_timeout_s",
                time(self.step_timeout_s),
                TIME,
            ),
            (
                "commissioning.alignment_damping_a_per_rad_s",
                self.alignment_damping_a_per_rad_s.is_finite()
                    && self.alignment_damping_a_per_rad_s >= 0.0,
                "must be finite and >= 0",
            ),
            (
                "commissioning.pulse_voltage_v",
                pos(self.pulse_voltage_v) && self.pulse_voltage_v <= 0.5 * voltage_limit_v,
                "must be > 0 and at most 0.5 * current.voltage_limit_v",
            ),
            (
                "commissioning.pulse_cycles",
                (1..=10_000).contains(&self.pulse_cycles),
                "must be within 1..=10000",
            ),
            (
                "commissioning.spin_speed_rad_s",
                pos(self.spin_speed_rad_s) && self.spin_speed_rad_s <= speed_limit_rad_s,
                "must be > 0 and at most speed.speed_limit_rad_s",
            ),
            (
                "commissioning.spin_current_a",
                pos(self.spin_current_a) && self.spin_current_a <= self.current_a,
                "must be > 0 and at most commissioning.current_a",
            ),
            (
                "commissioning.current_bandwidth_rad_s",
                pos(self.current_bandwidth_rad_s) && self.current_bandwidth_rad_s <= w_max,
                "must be > 0 and at most 0.1 * 2π * rates.pwm_hz",
            ),
            (
                "commissioning.speed_natural_frequency_rad_s",
                pos(self.speed_natural_frequency_rad_s)
                    && self.speed_natural_frequency_rad_s <= 0.25 * self.current_bandwidth_rad_s,
                "must be > 0 and at most 0.25 * commissioning.current_bandwidth_rad_s",
            ),
            (
                "commissioning.speed_damping_ratio",
                pos(self.speed_damping_ratio),
                "must be finite and > 0",
            ),
            (
                "commissioning.plausible_ratio",
                self.plausible_ratio.is_finite() && self.plausible_ratio > 1.0,
                "must be finite and > 1",
            ),
        ];
        for (field, good, problem) in checks {
            if !good {
                return Err(ConfigError { field, problem });
            }
        }
        Ok(())
    }
}

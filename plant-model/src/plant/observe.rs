//! What leaves the plant: the sensors' readings at the ADC trigger ([`Plant::sample`]), the
//! true physical quantities ([`Plant::observe`]), and the pressure transducer's first-order
//! lag, filtered exactly after each step.

use super::actuator::Plant;
use super::state::ix;
use crate::accumulator::ATMOSPHERE_PA;
use crate::inverter::dq_to_abc;
use crate::sensors::SensorReadings;

/// Physical quantities of the plant at one instant (true values, not measurements).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Observables {
    /// Time since the start. [s]
    pub t_s: f64,
    /// d-axis current. [A]
    pub i_d_a: f64,
    /// q-axis current. [A]
    pub i_q_a: f64,
    /// Phase currents a, b, c. [A]
    pub i_abc_a: [f64; 3],
    /// Currents through the bridge legs and the current sensors a, b, c: the phase
    /// currents plus a short circuit's path current ([`crate::faults`]). [A]
    pub i_bridge_abc_a: [f64; 3],
    /// DC-link voltage. [V]
    pub u_dc_v: f64,
    /// d-axis voltage applied by the inverter. [V]
    pub u_d_v: f64,
    /// q-axis voltage applied by the inverter. [V]
    pub u_q_v: f64,
    /// Shaft angle, unwrapped. [rad]
    pub theta_m_rad: f64,
    /// Shaft speed. [rad/s]
    pub omega_m_rad_s: f64,
    /// Electromagnetic torque. [N·m]
    pub torque_em_nm: f64,
    /// Cogging torque. [N·m]
    pub torque_cogging_nm: f64,
    /// Hydraulic load torque of the pump. [N·m]
    pub torque_pump_nm: f64,
    /// Port-A (high side) pressure. [Pa]
    pub p_a_pa: f64,
    /// Pressure in the pump's manifold (port A's unless the pump's port is blocked). [Pa]
    pub p_pump_pa: f64,
    /// Port-B (low side) pressure. [Pa]
    pub p_b_pa: f64,
    /// Pressure at the transducer (after its lag). [Pa]
    pub p_sensor_pa: f64,
    /// Fill accumulator pressure. [Pa]
    pub p_fill_pa: f64,
    /// Pump geometric flow B → A. [m³/s]
    pub pump_flow_m3_s: f64,
    /// Oil in the absorber. [m³]
    pub absorber_oil_m3: f64,
    /// Flow into the absorber. [m³/s]
    pub absorber_flow_m3_s: f64,
    /// Piston position. [m]
    pub x_m: f64,
    /// Piston velocity. [m/s]
    pub v_m_s: f64,
}

impl Plant {
    /// The pressure transducer's first-order lag over a step of `h` in which port A's
    /// pressure went from `p0` to its present value: the exact discrete filter of
    /// τ·ṗ_s = p − p_s for p linear over the step,
    /// p_s ← p_1 + (p_s − p_0)·e^{−h/τ} − (p_1 − p_0)·τ/h·(1 − e^{−h/τ}),
    /// stable and exact for any τ > 0 however short against the step.
    pub(super) fn filter_pressure_sensor(&mut self, p0: f64, h: f64) {
        let tau = self.sensor_lag_s;
        if tau <= 0.0 {
            return;
        }
        if self.lag_filter.0 != h {
            let decay = libm::exp(-h / tau);
            let gain = -tau / h * libm::expm1(-h / tau);
            self.lag_filter = (h, decay, gain);
        }
        let (_, decay, gain) = self.lag_filter;
        let p1 = self.x[ix::PA];
        self.x[ix::P_SENSOR] = p1 + (self.x[ix::P_SENSOR] - p0) * decay - (p1 - p0) * gain;
    }

    /// Reads every sensor at the present instant (the ADC trigger at the PWM centre).
    pub fn sample(&mut self) -> SensorReadings {
        let i_abc = self.leg_currents(self.motor_phase_currents());
        let p_sensed = if self.sensor_lag_s > 0.0 {
            self.x[ix::P_SENSOR]
        } else {
            self.x[ix::PA]
        };
        let u_dc = self.dc_link_v();
        self.sensors
            .sample(self.t_s, &i_abc, u_dc, p_sensed, self.x[ix::THETA])
    }

    /// True physical quantities now, with the inputs of the last step.
    pub fn observe(&self) -> Observables {
        let x = &self.x;
        let at = self.angle_terms(x[ix::THETA]);
        // Only the drive side of an evaluation: the hydraulic flows are not observed.
        let el = if self.faulted {
            self.electrical::<true>(x, &self.last_inputs, &at)
        } else {
            self.electrical::<false>(x, &self.last_inputs, &at)
        };
        let i_abc_a = dq_to_abc(x[ix::ID], x[ix::IQ], at.rot_e.sin, at.rot_e.cos);
        Observables {
            t_s: self.t_s,
            i_d_a: x[ix::ID],
            i_q_a: x[ix::IQ],
            i_abc_a,
            i_bridge_abc_a: self.leg_currents(i_abc_a),
            u_dc_v: self.dc_link_v(),
            u_d_v: el.u_d,
            u_q_v: el.u_q,
            theta_m_rad: x[ix::THETA],
            omega_m_rad_s: x[ix::OMEGA],
            torque_em_nm: self.motor.torque_nm(x[ix::ID], x[ix::IQ], &at.flux),
            torque_cogging_nm: at.t_cog,
            torque_pump_nm: self
                .pump
                .load_torque(self.pump_pressure(x), x[ix::PB], at.factor),
            p_a_pa: x[ix::PA],
            p_pump_pa: self.pump_pressure(x),
            p_b_pa: x[ix::PB],
            p_sensor_pa: if self.sensor_lag_s > 0.0 {
                x[ix::P_SENSOR]
            } else {
                x[ix::PA]
            },
            p_fill_pa: x[ix::FILL_PGAS] - ATMOSPHERE_PA,
            pump_flow_m3_s: self.pump.geometric_flow(x[ix::OMEGA], at.factor),
            absorber_oil_m3: x[ix::ABS_OIL],
            absorber_flow_m3_s: x[ix::ABS_Q],
            x_m: x[ix::X],
            v_m_s: x[ix::V],
        }
    }
}

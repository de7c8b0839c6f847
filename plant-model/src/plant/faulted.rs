//! The plant's side of the faults ([`crate::faults`], [`crate::sensor_faults`]): switching
//! them, the motor confined to one line, the short circuit's fault path, the bridge's
//! hardware over-current break, and the watch on the bridge currents a fault campaign
//! asserts on.
//!
//! # Hardware over-current break
//!
//! Drives protect their bridge with comparators on the current sensors' outputs wired to
//! the PWM timer's break input (on the STM32G4, COMPx → TIM1 BRK2): above the threshold
//! the gates are switched off within a microsecond, without software. Armed with
//! [`Plant::set_hardware_break`], the bridge here does the same: the first instant within
//! a step at which a leg current reaches the threshold ends the bridge's conduction (the
//! rest of the step runs with the gates off), and the break stays latched — gates off
//! whatever the duties say — until the software disables the bridge itself (acknowledges).
//! [`Plant::take_break_event`] tells the harness, which tells the control core, as the
//! board's break interrupt does. A short circuit's path current is exponential within a
//! step, so its crossing instant is solved for exactly; slower currents are checked at the
//! step's end.

use super::actuator::Plant;
use super::inputs::{Drive, Inputs};
use super::protection::CurrentWatch;
use super::state::{ix, Vector};
use crate::faults::{
    burst_flow, fault_path_current, fault_path_voltage, leg_contribution, line_current,
    line_derivatives, rotor_projections, Line, PlantFaults, ShortPath,
};
use crate::inverter::dq_to_abc;
use crate::motor::Phasor;
use crate::sensor_faults::SensorFaults;

/// √3.
const SQRT3: f64 = 1.732_050_807_568_877_2;

impl Plant {
    /// [`Plant::advance`]'s `n` steps of `h` with the faults' parts: the DC link's voltage,
    /// a short circuit's path current, the hardware break, the current watch. Kept out of
    /// line so the plain path's step stays inlined.
    #[cold]
    #[inline(never)]
    pub(super) fn advance_faulted(&mut self, n: u64, h: f64, mut inputs: Inputs) {
        for k in 0..n {
            self.inverter
                .set_u_dc(self.dc_link.voltage(self.t_s + k as f64 * h));
            self.impose(&inputs);
            let p0 = self.x[ix::PA];
            let mut left = h;
            if let Some(t_break) = self.break_within(h, &inputs) {
                self.step_with_events(t_break, &inputs);
                self.advance_fault_path(t_break, &inputs);
                self.trip_break(&mut inputs);
                left -= t_break;
            }
            self.step_with_events(left, &inputs);
            self.advance_fault_path(left, &inputs);
            self.dc_link.advance(h);
            self.filter_pressure_sensor(p0, h);
            self.after_step(h, &mut inputs);
        }
    }

    /// Switches the plant's faults from now on (`Err` names an invalid field; nothing
    /// changes then). Opening a phase removes its current at once; blocking the pump's port
    /// gives its manifold a node of its own at the port's pressure.
    pub fn set_faults(&mut self, faults: &PlantFaults) -> Result<(), &'static str> {
        faults.validate()?;
        let before = self.stored_energy_j(&self.x);
        if faults.pump_port_blocked && !self.faults.pump_port_blocked {
            self.x[ix::PP] = self.x[ix::PA];
        }
        if faults.short.map(|s| s.path) != self.faults.short.map(|s| s.path) {
            self.i_fault = 0.0;
        }
        self.dc_link.set_fault(faults.supply);
        self.faults = *faults;
        self.faulted = true;
        self.relief_a.conductance_m3_s_pa = if faults.relief_stuck_closed {
            0.0
        } else {
            self.relief.conductance_m3_s_pa
        };
        // A change of node structure changes what the state's energy counts, not the energy.
        self.projection_loss_j += before - self.stored_energy_j(&self.x);
        let enabled = match self.last_inputs.drive {
            Drive::Inverter { enabled, .. } => enabled,
            _ => true,
        };
        if let Some(line) = self.line_mode(enabled) {
            self.discrete.extinguished = false;
            self.project_line(line);
        }
        Ok(())
    }

    /// The plant's faults in force.
    pub fn faults(&self) -> PlantFaults {
        self.faults
    }

    /// Switches the sensors' faults from now on (`Err` names an invalid field).
    pub fn set_sensor_faults(&mut self, faults: &SensorFaults) -> Result<(), &'static str> {
        faults.validate()?;
        self.sensors.set_faults(*faults);
        Ok(())
    }

    /// The sensors' faults in force.
    pub fn sensor_faults(&self) -> SensorFaults {
        self.sensors.faults()
    }

    /// Arms the bridge's hardware over-current break at `threshold_a` on every leg (None:
    /// no break, the default). [A]
    pub fn set_hardware_break(&mut self, threshold_a: Option<f64>) {
        self.protection.break_threshold_a = threshold_a.filter(|t| t.is_finite() && *t > 0.0);
        self.faulted = true;
        if self.protection.break_threshold_a.is_none() {
            self.protection.latched = false;
        }
    }

    /// True once per hardware break (the break interrupt's flag, cleared by reading).
    pub fn take_break_event(&mut self) -> bool {
        core::mem::take(&mut self.protection.event)
    }

    /// True while the break holds the gates off.
    pub fn break_latched(&self) -> bool {
        self.protection.latched
    }

    /// Watches the bridge legs' currents against `limit_a` (None: off, the default). [A]
    pub fn set_current_watch(&mut self, limit_a: Option<f64>) {
        self.protection.watch_limit_a = limit_a;
        self.faulted = true;
        self.protection.peak_a = 0.0;
        self.protection.time_above_s = 0.0;
    }

    /// What the watch saw since the last call (then starts afresh).
    pub fn take_current_watch(&mut self) -> CurrentWatch {
        let w = CurrentWatch {
            peak_a: self.protection.peak_a,
            time_above_s: self.protection.time_above_s,
        };
        self.protection.peak_a = 0.0;
        self.protection.time_above_s = 0.0;
        w
    }

    /// The currents through the bridge legs (and the current sensors): the motor's phase
    /// currents plus a short circuit's path current. [A]
    #[inline]
    pub(super) fn leg_currents(&self, i_motor: [f64; 3]) -> [f64; 3] {
        if self.faulted {
            self.legs_with(i_motor, self.i_fault)
        } else {
            i_motor
        }
    }

    /// The DC-link voltage now. [V]
    #[inline]
    pub(super) fn dc_link_v(&self) -> f64 {
        if self.faulted {
            self.dc_link.voltage(self.t_s)
        } else {
            self.inverter.u_dc_v
        }
    }

    /// The bridge legs' currents for the motor's phase currents `i_motor` and a fault-path
    /// current `i_f`. [A]
    fn legs_with(&self, i_motor: [f64; 3], i_f: f64) -> [f64; 3] {
        let Some(s) = self.faults.short else {
            return i_motor;
        };
        let add = leg_contribution(s.path, i_f);
        let mut legs = [
            i_motor[0] + add[0],
            i_motor[1] + add[1],
            i_motor[2] + add[2],
        ];
        // With the gates off a rail short feeds its phase's motor current itself, unless
        // that current flows the way the leg's diode to the same rail conducts.
        let off = matches!(
            self.last_inputs.drive,
            Drive::Inverter { enabled: false, .. }
        );
        if let (true, ShortPath::PhaseToRail { phase, rail }) = (off, s.path) {
            let i = i_motor[phase.index()];
            let through_diode = match rail {
                crate::faults::Rail::Positive => i.min(0.0),
                crate::faults::Rail::Negative => i.max(0.0),
            };
            legs[phase.index()] = through_diode + add[phase.index()];
        }
        legs
    }

    /// The motor's phase currents now. [A]
    pub(super) fn motor_phase_currents(&self) -> [f64; 3] {
        let e = self.rotor_e(self.x[ix::THETA]);
        dq_to_abc(self.x[ix::ID], self.x[ix::IQ], e.sin, e.cos)
    }

    /// Whether the motor's current is confined to one line with the bridge `enabled` or not.
    #[inline]
    pub(super) fn line_mode(&self, enabled: bool) -> Option<Line> {
        if let Some(p) = self.faults.open_phase {
            return Some(Line::Open(p));
        }
        match self.faults.short {
            Some(s) if !enabled => match s.path {
                ShortPath::PhaseToPhase { from, to } => Some(Line::Shorted {
                    floating: from.third(to),
                    resistance_ohm: s.resistance_ohm,
                }),
                ShortPath::PhaseToRail { .. } => None,
            },
            _ => None,
        }
    }

    /// The line-confined motor's derivatives: (di_d/dt, di_q/dt, v_n, i) with the line
    /// voltage from the poles `v_pole` or, for a shorted line, from the short. [A/s, V, A]
    #[inline]
    pub(super) fn line_electrical(
        &self,
        x: &Vector,
        line: Line,
        v_pole: [f64; 3],
        e: Phasor,
        flux: &crate::motor::MagnetFlux,
    ) -> (f64, f64, f64, f64) {
        let idle = line.idle_phase();
        let n = idle.line_direction();
        let i = line_current(n, x[ix::ID], x[ix::IQ], e);
        let v_n = match line {
            Line::Open(_) => {
                let (y, z) = (idle.next(), idle.next().next());
                (v_pole[y.index()] - v_pole[z.index()]) / SQRT3
            }
            Line::Shorted { resistance_ohm, .. } => -0.5 * resistance_ohm * i,
        };
        let omega_e = self.motor.pole_pairs * x[ix::OMEGA];
        let (_, did, diq) = line_derivatives(&self.motor, n, i, v_n, omega_e, e, flux);
        (did, diq, v_n, i)
    }

    /// Whether a short keeps the motor's circuit closed with the bridge off (`line`: the
    /// line confinement in force): across two phases it closes the line, to a rail it pins a
    /// terminal so the back-EMF always finds a diode to drive through.
    #[inline]
    pub(super) fn short_closes_circuit(&self, line: Option<Line>) -> bool {
        matches!(line, Some(Line::Shorted { .. }))
            || matches!(
                self.faults.short,
                Some(crate::faults::Short {
                    path: ShortPath::PhaseToRail { .. },
                    ..
                })
            )
    }

    /// A rail short pins its phase's pole at the rail while the bridge is off.
    #[inline]
    pub(super) fn pin_shorted_pole(&self, v_pole: &mut [f64; 3]) {
        if let Some(s) = self.faults.short {
            if let ShortPath::PhaseToRail { phase, rail } = s.path {
                v_pole[phase.index()] = match rail {
                    crate::faults::Rail::Positive => self.inverter.u_dc_v,
                    crate::faults::Rail::Negative => 0.0,
                };
            }
        }
    }

    /// Puts the currents back on the line (removing what drifted off it, or a phase's
    /// current when it opens) and books the winding energy removed.
    pub(super) fn project_line(&mut self, line: Line) {
        let e = self.rotor_e(self.x[ix::THETA]);
        let n = line.idle_phase().line_direction();
        let (id, iq) = (self.x[ix::ID], self.x[ix::IQ]);
        let i = line_current(n, id, iq, e);
        let (c, s) = rotor_projections(n, e);
        let (id_new, iq_new) = (i * c, i * s);
        self.projection_loss_j +=
            self.motor.winding_energy_j(id, iq) - self.motor.winding_energy_j(id_new, iq_new);
        self.x[ix::ID] = id_new;
        self.x[ix::IQ] = iq_new;
    }

    /// The burst line's outflow at port-A pressure `p_a`. [m³/s]
    #[inline]
    pub(super) fn burst_outflow(&self, p_a: f64) -> f64 {
        burst_flow(self.faults.burst_area_m2, p_a, self.oil_density)
    }

    /// The fault path's driving voltage for `inputs` (None: bridge off).
    fn fault_path_drive(&self, inputs: &Inputs) -> Option<f64> {
        let s = self.faults.short?;
        match inputs.drive {
            Drive::Inverter {
                duties,
                enabled: true,
            } => Some(fault_path_voltage(s.path, &duties, self.inverter.u_dc_v)),
            _ => None,
        }
    }

    /// Advances the fault path's current by `h` with `inputs` held, and books what the
    /// current watch sees of it. [s]
    pub(super) fn advance_fault_path(&mut self, h: f64, inputs: &Inputs) {
        let Some(s) = self.faults.short else {
            return;
        };
        let v = self.fault_path_drive(inputs);
        let u = self.inverter.u_dc_v;
        let i0 = self.i_fault;
        self.i_fault = fault_path_current(&s, i0, v, u, h);
        let Some(limit) = self.protection.watch_limit_a else {
            return;
        };
        // The motor's currents barely move within a step; the path's is an exponential
        // toward a fixed value (or to zero through the diodes), monotone, so a leg's current
        // crosses the limit at most once unless it is above it at both ends.
        let motor = self.motor_phase_currents();
        let leg_max = |i_f: f64| {
            self.legs_with(motor, i_f)
                .iter()
                .fold(0.0f64, |m, i| m.max(libm::fabs(*i)))
        };
        let (a, b) = (leg_max(i0), leg_max(self.i_fault));
        let above = match (a > limit, b > limit) {
            (false, false) => 0.0,
            (true, true) => h,
            (rising_out, _) => {
                let (mut lo, mut hi) = (0.0, h);
                while hi - lo > 1e-9 {
                    let mid = 0.5 * (lo + hi);
                    let out = leg_max(fault_path_current(&s, i0, v, u, mid)) > limit;
                    if out == rising_out {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                if rising_out {
                    hi
                } else {
                    h - hi
                }
            }
        };
        let w = &mut self.protection;
        w.peak_a = w.peak_a.max(a).max(b);
        w.time_above_s += above;
    }

    /// When within the next `h` seconds a short circuit's current takes a leg to the break
    /// threshold (bridge on, break armed and not latched), the time until then. [s]
    pub(super) fn break_within(&self, h: f64, inputs: &Inputs) -> Option<f64> {
        let threshold = self.protection.break_threshold_a?;
        let s = self.faults.short?;
        let v = self.fault_path_drive(inputs)?;
        if self.protection.latched {
            return None;
        }
        let motor = self.motor_phase_currents();
        let legs_at = |t: f64| {
            let i_f = fault_path_current(&s, self.i_fault, Some(v), self.inverter.u_dc_v, t);
            self.legs_with(motor, i_f)
                .iter()
                .fold(0.0f64, |m, i| m.max(libm::fabs(*i)))
        };
        if legs_at(h) < threshold {
            return None;
        }
        // The path current is monotone within the step: bisect the first crossing (to 1 ns).
        let (mut lo, mut hi) = (0.0, h);
        if legs_at(lo) >= threshold {
            return Some(0.0);
        }
        while hi - lo > 1e-9 {
            let mid = 0.5 * (lo + hi);
            if legs_at(mid) >= threshold {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Some(hi)
    }

    /// Latches the break: the gates go off for the rest of the advance.
    pub(super) fn trip_break(&mut self, inputs: &mut Inputs) {
        self.protection.latched = true;
        self.protection.event = true;
        if let Drive::Inverter { enabled, .. } = &mut inputs.drive {
            *enabled = false;
        }
        self.last_inputs = *inputs;
    }

    /// The software's enable against the latched break: the gates stay off while it holds,
    /// and the software's disabling the bridge acknowledges (clears) it.
    pub(super) fn gate_enable(&mut self, inputs: &mut Inputs) {
        if let Drive::Inverter { enabled, .. } = &mut inputs.drive {
            if self.protection.latched {
                if *enabled {
                    *enabled = false;
                } else {
                    self.protection.latched = false;
                }
            }
        }
    }

    /// After an integration step of `h` seconds: the break against slower over-currents
    /// (checked at the step's end) and, without a short circuit (whose path current
    /// [`Plant::advance_fault_path`] watches), the watch's books. [s]
    pub(super) fn after_step(&mut self, h: f64, inputs: &mut Inputs) {
        let p = self.protection;
        if p.break_threshold_a.is_none() && p.watch_limit_a.is_none() {
            return;
        }
        let motor = self.motor_phase_currents();
        let legs = self.leg_currents(motor);
        let peak = legs.iter().fold(0.0f64, |m, i| m.max(libm::fabs(*i)));
        if let Some(t) = p.break_threshold_a {
            let on = matches!(inputs.drive, Drive::Inverter { enabled: true, .. });
            if on && !p.latched && peak >= t {
                self.trip_break(inputs);
            }
        }
        let Some(limit) = p.watch_limit_a else {
            return;
        };
        if self.faults.short.is_none() {
            let w = &mut self.protection;
            w.peak_a = w.peak_a.max(peak);
            if peak > limit {
                w.time_above_s += h;
            }
        }
    }
}

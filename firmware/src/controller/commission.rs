//! The controller's side of commissioning: feeds the sequence ([`crate::commissioning`])
//! its measurements each period, carries out the action it asks for (bridge off, current
//! loop at a forced or encoder angle, open-loop voltage, speed loop), applies the designed
//! current gains as soon as they exist and, at the end, the identified encoder offset and
//! machine constants.

use super::calibration_state::Calibration;
use super::drive::Controller;
use crate::commissioning::{Action, Input};
use crate::io::Measurements;
use crate::supervisor::{FaultCode, Mode};
use crate::transforms::wrap_2pi;

impl Controller {
    /// The speed-loop tick in Calibrating: runs the speed PI only while commissioning asks
    /// for speed control, starting it bumplessly from the present q-current reference.
    pub(super) fn commission_speed_tick(&mut self, w: f32) {
        match self.commissioning.speed_setpoint() {
            Some(w_ref) if self.calibration == Calibration::Commission => {
                if !self.commission_speed_on {
                    self.speed.reset(self.observer.angle(), self.iq_ref);
                    self.commission_speed_on = true;
                }
                self.iq_ref = self.speed.step(w_ref, w);
            }
            _ => self.commission_speed_on = false,
        }
    }

    /// One commissioning period: (bridge on, electrical angle, fault found). Kept out of
    /// the ISR body's inlined code: it runs only while commissioning.
    #[inline(never)]
    pub(super) fn commission_step(&mut self, m: &Measurements) -> (bool, f32, Option<FaultCode>) {
        let input = Input {
            i_abc: self.current.phase_currents(m),
            u_dq_prev: self.state.u_dq,
            theta_e_raw: self.encoder.raw_electrical_angle(m.encoder_count),
            position_counts: self.encoder.position(),
            speed_rad_s: self.observer.filtered_speed_rad_s(),
        };
        let action = self.commissioning.step(&input);
        if let Some(g) = self.commissioning.take_new_gains() {
            self.current.set_gains(g.kp_d, g.kp_q, g.ki);
            let (l_d, l_q, _) = self.commissioning.machine();
            self.current
                .set_machine(l_d, l_q, self.cfg.motor.flux_linkage_wb);
            // The live parameter table holds what the loops use, so a later parameter
            // change (which retunes from the table) keeps the commissioned gains, and a
            // save stores them.
            let c = &mut self.cfg.current;
            (c.kp_d, c.kp_q, c.ki_d, c.ki_q) = (g.kp_d, g.kp_q, g.ki, g.ki);
            (self.cfg.motor.d_inductance_h, self.cfg.motor.q_inductance_h) = (l_d, l_q);
        }
        match action {
            Action::Off => (false, 0.0, None),
            Action::Current {
                theta_e,
                rotor_frame,
                i_ref,
            } => {
                self.id_ref = i_ref.d;
                self.iq_ref = i_ref.q;
                self.forced_frame = !rotor_frame;
                (true, theta_e, None)
            }
            Action::Voltage { theta_e, u } => {
                self.open_loop_voltage = Some(u);
                self.forced_frame = true;
                (true, theta_e, None)
            }
            Action::Speed { theta_e, .. } => {
                // iq_ref comes from the speed tick.
                self.id_ref = 0.0;
                self.forced_frame = false;
                (true, theta_e, None)
            }
            Action::Done => {
                if let Some(r) = self.commissioning.result() {
                    self.encoder.align(wrap_2pi(r.encoder_offset_rad));
                    self.current
                        .set_machine(r.d_inductance_h, r.q_inductance_h, r.flux_linkage_wb);
                    self.calibrated = true;
                    // The commissioning results in the live table (see above).
                    let m = &mut self.cfg.motor;
                    m.stator_resistance_ohm = r.stator_resistance_ohm;
                    m.d_inductance_h = r.d_inductance_h;
                    m.q_inductance_h = r.q_inductance_h;
                    m.flux_linkage_wb = r.flux_linkage_wb;
                    self.take_learned_encoder_offset();
                }
                self.finish_commissioning();
                // Disabled is always granted.
                let _ = self.sup.request(Mode::Disabled);
                (false, 0.0, None)
            }
            Action::Fault(f) => {
                // The supervisor latches `f` and disables the drive in this same period.
                self.finish_commissioning();
                (false, 0.0, Some(f))
            }
        }
    }

    fn finish_commissioning(&mut self) {
        self.commission_requested = false;
        self.commission_speed_on = false;
        self.forced_frame = false;
        self.id_ref = 0.0;
        self.iq_ref = 0.0;
        self.calibration = Calibration::START;
    }
}

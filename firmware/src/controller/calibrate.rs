//! The controller's calibrations: the phase-current offsets, averaged with the bridge off
//! over `calibration.offset_time_s` — once at power-up in Disabled, and again at the start
//! of Calibrating — and the encoder alignment (a d-axis current at θ_e = 0 pulls the
//! rotor's d axis onto phase a's; the count there is the electrical offset in the counter's
//! frame, [`crate::encoder::Encoder::align`]).
//!
//! Active modes wait for the power-up measurement ([`crate::supervisor::Readiness`]): an
//! offset left at the configured mid-scale is a constant error on every phase current, a
//! once-per-electrical-revolution ripple on i_d and i_q that the current loop then drives
//! into the motor. A measurement far from the configured zero (a dead amplifier supply, a
//! missing reference) latches [`FaultCode::CurrentOffset`] and starts again, so the drive
//! becomes ready once the cause is gone and the fault is cleared.

use super::calibration_state::Calibration;
use super::drive::Controller;
use crate::io::Measurements;
use crate::supervisor::{FaultCode, Mode};
use crate::transforms::wrap_2pi;

impl Controller {
    /// Takes a mean of the zero-current ADC results: in use from now on (true), or refused
    /// because it is farther than `calibration.offset_max_lsb` from the configured zero.
    fn accept_offsets(&mut self, mean: [f32; 3]) -> bool {
        let zero = self.cfg.sensors.current_zero_lsb;
        let limit = self.cfg.calibration.offset_max_lsb;
        if mean.iter().any(|o| (o - zero).abs() > limit) {
            return false;
        }
        self.current.set_offsets(mean);
        self.current.reset();
        self.offsets_measured = true;
        true
    }

    /// One Disabled sample of the power-up offset measurement (the bridge is off).
    pub(super) fn measure_boot_offsets(&mut self, m: &Measurements) {
        if let Some(mean) = self
            .boot_offsets
            .add(m.adc_phase_current, self.d.offset_calls)
        {
            if !self.accept_offsets(mean) {
                self.sup.trip(FaultCode::CurrentOffset);
            }
        }
    }

    /// One calibration sample: returns (bridge on, electrical angle to use, fault found).
    pub(super) fn calibrate(&mut self, m: &Measurements) -> (bool, f32, Option<FaultCode>) {
        match self.calibration {
            Calibration::Offsets(mut average) => {
                self.calibration = match average.add(m.adc_phase_current, self.d.offset_calls) {
                    None => Calibration::Offsets(average),
                    Some(mean) if !self.accept_offsets(mean) => {
                        return (false, 0.0, Some(FaultCode::CurrentOffset));
                    }
                    Some(_) if self.commission_requested => {
                        self.commissioning.start();
                        Calibration::Commission
                    }
                    Some(_) => Calibration::Align { n: 0 },
                };
                (false, 0.0, None)
            }
            Calibration::Align { n } => {
                self.id_ref = self.cfg.calibration.alignment_current_a;
                self.iq_ref = 0.0;
                let n = n + 1;
                if n >= self.d.align_calls {
                    // The rotor's d axis now sits at θ_e = 0: the count's electrical angle
                    // in the counter's frame is the offset.
                    let raw = self.encoder.raw_electrical_angle(m.encoder_count);
                    self.encoder.align(wrap_2pi(raw));
                    self.take_learned_encoder_offset();
                    self.calibrated = true;
                    self.id_ref = 0.0;
                    self.calibration = Calibration::START;
                    // Disabled is always granted.
                    let _ = self.sup.request(Mode::Disabled);
                    return (false, 0.0, None);
                }
                self.calibration = Calibration::Align { n };
                (true, 0.0, None)
            }
            Calibration::Commission => self.commission_step(m),
        }
    }
}

//! Three low-side shunts and their sampling window: which phase currents a sample can be
//! trusted for, and the rebuild of the one it cannot.
//!
//! A low-side shunt carries its phase's current only while that phase's low-side switch
//! (or its body diode) conducts. The ADC samples at the PWM counter's peak, the middle of
//! the interval in which all low sides conduct; with duty d (the high side's share of the
//! period) a phase's low side has conducted (1 − d)/(2·f_PWM) before that instant. The
//! reading is valid only if this covers the dead time, the switching ringing, the current
//! amplifier's settling and the ADC's sampling time — `sensors.shunt_settling_s` — so the
//! largest readable duty is `w = 1 − 2·t_settle·f_PWM` ([`max_sampled_duty`]; 0.92 for 2 µs
//! at 20 kHz). The modulator keeps at most one duty above w
//! ([`crate::svpwm::modulate_sampled`]); that phase's current is rebuilt from the other
//! two by Kirchhoff's law, i_x = −(i_y + i_z) (a star-connected motor without neutral).
//!
//! The duties in force around a sample are those of the previous period or of the one
//! before (the board loads new compare values one period after it computed them, the
//! simulator at once), so a phase above the window in either of the last two periods is
//! rebuilt.

/// Largest duty whose low-side conduction before the centre-aligned sampling instant lasts
/// `settle_s` [s] at `pwm_hz` [Hz]: `1 − 2·settle_s·pwm_hz`, within [0, 1]. [1]
pub fn max_sampled_duty(settle_s: f32, pwm_hz: f32) -> f32 {
    let w = 1.0 - 2.0 * settle_s * pwm_hz;
    if w.is_nan() {
        0.0
    } else {
        w.clamp(0.0, 1.0)
    }
}

use crate::svpwm::DutyWindow;

/// No phase to rebuild.
const NONE: u8 = 3;

/// The phases that were above the window in the last two periods.
#[derive(Clone, Copy, Debug)]
pub struct SamplingWindow {
    duty: DutyWindow,
    /// Phase (0‥2) above the window in the last recorded period, or [`NONE`].
    last: u8,
    /// Phase (0‥2) to rebuild in the next sample, or [`NONE`].
    rebuild: u8,
}

impl SamplingWindow {
    /// For the largest readable duty `max_duty` [1]; nothing recorded yet.
    pub fn new(max_duty: f32) -> SamplingWindow {
        SamplingWindow {
            duty: DutyWindow::new(max_duty),
            last: NONE,
            rebuild: NONE,
        }
    }

    /// Largest readable duty. [1]
    pub fn max_duty(&self) -> f32 {
        self.duty.max_duty
    }

    /// The window as the modulator's common path takes it.
    pub fn duty_window(&self) -> DutyWindow {
        self.duty
    }

    /// Forgets the duties (bridge off: no phase is left in a long high-side interval).
    pub fn reset(&mut self) {
        self.last = NONE;
        self.rebuild = NONE;
    }

    /// Records which phase the modulator left above the window this period
    /// ([`crate::svpwm::Modulation::above_window`]). The next sample distrusts the older
    /// period's phase if there was one — on the board its duty set the low-side interval
    /// before the sampling instant — else this period's. No float comparison here: the
    /// modulator has compared the duties already.
    #[inline]
    pub fn record(&mut self, above_window: Option<u8>) {
        let now = match above_window {
            Some(p) if p < NONE => p,
            _ => NONE,
        };
        self.rebuild = if self.last != NONE { self.last } else { now };
        self.last = now;
    }

    /// The phase the next sample cannot be trusted for, if any.
    #[inline]
    pub fn unreadable(&self) -> Option<usize> {
        (self.rebuild != NONE).then_some(self.rebuild as usize)
    }

    /// Phase currents `i` [A] with the unreadable one (if any) rebuilt from the other two.
    #[inline]
    pub fn rebuild(&self, i: [f32; 3]) -> [f32; 3] {
        let [a, b, c] = i;
        match self.rebuild {
            0 => [-(b + c), b, c],
            1 => [a, -(a + c), c],
            2 => [a, b, -(a + b)],
            _ => i,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_follows_from_the_settling_time() {
        // 2 µs of the 25 µs half period at 20 kHz.
        assert!((max_sampled_duty(2e-6, 20e3) - 0.92).abs() < 1e-6);
        assert!((max_sampled_duty(2e-6, 100e3) - 0.6).abs() < 1e-6);
        assert_eq!(max_sampled_duty(0.0, 20e3), 1.0);
        assert_eq!(max_sampled_duty(1.0, 20e3), 0.0);
        assert_eq!(max_sampled_duty(f32::NAN, 20e3), 0.0);
    }

    #[test]
    fn a_phase_above_the_window_in_either_of_the_last_two_periods_is_rebuilt() {
        let mut w = SamplingWindow::new(0.92);
        w.record(None);
        assert_eq!(w.unreadable(), None);
        w.record(Some(0));
        assert_eq!(w.unreadable(), Some(0));
        // Phase b takes over the top while a was above the window last period: a's duty
        // set the low-side interval before the next sample.
        w.record(Some(1));
        assert_eq!(w.unreadable(), Some(0));
        w.record(Some(1));
        assert_eq!(w.unreadable(), Some(1));
        assert_eq!(w.rebuild([1.0, 99.0, 2.0]), [1.0, -3.0, 2.0]);
        // Below the window again: one more period, then nothing.
        w.record(None);
        assert_eq!(w.unreadable(), Some(1));
        w.record(None);
        assert_eq!(w.unreadable(), None);
        assert_eq!(w.rebuild([1.0, 99.0, 2.0]), [1.0, 99.0, 2.0]);
        w.record(Some(2));
        w.reset();
        assert_eq!(w.unreadable(), None);
    }
}

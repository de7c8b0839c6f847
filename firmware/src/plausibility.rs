//! Plausibility of the measurements against the machine's physics, for the supervisor:
//! faults no single reading shows beyond a range.
//!
//! **Phase-current sum.** The motor is a star without a neutral, so by Kirchhoff's current
//! law i_a + i_b + i_c = 0 at every instant. Three sensed currents that do not sum to zero
//! mean a channel reads wrong (stuck, off in gain, clipping below its range) or current
//! leaves the star through a short from a phase to a DC-link rail or earth (the drive's
//! earth-fault check). The sum of three independent readings carries √3 times one
//! channel's noise; [`crate::config::FaultLimits::current_sum_a`] sits far above that and
//! above what the channels' gain tolerance makes of the largest current. Checked every
//! PWM period, so it latches in the call that reads it.
//!
//! **Stall.** The speed loop asks for its largest current only to accelerate the shaft,
//! which at that torque takes milliseconds; a q-current reference held at its limit while
//! the shaft is measured nearly at rest (below a tenth of the speed limit) for
//! [`crate::config::FaultLimits::stall_time_s`] means the shaft cannot turn (a seized pump,
//! a locked rotor) or the encoder does not see it turn (a stuck counter, A and B swapped:
//! the field then stays put or turns the wrong way and the rotor locks to it). A real
//! locked rotor at the current limit overheats the winding; either way the bridge goes off.

/// True when the three phase currents `i_abc` [A] do not sum to zero within `limit_a` [A]
/// (a NaN counts as not summing).
#[inline]
pub fn current_sum_off(i_abc: &[f32; 3], limit_a: f32) -> bool {
    let sum = i_abc[0] + i_abc[1] + i_abc[2];
    sum.is_nan() || sum.abs() > limit_a
}

/// The stall check's timer.
#[derive(Clone, Copy, Debug, Default)]
pub struct StallMonitor {
    calls: u32,
    limit_calls: u32,
}

impl StallMonitor {
    /// For `stall_time_s` [s] at the current-loop rate `pwm_hz` [Hz].
    pub fn new(stall_time_s: f32, pwm_hz: f32) -> StallMonitor {
        StallMonitor {
            calls: 0,
            limit_calls: ((stall_time_s * pwm_hz) as u32).max(1),
        }
    }

    /// One current-loop call: the speed loop `running` (Speed or Pressure mode) with the
    /// q-current reference `iq_ref` [A] against its limit `iq_limit` [A], the measured
    /// speed `speed` [rad/s] against the speed limit `speed_limit` [rad/s]. True once the
    /// reference has sat at its limit with the shaft nearly at rest for the stall time.
    #[inline]
    pub fn update(
        &mut self,
        running: bool,
        iq_ref: f32,
        iq_limit: f32,
        speed: f32,
        speed_limit: f32,
    ) -> bool {
        let saturated = iq_ref.abs() >= 0.99 * iq_limit;
        let at_rest = speed.abs() < 0.1 * speed_limit;
        if running && saturated && at_rest {
            self.calls = self.calls.saturating_add(1);
        } else {
            self.calls = 0;
        }
        self.calls > self.limit_calls
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_balanced_set_sums_to_zero_a_stuck_channel_does_not() {
        // 30 A peak at any angle: the sum is rounding only.
        for k in 0..360 {
            let th = k as f32 * core::f32::consts::PI / 180.0;
            let tau3 = core::f32::consts::TAU / 3.0;
            let i = [
                30.0 * libm::cosf(th),
                30.0 * libm::cosf(th - tau3),
                30.0 * libm::cosf(th + tau3),
            ];
            assert!(!current_sum_off(&i, 3.0), "{th}: {i:?}");
            // Channel a stuck at zero: the sum is −i_a.
            let stuck = [0.0, i[1], i[2]];
            assert_eq!(current_sum_off(&stuck, 3.0), i[0].abs() > 3.0, "{th}");
        }
        assert!(current_sum_off(&[f32::NAN, 0.0, 0.0], 3.0));
        // A 2 % gain error on one channel at the 45 A trip stays inside 3 A.
        assert!(!current_sum_off(&[45.0 * 1.02, -22.5, -22.5], 3.0));
    }

    #[test]
    fn stall_needs_the_limit_at_rest_for_the_whole_time() {
        // 0.1 s at 20 kHz: trips on call 2001, not before.
        let mut s = StallMonitor::new(0.1, 20e3);
        for k in 1..=2000 {
            assert!(!s.update(true, 30.0, 30.0, 0.5, 200.0), "call {k}");
        }
        assert!(s.update(true, -30.0, 30.0, -0.5, 200.0));
        // Any call off the limit, moving, or outside Speed/Pressure restarts the time.
        for interrupt in [(true, 29.0, 0.5), (true, 30.0, 25.0), (false, 30.0, 0.5)] {
            let mut s = StallMonitor::new(0.1, 20e3);
            for _ in 0..1500 {
                s.update(true, 30.0, 30.0, 0.0, 200.0);
            }
            s.update(interrupt.0, interrupt.1, 30.0, interrupt.2, 200.0);
            for k in 1..=2000 {
                assert!(!s.update(true, 30.0, 30.0, 0.0, 200.0), "{interrupt:?} {k}");
            }
        }
        // An acceleration at the limit through the slow band (5 ms) never trips.
        let mut s = StallMonitor::new(0.1, 20e3);
        for k in 0..100 {
            let w = 41_000.0 * k as f32 / 20e3;
            assert!(!s.update(true, 30.0, 30.0, w, 200.0));
        }
    }
}

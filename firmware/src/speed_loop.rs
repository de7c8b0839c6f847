//! The speed loop (Section 3.1, eq. 4, 7–8; Table 1 "Speed"): PI from speed error to the
//! q-current reference, with Table 1's feedback gain Ba as active damping.
//!
//! ## How Ba is read
//!
//! Table 1 lists for the speed regulator a "feedback gain Ba = 0.013" besides Kp and Ki.
//! This is the *active damping* of the textbook PMSM speed regulator (the form used with
//! MATLAB/Simulink PMSM models):
//!
//! ```text
//! i_q* = Kp·(ω* − ω) + Ki·∫(ω* − ω)dt − Ba·ω        [A], ω mechanical [rad/s]
//! ```
//!
//! Speed fed back through Ba acts as K_t·Ba = 0.0143 N·m·s of extra viscous damping (47×
//! the motor's own) without steady-state error, since the integrator supplies the
//! corresponding current. It is not read as a back-calculation anti-windup gain: as one,
//! 0.013 1/s would track the limit with a 77 s time constant, i.e. do nothing at these
//! rates. Anti-windup is therefore separate: back-calculation at Kb = Ki/Kp = 50 1/s (see
//! [`crate::pi`]), with the ±30 A limit on the whole output (damping term included).
//!
//! With J = 8.0e-4 kg·m² (motor + pump), B ≈ 3e-4 N·m·s and an ideal current loop the
//! closed loop is `J s² + (B + K_t(Kp + Ba)) s + K_t·Ki = 0`: poles at −67 and −143 rad/s
//! (ζ ≈ 1.07) with the PI zero at −Ki/Kp = −50 rad/s; the current loop (1100 rad/s) is
//! eight times faster than the fastest of them.
//!
//! Speed is the difference of the speed observer's angle estimate θ̂ over one speed period
//! (the M method on θ̂ rather than on the raw count; [`crate::speed_observer`]), so the
//! estimate is still the mean speed over the last period (0.25 ms behind, as the speed-step
//! design model assumes) but without the count's 1.26 rad/s quantum: θ̂ follows constant
//! speed and acceleration with no or constant error, and adds −0.8° and +0.3 dB at the
//! ≈ 200 rad/s crossover. Rate: see [`crate::config::Rates::speed_loop_hz`].

use crate::pi::Pi;
use crate::speed_observer::EstimatedAngle;

/// Speed PI with active damping and the speed estimate.
#[derive(Clone, Copy, Debug)]
pub struct SpeedLoop {
    pi: Pi,
    active_damping: f32,
    rad_s_per_count: f32,
    last_angle: EstimatedAngle,
    speed: f32,
}

impl SpeedLoop {
    /// From a validated configuration.
    pub fn new(cfg: &crate::config::Config) -> SpeedLoop {
        let t = 1.0 / cfg.rates.speed_loop_hz;
        let s = &cfg.speed;
        let n = cfg.sensors.encoder_counts_per_rev as f32;
        SpeedLoop {
            pi: Pi::new(s.kp, s.ki, t, -s.iq_limit_a, s.iq_limit_a),
            active_damping: s.active_damping,
            rad_s_per_count: core::f32::consts::TAU / n * cfg.rates.speed_loop_hz,
            last_angle: EstimatedAngle::default(),
            speed: 0.0,
        }
    }

    /// Takes changed gains, damping and current limit from `cfg` without resetting the
    /// integral (bumpless, [`Pi::set_gains`]).
    pub fn retune(&mut self, cfg: &crate::config::Config) {
        let s = &cfg.speed;
        self.pi.set_limits(-s.iq_limit_a, s.iq_limit_a);
        self.pi.set_gains(s.kp, s.ki);
        self.active_damping = s.active_damping;
    }

    /// Sets the integral to `iq` [A] (the loop resumes from there after a current step).
    pub fn set_integral(&mut self, iq: f32) {
        self.pi.reset(iq);
    }

    /// Measures the speed from the observer's angle estimate `angle` [counts] taken once
    /// per speed period; returns it. [rad/s]
    #[inline]
    pub fn measure(&mut self, angle: EstimatedAngle) -> f32 {
        // Saturated to 2^24 counts per period: a corrupted position gives a large but
        // finite speed.
        self.speed = angle.counts_since(&self.last_angle) * self.rad_s_per_count;
        self.last_angle = angle;
        self.speed
    }

    /// Last measured speed. [rad/s]
    pub fn speed(&self) -> f32 {
        self.speed
    }

    /// Restarts at the observer's `angle` with the integral at `iq` [A] (bumpless start).
    pub fn reset(&mut self, angle: EstimatedAngle, iq: f32) {
        self.last_angle = angle;
        self.pi.reset(iq);
    }

    /// One speed-loop step: reference `speed_ref` and measurement `speed` [rad/s] to the
    /// q-current reference [A].
    #[inline]
    pub fn step(&mut self, speed_ref: f32, speed: f32) -> f32 {
        self.pi
            .step(speed_ref - speed, -self.active_damping * speed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    #[test]
    fn speed_from_counts() {
        let cfg = Config::nominal();
        let mut s = SpeedLoop::new(&cfg);
        s.measure(EstimatedAngle {
            whole: 7,
            frac: 0.25,
        });
        // 100 counts in 0.5 ms = 0.01 rev / 0.5 ms = 20 rev/s = 125.66 rad/s.
        let w = s.measure(EstimatedAngle {
            whole: 107,
            frac: 0.25,
        });
        assert!((w - 20.0 * core::f32::consts::TAU).abs() < 1e-3);
    }

    #[test]
    fn active_damping_and_limit() {
        let cfg = Config::nominal();
        let mut s = SpeedLoop::new(&cfg);
        // Zero error at 100 rad/s: only the damping term, −0.013·100 = −1.3 A.
        assert!((s.step(100.0, 100.0) + 1.3).abs() < 1e-5);
        // Large error saturates at +30 A.
        assert_eq!(s.step(1000.0, 0.0), 30.0);
    }

    #[test]
    fn closed_loop_on_an_inertia_has_no_steady_state_error() {
        // Ideal current loop, J = 8e-4, B = 3.035e-4, K_t = 1.0962, 3 N·m load.
        let cfg = Config::nominal();
        let mut s = SpeedLoop::new(&cfg);
        let (j, b, kt, tl, dt) = (8.0e-4f32, 3.035e-4f32, 1.0962f32, 3.0f32, 5e-4f32);
        let mut w = 0.0f32;
        let mut peak = 0.0f32;
        for _ in 0..4000 {
            let iq = s.step(100.0, w);
            // Exact ZOH step of J w' = kt iq − tl − b w.
            let a = libm::expf(-b / j * dt);
            w = w * a + (1.0 - a) * (kt * iq - tl) / b;
            peak = peak.max(w);
        }
        assert!((w - 100.0).abs() < 0.05, "{w}");
        assert!(peak < 130.0, "{peak}");
    }
}

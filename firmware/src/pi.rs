//! Discrete PI controller with output limits, back-calculation anti-windup and bumpless
//! gain changes (Table 1's regulators are PI controllers with output limits).
//!
//! Continuous form: `u = Kp·e + Ki·∫e dt + u_ff`. Discretised step-invariantly (zero-order
//! hold on the sampled error, the integral of a held error is exact):
//!
//! ```text
//! u[k]   = Kp·e[k] + x[k] + ff[k],          y[k] = clamp(u[k], min, max)
//! x[k+1] = x[k] + Ki·T·e[k] + Kb·T·(y[k] − u[k])
//! ```
//!
//! so for a constant error E from k = 0 the output is `Kp·E + Ki·E·kT`, the continuous step
//! response sampled at t = kT. The integral state x is held in output units; changing Ki
//! therefore never moves the output, and [`Pi::set_gains`] moves x by `(Kp_old − Kp_new)·e`
//! so a Kp change does not either (bumpless gain scheduling).
//!
//! Anti-windup by back-calculation: while the output is limited, x is pulled toward the
//! value that puts u on the limit, at rate Kb. The default Kb = Ki/Kp makes x converge to the
//! limit itself during a long saturation (x' = Kb·(limit − x) once the Ki·e and −Kb·Kp·e
//! terms cancel), so when the error reverses the output leaves the limit at once; x is also
//! clamped to the output range so it can never wind beyond it. Kb·T is capped at 1
//! (dead-beat tracking), the stability bound of the discrete tracking loop.

/// `x` limited to `[lo, hi]` by two comparisons: unlike `f32::clamp` it has no panic path
/// (clamp asserts `lo <= hi`), and unlike `f32::max`/`min` it needs no `fmaxf`/`fminf` call
/// on a Cortex-M4F (no `vmaxnm` in FPv4), so the current-loop step stays branch-light.
/// A NaN `x` passes through unchanged; callers that care check finiteness first.
#[inline(always)]
pub fn saturate(x: f32, lo: f32, hi: f32) -> f32 {
    if x > hi {
        hi
    } else if x < lo {
        lo
    } else {
        x
    }
}

/// PI state and discretised gains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pi {
    kp: f32,
    ki_t: f32,
    kb_t: f32,
    t: f32,
    min: f32,
    max: f32,
    integral: f32,
    last_error: f32,
}

impl Pi {
    /// From continuous gains `kp` [out/in], `ki` [out/(in·s)], the sample time
    /// `sample_time_s` [s] and output limits (`min ≤ max`). The back-calculation gain is
    /// Ki/Kp (or 1/T when Kp = 0).
    pub fn new(kp: f32, ki: f32, sample_time_s: f32, min: f32, max: f32) -> Pi {
        let mut pi = Pi {
            kp: 0.0,
            ki_t: 0.0,
            kb_t: 0.0,
            t: sample_time_s.max(0.0),
            min: min.min(max),
            max: max.max(min),
            integral: 0.0,
            last_error: 0.0,
        };
        pi.set_gains_raw(kp, ki);
        pi
    }

    fn set_gains_raw(&mut self, kp: f32, ki: f32) {
        self.kp = kp;
        self.ki_t = ki * self.t;
        let kb = if kp > 0.0 {
            ki / kp
        } else {
            1.0 / self.t.max(1e-9)
        };
        self.kb_t = (kb * self.t).clamp(0.0, 1.0);
    }

    /// Overrides the back-calculation gain `kb` [1/s] (Kb·T is capped at 1).
    pub fn set_back_calculation(&mut self, kb: f32) {
        self.kb_t = (kb * self.t).clamp(0.0, 1.0);
    }

    /// Changes the gains without a step in the output: the integral absorbs the change of
    /// the proportional term at the last error.
    pub fn set_gains(&mut self, kp: f32, ki: f32) {
        let bump = (self.kp - kp) * self.last_error;
        self.integral = saturate(self.integral + bump, self.min, self.max);
        self.set_gains_raw(kp, ki);
    }

    /// Changes the output limits (`min ≤ max`); the integral is clamped into them.
    pub fn set_limits(&mut self, min: f32, max: f32) {
        self.min = min.min(max);
        self.max = max.max(min);
        self.integral = saturate(self.integral, self.min, self.max);
    }

    /// Sets the integral state (in output units) and forgets the last error: start a loop
    /// at `value` without a bump.
    pub fn reset(&mut self, value: f32) {
        self.integral = saturate(value, self.min, self.max);
        self.last_error = 0.0;
    }

    /// Integral state. [output units]
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Proportional gain. [out/in]
    pub fn kp(&self) -> f32 {
        self.kp
    }

    /// One step for `error` with feed-forward `ff` added before the limit. Infallible:
    /// a non-finite input leaves the state unchanged and returns the held integral.
    #[inline]
    pub fn step(&mut self, error: f32, ff: f32) -> f32 {
        let u = self.kp * error + self.integral + ff;
        if !u.is_finite() {
            return saturate(self.integral, self.min, self.max);
        }
        let y = saturate(u, self.min, self.max);
        self.integral = saturate(
            self.integral + self.ki_t * error + self.kb_t * (y - u),
            self.min,
            self.max,
        );
        self.last_error = error;
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_response_equals_the_continuous_pi_at_the_sample_instants() {
        // Continuous PI on a constant error E: u(t) = Kp·E + Ki·E·t.
        for (kp, ki, t) in [
            (13.2f32, 1053.8f32, 5e-5f32),
            (0.14, 7.0, 5e-4),
            (5.775, 1053.8, 1e-5),
        ] {
            let mut pi = Pi::new(kp, ki, t, -1e9, 1e9);
            let e = 0.37;
            for k in 0..2000 {
                let u = pi.step(e, 0.0);
                let tk = k as f64 * t as f64;
                let cont = kp as f64 * e as f64 + ki as f64 * e as f64 * tk;
                assert!(
                    (u as f64 - cont).abs() < 1e-4 * cont.abs().max(1.0),
                    "k {k}: {u} vs {cont}"
                );
            }
        }
    }

    #[test]
    fn ramp_response_matches_continuous_within_half_a_sample() {
        // e(t) = r·t: u(t) = Kp·r·t + Ki·r·t²/2. ZOH integration lags by T/2 at most.
        let (kp, ki, t, r) = (2.0f64, 50.0f64, 1e-3f64, 3.0f64);
        let mut pi = Pi::new(kp as f32, ki as f32, t as f32, -1e9, 1e9);
        for k in 0..1000 {
            let tk = k as f64 * t;
            let u = pi.step((r * tk) as f32, 0.0) as f64;
            let cont = kp * r * tk + ki * r * tk * tk / 2.0;
            let bound = ki * r * tk * t / 2.0 + 1e-4 * cont.abs() + 1e-5;
            assert!((u - cont).abs() <= bound, "k {k}: {u} vs {cont}");
        }
    }

    /// Simulates a PI (pole-zero cancelling, Kp = L·ω, Ki = R·ω) on an R-L load with the
    /// output limit, returning the peak overshoot of the current above `r` after a long
    /// saturation, and the largest integral seen.
    fn rl_overshoot(anti_windup: bool) -> (f64, f32) {
        let (r_ohm, l_h, w) = (0.958f64, 12e-3f64, 1100.0f64);
        let t = 5e-5f64;
        let limit = 20.0f32;
        let mut pi = Pi::new(
            (l_h * w) as f32,
            (r_ohm * w) as f32,
            t as f32,
            -limit,
            limit,
        );
        if !anti_windup {
            pi.set_back_calculation(0.0);
            pi.min = -1e9;
            pi.max = 1e9;
        }
        let reference = 15.0f64; // needs R·i = 14.4 V < 20 V in steady state
        let mut i = 0.0f64;
        let mut peak = 0.0f64;
        let mut max_integral = f32::MIN;
        for _ in 0..40_000 {
            let u = pi.step((reference - i) as f32, 0.0).clamp(-limit, limit) as f64;
            max_integral = max_integral.max(pi.integral());
            // Exact ZOH solution of L di/dt = u − R i over one period.
            let a = libm::exp(-r_ohm / l_h * t);
            i = i * a + (1.0 - a) * u / r_ohm;
            peak = peak.max(i - reference);
        }
        (peak, max_integral)
    }

    #[test]
    fn anti_windup_recovers_without_integrator_overshoot() {
        // The current saturates for ~17 ms (rises with τ = L/R = 12.5 ms at 20 V). With
        // back-calculation the integral sits on the limit when the error reaches 0; after
        // that the loop is linear with z = x − R·i decaying as e^{−t R/L} and
        // e' = −ω·e − z/L, so the overshoot is bounded by
        // z0/(L(ω − a))·max(e^{−a t} − e^{−ω t}), a = R/L, z0 = U_max − R·i_ref.
        let (r_ohm, l_h, w) = (0.958f64, 12e-3f64, 1100.0f64);
        let a = r_ohm / l_h;
        let z0 = 20.0 - r_ohm * 15.0;
        let t_star = (w / a).ln() / (w - a);
        let bound = z0 / (l_h * (w - a)) * ((-a * t_star).exp() - (-w * t_star).exp());
        let (with, max_x) = rl_overshoot(true);
        let (without, _) = rl_overshoot(false);
        assert!(max_x <= 20.0, "integral wound beyond the limit: {max_x}");
        assert!(
            with <= 1.05 * bound + 0.01,
            "overshoot {with} A, bound {bound} A"
        );
        // The check can fail: plain integration overshoots by far more.
        assert!(
            without > 5.0 * with.max(bound),
            "without anti-windup: {without} A"
        );
    }

    #[test]
    fn gain_change_is_bumpless() {
        let mut pi = Pi::new(1.0, 10.0, 1e-3, -100.0, 100.0);
        for _ in 0..100 {
            pi.step(2.0, 0.0);
        }
        let before = pi.step(2.0, 0.0);
        pi.set_gains(5.0, 40.0);
        let after = pi.step(2.0, 0.0);
        // Only one sample of integration separates the two outputs: Ki_old·T·e.
        assert!(
            (after - before - 10.0 * 1e-3 * 2.0).abs() < 1e-4,
            "{before} -> {after}"
        );
    }

    #[test]
    fn limits_and_non_finite_inputs() {
        let mut pi = Pi::new(1.0, 1.0, 1e-3, -2.0, 3.0);
        assert_eq!(pi.step(100.0, 0.0), 3.0);
        assert_eq!(pi.step(-100.0, 0.0), -2.0);
        let x = pi.integral();
        let y = pi.step(f32::NAN, 0.0);
        assert!(y.is_finite());
        assert_eq!(pi.integral(), x);
    }
}

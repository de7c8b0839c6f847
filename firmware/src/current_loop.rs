//! The d- and q-current loops with i_d = 0 control (Section 3.1, eq. 2 and 5–7; Table 1
//! Pi-Id and Pi-Iq): ADC scaling, Clarke, Park, two PIs, inverse Park and SVPWM in one
//! step per PWM period.
//!
//! The Table 1 gains are pole–zero cancellation on the stator's R-L (eq. 6): Kp = L·ω_c,
//! Ki = R_s·ω_c with ω_c = 1100 rad/s, so the closed current loop is first order with
//! τ = 1/ω_c = 0.91 ms. The PIs are limited to ±161.6 V (U_dc/√3, the SVPWM linear limit),
//! and the modulator limits the resulting vector to the hexagon keeping its angle.
//!
//! Optional decoupling (eq. 2's speed voltages) adds `u_d,ff = −ω_e·L_q·i_q` and
//! `u_q,ff = ω_e·(L_d·i_d + ψ_f·(1 − k(θ)))` before the limits, so the PIs see the bare
//! R-L of the design; without it the back-EMF is a disturbance the integrators reject.
//! k(θ) is the torque feed-forward's per-current channel ([`crate::compensation`]): with
//! i_d = 0 the flux harmonics' q-axis flux and its slope, ψ_df + ∂ψ_qf/∂θ_e, which set both
//! the torque per ampere (eq. 19) and the q-axis back-EMF, equal ψ_f·(1 − k(θ)); so the
//! same channel that cancels the harmonics' torque cancels their back-EMF, which the PI
//! would otherwise pass at the 6th electrical harmonic's frequency as a current ripple.
//!
//! Budget: one sin/cos pair (an interpolated table, [`crate::transforms::sin_cos`]), about
//! 60 floating-point operations; no division except one by the DC link, which is guarded,
//! and no clamp of the duties on the modulator's common path
//! ([`crate::svpwm::modulate_finite`]: the PIs' outputs are finite by construction).

use crate::io::Measurements;
use crate::pi::Pi;
use crate::shunt::{max_sampled_duty, SamplingWindow};
use crate::svpwm::modulate_finite;
use crate::transforms::{clarke, inverse_park, park, sin_cos, Dq, SinCos};

/// Everything the current-loop step measured and commanded.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CurrentLoopState {
    /// Phase currents a, b, c. [A]
    pub i_abc: [f32; 3],
    /// Measured d-q current. [A]
    pub i_dq: Dq,
    /// Commanded (limited) d-q voltage. [V]
    pub u_dq: Dq,
    /// Measured DC link. [V]
    pub u_dc: f32,
    /// Duties. [1]
    pub duties: [f32; 3],
}

/// The two current PIs with the sensor scaling and machine constants of the step.
#[derive(Clone, Copy, Debug)]
pub struct CurrentLoop {
    pi_d: Pi,
    pi_q: Pi,
    a_per_lsb: f32,
    offsets_lsb: [f32; 3],
    v_per_lsb: f32,
    l_d: f32,
    l_q: f32,
    psi_f: f32,
    decoupling: bool,
    window: SamplingWindow,
}

impl CurrentLoop {
    /// From a validated configuration; current offsets start at the configured zero.
    pub fn new(cfg: &crate::config::Config) -> CurrentLoop {
        let t = 1.0 / cfg.rates.pwm_hz;
        let c = &cfg.current;
        let lim = c.voltage_limit_v;
        CurrentLoop {
            pi_d: Pi::new(c.kp_d, c.ki_d, t, -lim, lim),
            pi_q: Pi::new(c.kp_q, c.ki_q, t, -lim, lim),
            a_per_lsb: cfg.sensors.current_a_per_lsb,
            offsets_lsb: [cfg.sensors.current_zero_lsb; 3],
            v_per_lsb: cfg.sensors.dc_link_v_per_lsb,
            l_d: cfg.motor.d_inductance_h,
            l_q: cfg.motor.q_inductance_h,
            psi_f: cfg.motor.flux_linkage_wb,
            decoupling: c.decoupling,
            window: SamplingWindow::new(max_sampled_duty(
                cfg.sensors.shunt_settling_s,
                cfg.rates.pwm_hz,
            )),
        }
    }

    /// Takes changed gains, voltage limit and machine constants from `cfg` without
    /// resetting the integrators (bumpless, [`Pi::set_gains`]).
    pub fn retune(&mut self, cfg: &crate::config::Config) {
        let c = &cfg.current;
        let lim = c.voltage_limit_v;
        self.pi_d.set_limits(-lim, lim);
        self.pi_q.set_limits(-lim, lim);
        self.pi_d.set_gains(c.kp_d, c.ki_d);
        self.pi_q.set_gains(c.kp_q, c.ki_q);
        self.l_d = cfg.motor.d_inductance_h;
        self.l_q = cfg.motor.q_inductance_h;
        self.psi_f = cfg.motor.flux_linkage_wb;
        self.decoupling = c.decoupling;
    }

    /// Sets the calibrated zero-current ADC results. [counts]
    pub fn set_offsets(&mut self, offsets_lsb: [f32; 3]) {
        self.offsets_lsb = offsets_lsb;
    }

    /// Zero-current ADC results in use. [counts]
    pub fn offsets(&self) -> [f32; 3] {
        self.offsets_lsb
    }

    /// Zeroes both integrators and forgets the duties (before the bridge is enabled).
    pub fn reset(&mut self) {
        self.pi_d.reset(0.0);
        self.pi_q.reset(0.0);
        self.window.reset();
    }

    /// The shunts' sampling window (which phase the next sample rebuilds).
    pub fn sampling_window(&self) -> &SamplingWindow {
        &self.window
    }

    /// Replaces the PI gains (commissioning's design): `kp_d`, `kp_q` [V/A] and one `ki`
    /// [V/(A·s)] for both axes (Ki = R_s·ω_c is the same on d and q), without an output step.
    pub fn set_gains(&mut self, kp_d: f32, kp_q: f32, ki: f32) {
        self.pi_d.set_gains(kp_d, ki);
        self.pi_q.set_gains(kp_q, ki);
    }

    /// Replaces the machine constants of the decoupling feed-forward: L_d, L_q [H] and
    /// ψ_f [Wb] (commissioning's identified values).
    pub fn set_machine(&mut self, l_d: f32, l_q: f32, psi_f: f32) {
        self.l_d = l_d;
        self.l_q = l_q;
        self.psi_f = psi_f;
    }

    /// Phase currents from the ADC results, the one outside its shunt's sampling window
    /// (if any) rebuilt from the other two ([`crate::shunt`]). [A]
    #[inline]
    pub fn phase_currents(&self, m: &Measurements) -> [f32; 3] {
        let [a, b, c] = m.adc_phase_current;
        let [oa, ob, oc] = self.offsets_lsb;
        self.window.rebuild([
            (a as f32 - oa) * self.a_per_lsb,
            (b as f32 - ob) * self.a_per_lsb,
            (c as f32 - oc) * self.a_per_lsb,
        ])
    }

    /// The sample's measurements at `theta_e` [rad] (phase and d-q currents, DC link),
    /// before any control, with the angle's sin/cos.
    #[inline]
    fn measure(&self, m: &Measurements, theta_e: f32) -> (CurrentLoopState, SinCos) {
        let i_abc = self.phase_currents(m);
        let sc = sin_cos(theta_e);
        let state = CurrentLoopState {
            i_abc,
            i_dq: park(clarke(i_abc[0], i_abc[1], i_abc[2]), sc),
            u_dq: Dq::default(),
            u_dc: m.adc_dc_link as f32 * self.v_per_lsb,
            duties: [0.5; 3],
        };
        (state, sc)
    }

    /// Open-loop voltage: modulates `u_dq` [V] at `theta_e` [rad] without the PIs (their
    /// integrators keep their state for the return to closed loop). Commissioning's
    /// inductance pulses use it, where the voltage must be known exactly.
    /// A non-finite voltage is zero.
    pub fn apply_voltage(&mut self, m: &Measurements, theta_e: f32, u_dq: Dq) -> CurrentLoopState {
        let u_dq = if u_dq.d.is_finite() && u_dq.q.is_finite() {
            u_dq
        } else {
            Dq::default()
        };
        let (state, sc) = self.measure(m, theta_e);
        self.with_voltage(state, sc, u_dq)
    }

    /// One current-loop step: measurement `m`, electrical angle `theta_e` [rad], current
    /// references `i_ref` [A], electrical speed `omega_e` [rad/s] and the flux harmonics'
    /// share `flux_ripple` = k(θ) of the magnet flux (0: none) for the decoupling.
    #[inline]
    pub fn step(
        &mut self,
        m: &Measurements,
        theta_e: f32,
        i_ref: Dq,
        omega_e: f32,
        flux_ripple: f32,
    ) -> CurrentLoopState {
        let (state, sc) = self.measure(m, theta_e);
        let i_dq = state.i_dq;
        let (ff_d, ff_q) = if self.decoupling {
            (
                -omega_e * self.l_q * i_dq.q,
                omega_e * (self.l_d * i_dq.d + self.psi_f - self.psi_f * flux_ripple),
            )
        } else {
            (0.0, 0.0)
        };
        let u_dq = Dq {
            d: self.pi_d.step(i_ref.d - i_dq.d, ff_d),
            q: self.pi_q.step(i_ref.q - i_dq.q, ff_q),
        };
        self.with_voltage(state, sc, u_dq)
    }

    /// `state` commanding the finite `u_dq` [V] at the angle of `sc`: the voltage and its
    /// duties, the middle one kept in its shunt's window; the duties are recorded for the
    /// next sample.
    #[inline]
    fn with_voltage(
        &mut self,
        mut state: CurrentLoopState,
        sc: SinCos,
        u_dq: Dq,
    ) -> CurrentLoopState {
        state.u_dq = u_dq;
        let m = modulate_finite(
            inverse_park(u_dq, sc),
            state.u_dc,
            self.window.duty_window(),
        );
        state.duties = m.duties;
        self.window.record(m.above_window);
        state
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    fn adc_for(i: [f32; 3]) -> Measurements {
        let lsb = 100.0 / 4096.0;
        Measurements {
            adc_phase_current: i.map(|x| (2048.0 + x / lsb + 0.5) as u16),
            adc_dc_link: 2800,
            ..Measurements::default()
        }
    }

    #[test]
    fn measures_dq_of_a_known_current() {
        // i_q = 10 A at θ_e = 0.6 rad: i_a = −10·sin θ, i_b = −10·sin(θ − 2π/3), ...
        let cfg = Config::nominal();
        let mut cl = CurrentLoop::new(&cfg);
        let th = 0.6f32;
        let tau3 = core::f32::consts::TAU / 3.0;
        let i = [
            -10.0 * libm::sinf(th),
            -10.0 * libm::sinf(th - tau3),
            -10.0 * libm::sinf(th + tau3),
        ];
        let s = cl.step(&adc_for(i), th, Dq { d: 0.0, q: 10.0 }, 0.0, 0.0);
        // Within the ADC's LSB (0.024 A).
        assert!((s.i_dq.q - 10.0).abs() < 0.06, "{:?}", s.i_dq);
        assert!(s.i_dq.d.abs() < 0.06, "{:?}", s.i_dq);
        assert!((s.u_dc - 280.0).abs() < 1e-3);
    }

    /// xorshift32 for the ADC noise.
    fn next(state: &mut u32) -> u32 {
        *state ^= *state << 13;
        *state ^= *state >> 17;
        *state ^= *state << 5;
        *state
    }

    /// Worst phase-current error over a turn of a 155 V command (96 % of the linear
    /// limit, so over most of the turn one phase's duty is above 0.92) with 20 A
    /// flowing 30° behind it; the readings carry ±1 LSB of noise, and the phase whose
    /// duty is above the window reads what a shunt sampled during its ringing reads (here
    /// +15 A of garbage). Returns (worst error [A], samples with a phase above the window).
    fn worst_error_at_high_duty(cfg: &Config) -> (f32, u32) {
        let lsb = 100.0 / 4096.0;
        let w = 1.0 - 2.0 * 2e-6 * 20e3;
        let mut cl = CurrentLoop::new(cfg);
        let mut rng = 0x1357_9bdfu32;
        let mut worst = 0f32;
        let mut above = 0;
        let tau3 = core::f32::consts::TAU / 3.0;
        for k in 0..720 {
            let th = k as f32 * core::f32::consts::PI / 360.0;
            let u = Dq { d: 0.0, q: 155.0 };
            // Two periods at this angle, so both duties the sample sees are known.
            let m0 = adc_for([0.0; 3]);
            let s1 = cl.apply_voltage(&m0, th, u);
            let s2 = cl.apply_voltage(&m0, th, u);
            let in_force: [f32; 3] = core::array::from_fn(|p| s1.duties[p].max(s2.duties[p]));
            let truth = [0.0, -tau3, tau3].map(|shift| {
                let phase = th - core::f32::consts::FRAC_PI_6 + shift;
                -20.0 * libm::sinf(phase)
            });
            let mut adc = [0u16; 3];
            for p in 0..3 {
                let noise = (next(&mut rng) % 3) as f32 - 1.0;
                let garbage = if in_force[p] > w { 15.0 } else { 0.0 };
                adc[p] = libm::roundf(2048.0 + (truth[p] + garbage) / lsb + noise) as u16;
            }
            if in_force.iter().any(|d| *d > w) {
                above += 1;
            }
            let got = cl.phase_currents(&Measurements {
                adc_phase_current: adc,
                adc_dc_link: 2800,
                ..Measurements::default()
            });
            for p in 0..3 {
                worst = worst.max((got[p] - truth[p]).abs());
            }
        }
        (worst, above)
    }

    #[test]
    fn a_phase_above_the_sampling_window_is_rebuilt_within_the_noise() {
        // Nominal: 2 µs of settling, readable duty 0.92. The rebuilt phase carries the two
        // others' rounding and noise: 2 × (0.5 + 1) LSB = 0.073 A at most.
        let (worst, above) = worst_error_at_high_duty(&Config::nominal());
        std::println!(
            "rebuilt: worst phase-current error {worst} A, {above} of 720 samples above the window"
        );
        assert!(above > 50, "{above} samples above the window");
        assert!(
            worst <= 3.0 * 100.0 / 4096.0 + 1e-4,
            "worst error {worst} A"
        );
        // Trusting every shunt (no window), the garbage goes straight into the currents.
        let mut trusting = Config::nominal();
        trusting.sensors.shunt_settling_s = 0.0;
        let (worst, _) = worst_error_at_high_duty(&trusting);
        std::println!("trusting every shunt: worst error {worst} A");
        assert!(worst > 14.0, "worst error {worst} A");
    }

    #[test]
    fn first_output_is_the_proportional_action_plus_decoupling() {
        let cfg = Config::nominal();
        let mut cl = CurrentLoop::new(&cfg);
        let s = cl.step(&adc_for([0.0; 3]), 0.0, Dq { d: 0.0, q: 2.0 }, 100.0, 0.0);
        // Kp_q·2 A + ω_e·ψ_f = 26.4 + 18.27 V; d: −ω_e·L_q·0 = 0.
        assert!(
            (s.u_dq.q - (13.2 * 2.0 + 100.0 * 0.1827)).abs() < 1e-3,
            "{:?}",
            s.u_dq
        );
        assert!(s.u_dq.d.abs() < 1e-3);
        for d in s.duties {
            assert!((0.0..=1.0).contains(&d));
        }
    }
}

//! The flux harmonics' back-EMF in the d- and q-current lines at order 6·p_n, for logs
//! without stator voltages.
//!
//! A magnet flux whose d-q image ripples at 6·θ_e (the 5th and 7th harmonics, eq. 17–18)
//! both ripples the torque (eq. 19) and induces a back-EMF. Power balance fixes the q part:
//! with i_d = 0 the electrical power (3/2)·e_q·i_q is the mechanical T_e·ω_m, so
//!
//! ```text
//!   e_q(θ) = ψ_eff(θ)·ω_e,   its line at 6·θ_e:  E_q = r·ψ_f·ω_e·e^{jφ}
//! ```
//!
//! with r·e^{jφ} the torque ripple's own line over the mean torque (`t6_ratio`, its phase),
//! whatever the split between the 5th and the 7th. The d part depends on that split (zero
//! when 5·ψ_5 = −7·ψ_7, as large as E_q for a lone 5th or 7th), which the effects contract
//! leaves open: it enters as a free complex amplitude, proportional to ψ_f·ω_e as any
//! back-EMF is.
//!
//! The current loops pass a voltage E as the line −H(jw)·E ([`disturbance_sensitivity`],
//! w = 6·p_n·ω̄), and the q loop also follows its reference, which the speed loop moves
//! against the shaft's oscillation: I_q,ref = −C_ω(jw)·jw·Θ with Θ the logged angle's line
//! and C_ω = K_p + K_i/(jw) + B_a (Table 1 with the active damping), followed by
//! G_i = (K_p·s + K_i)/(L·s² + (R + K_p)·s + K_i). Of the q-current line the back-EMF's is
//! therefore what the measured oscillation does not account for:
//!
//! ```text
//!   Y_q = I_q + G_i(jw)·C_ω(jw)·jw·Θ = H_q(jw)·ψ_f·ω_e·a
//! ```
//!
//! where a = −r·e^{jφ} is the same amplitude the torque line fits (the unexplained torque
//! line is minus the effect's). The speed loop's share is taken from the shaft's measured
//! oscillation rather than from a model of the shaft's response, so the shaft's load and
//! inertia do not enter. The loops are the rig's Table 1 design; a bench's own controller
//! and parts differ (the line's size then follows the bench's current-loop gains), so each
//! line carries, beside its noise floor, a model uncertainty of [`LOOP_TOLERANCE`] of the
//! terms computed with them.

use crate::diagnose::dead_time::disturbance_sensitivity;
use crate::diagnose::lines::{OrderLines, WindowLines};
use plant_model::Rig;
use rustfft::num_complex::Complex64;

/// Relative uncertainty of the current and speed loops' responses computed from the rig's
/// Table 1 gains and inductances. [1]
pub const LOOP_TOLERANCE: f64 = 0.25;

/// One measured line an amplitude explains: the line, what one unit of the amplitude makes
/// of it, and its noise variance per real component.
#[derive(Clone, Copy, Debug)]
pub struct LineObservation {
    /// The measured line. [unit of the signal]
    pub line: Complex64,
    /// The line one unit of amplitude makes. [unit of the signal]
    pub regressor: Complex64,
    /// Noise variance per real component, with the model's uncertainty. [unit²]
    pub var: f64,
}

/// The q current's closed-loop response to its reference on `rig` at angular frequency
/// `w`. [1]
pub fn current_tracking(rig: &Rig, w: f64) -> Complex64 {
    let c = closed_loop::controller_config(rig).current;
    let m = &rig.motor;
    let s = Complex64::new(0.0, w);
    let (kp, ki) = (c.kp_q as f64, c.ki_q as f64);
    (s * kp + ki) / (s * s * m.l_q_h + s * (m.r_s_ohm + kp) + ki)
}

/// The speed loop's q-current reference per unit angle line at `w`: C_ω(jw)·jw. [A/rad]
pub fn speed_reference_per_angle(rig: &Rig, w: f64) -> Complex64 {
    let c = closed_loop::controller_config(rig).speed;
    let s = Complex64::new(0.0, w);
    let pi = Complex64::new(c.kp as f64 + c.active_damping as f64, 0.0) + (c.ki as f64) / s;
    pi * s
}

/// The q and d back-EMF lines of window `w` at its 6·p_n order `o` (`candidates` kept out
/// of the noise floors); `None` for a window without a speed or a floor.
pub fn back_emf_lines(
    w: &WindowLines,
    o: &OrderLines,
    rig: &Rig,
    candidates: &[u32],
) -> Option<[LineObservation; 2]> {
    let speed = w.window.speed_rad_s;
    let freq = o.order as f64 * speed;
    if freq == 0.0 {
        return None;
    }
    let floor_q = w.floor(o.order, candidates, |x| x.iq);
    let floor_d = w.floor(o.order, candidates, |x| x.id);
    if !(floor_q.is_finite() && floor_d.is_finite()) {
        return None;
    }
    let tol = |z: Complex64| 0.5 * (LOOP_TOLERANCE * z.norm()).powi(2);
    let emf_per_unit = rig.motor.psi_f_wb * rig.motor.pole_pairs as f64 * speed;
    let (hd, hq) = disturbance_sensitivity(rig, freq);
    // The speed loop's share, from the shaft's measured oscillation.
    let share = -(current_tracking(rig, freq) * speed_reference_per_angle(rig, freq)) * o.theta;
    let q_line = o.iq - share;
    Some([
        LineObservation {
            line: q_line,
            regressor: hq * emf_per_unit,
            var: floor_q + tol(q_line) + tol(share),
        },
        LineObservation {
            line: o.id,
            regressor: hd * emf_per_unit,
            var: floor_d + tol(o.id),
        },
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_current_loop_follows_slow_references_and_lets_fast_ones_pass_attenuated() {
        // Far below its bandwidth a PI loop tracks (G → 1); far above, G → K_p/(L·s).
        let rig = Rig::nominal();
        let c = closed_loop::controller_config(&rig).current;
        assert!((current_tracking(&rig, 0.1) - 1.0).norm() < 1e-3);
        let w = 1e6;
        let far = current_tracking(&rig, w).norm() * rig.motor.l_q_h * w / c.kp_q as f64;
        assert!((far - 1.0).abs() < 0.01, "{far}");
    }

    /// Lines at 6·θ_e of the q and d back-EMF over ψ_1·ω_e and of the torque over its mean,
    /// from eq. 17's phase flux linkages with harmonics ψ_5, ψ_7 (a 2 A q current).
    fn lines_from_phase_fluxes(psi5: f64, psi7: f64) -> (Complex64, Complex64, Complex64) {
        let (psi1, pp, w_m, i_q) = (0.18, 4.0, 50.0, 2.0);
        let w_e = pp * w_m;
        let n = 3600;
        let third = 2.0 * std::f64::consts::PI / 3.0;
        let (mut eq6, mut ed6, mut t6, mut t0) = (
            Complex64::default(),
            Complex64::default(),
            Complex64::default(),
            0.0,
        );
        for k in 0..n {
            let th = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            // dψ_x/dθ_e of ψ_1·cos(θ_x) + ψ_5·cos(5θ_x) + ψ_7·cos(7θ_x), θ_x = θ − 0, ∓2π/3.
            let slope = |x: f64| {
                -psi1 * x.sin() - 5.0 * psi5 * (5.0 * x).sin() - 7.0 * psi7 * (7.0 * x).sin()
            };
            let angles = [th, th - third, th + third];
            let e: Vec<f64> = angles.iter().map(|&x| w_e * slope(x)).collect();
            let i: Vec<f64> = angles.iter().map(|&x| -i_q * x.sin()).collect();
            let torque = e.iter().zip(&i).map(|(e, i)| e * i).sum::<f64>() / w_m;
            let e_q = -2.0 / 3.0 * angles.iter().zip(&e).map(|(x, e)| e * x.sin()).sum::<f64>();
            let e_d = 2.0 / 3.0 * angles.iter().zip(&e).map(|(x, e)| e * x.cos()).sum::<f64>();
            let basis = Complex64::from_polar(2.0 / n as f64, -6.0 * th);
            eq6 += basis * e_q;
            ed6 += basis * e_d;
            t6 += basis * torque;
            t0 += torque / n as f64;
        }
        (eq6 / (psi1 * w_e), ed6 / (psi1 * w_e), t6 / t0)
    }

    #[test]
    fn the_q_back_emf_line_is_the_torque_ripple_for_any_fifth_seventh_split() {
        // Power balance: the q back-EMF's line over ψ_f·ω_e equals the torque's line over the
        // mean torque, whether the 5th, the 7th or both make it; the d part follows the split
        // (zero when 5·ψ_5 = −7·ψ_7, as large as the q part for a lone harmonic).
        let splits = [
            (0.002, 0.0),
            (0.0, 0.0015),
            (-0.0036, 0.00257),
            (0.001, 0.001),
        ];
        for (psi5, psi7) in splits {
            let (eq, ed, t) = lines_from_phase_fluxes(psi5, psi7);
            assert!(t.norm() > 0.01, "a ripple is there: {t}");
            assert!(
                (eq - t).norm() < 1e-9 * t.norm().max(1.0),
                "{psi5}, {psi7}: {eq} vs {t}"
            );
            let lone = psi5 == 0.0 || psi7 == 0.0;
            let cancelling = (5.0 * psi5 + 7.0 * psi7).abs() < 1e-4;
            if lone {
                assert!((ed.norm() / eq.norm() - 1.0).abs() < 1e-9, "{ed} vs {eq}");
            } else if cancelling {
                assert!(ed.norm() < 0.01 * eq.norm(), "{ed} vs {eq}");
            }
        }
    }

    #[test]
    fn the_speed_loop_reference_is_its_pi_on_the_angle_rate() {
        // C_ω(jw)·jw = (K_p + B_a)·jw + K_i: at w = 100 rad/s with Table 1's 0.14, 0.013
        // and 7: 7 + j·15.3.
        let rig = Rig::nominal();
        let z = speed_reference_per_angle(&rig, 100.0);
        assert!((z - Complex64::new(7.0, 15.3)).norm() < 1e-4, "{z}");
    }
}

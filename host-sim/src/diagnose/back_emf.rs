//! The flux harmonics' back-EMF at order 6·p_n: in the d- and q-current lines when the
//! log has no stator voltages, in the commanded voltages' lines when it has them.
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
//! back-EMF is. In the amplitude a = −r·e^{jφ} the torque line fits (the unexplained
//! torque line is minus the effect's), E_q = −ψ_f·ω_e·a.
//!
//! **Without the voltages** ([`back_emf_lines`]) the current loops pass a voltage E as the
//! line −H(jw)·E ([`disturbance_sensitivity`], w = 6·p_n·ω̄), and the q loop also follows
//! its reference, which the speed loop moves against the shaft's oscillation:
//! I_q,ref = −C_ω(jw)·jw·Θ with Θ the logged angle's line and C_ω = K_p + K_i/(jw) + B_a
//! (Table 1 with the active damping), followed by
//! G_i = (K_p·s + K_i)/(L·s² + (R + K_p)·s + K_i). Of the q-current line the back-EMF's is
//! therefore what the measured oscillation does not account for:
//!
//! ```text
//!   Y_q = I_q + G_i(jw)·C_ω(jw)·jw·Θ = H_q(jw)·ψ_f·ω_e·a
//! ```
//!
//! The speed loop's share is taken from the shaft's measured oscillation rather than from a
//! model of the shaft's response, so the shaft's load and inertia do not enter. The loops
//! are the rig's Table 1 design; a bench's own controller and parts differ (the line's size
//! then follows the bench's current-loop gains), so each line carries, beside its noise
//! floor, a model uncertainty of [`LOOP_TOLERANCE`] of the terms computed with them.
//!
//! **With the voltages** ([`voltage_lines`]) no loop enters: the stator equations (eq.
//! 1–2) at one order, with the speed's line jw·Θ from the logged angle,
//!
//! ```text
//!   Y_q = U_q − (R + jw·L_q)·I_q − ω̄_e·L_d·I_d − p_n·(L_d·ī_d + ψ_f)·jw·Θ = −ψ_f·ω̄_e·a
//!   Y_d = U_d − (R + jw·L_d)·I_d + ω̄_e·L_q·I_q + p_n·L_q·ī_q·jw·Θ        = ψ_f·ω̄_e·b
//! ```
//!
//! leave the back-EMF's lines, whatever controller commanded the voltages (b the free d
//! amplitude). Each carries the calibrated stator constants' tolerances
//! ([`STATOR_TOLERANCE`]) on the terms computed with them.

use crate::diagnose::lines::{OrderLines, WindowLines};
use crate::diagnose::loop_response::{
    current_tracking, disturbance_sensitivity, speed_reference_per_angle, LOOP_TOLERANCE,
};
use plant_model::Rig;
use rustfft::num_complex::Complex64;

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

/// The weighted least-squares complex amplitude of `lines` (each line its regressor times
/// the amplitude, plus noise of its variance) and its information Σ |x|²/σ²; its likelihood
/// ratio against no amplitude is |a|²·information. `None` without information.
pub fn weighted_amplitude<'a>(
    lines: impl Iterator<Item = &'a LineObservation> + Clone,
) -> Option<(Complex64, f64)> {
    let info: f64 = lines.clone().map(|o| o.regressor.norm_sqr() / o.var).sum();
    (info > 0.0).then(|| {
        let a = lines
            .map(|o| o.regressor.conj() * o.line / o.var)
            .sum::<Complex64>()
            / info;
        (a, info)
    })
}

/// The power of a measured line `y` that a predicted line `predicted` explains, over the
/// line's noise variance `var`: (|y|² − |y − ŷ|²)/σ², the likelihood ratio's share of one
/// line (negative where the prediction is worse than none). [1]
#[inline]
pub fn explained_power(y: Complex64, predicted: Complex64, var: f64) -> f64 {
    (y.norm_sqr() - (y - predicted).norm_sqr()) / var
}

/// Relative uncertainty of the calibrated resistance, inductances and flux linkage in the
/// voltage lines: R, L and ψ_f in that order (winding temperature, saturation, magnets). [1]
pub const STATOR_TOLERANCE: [f64; 3] = [0.2, 0.1, 0.05];

/// The stator constants the voltage lines are read with (the electrical relation's
/// calibration).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stator {
    /// Phase resistance. [Ω]
    pub r_s_ohm: f64,
    /// d inductance. [H]
    pub l_d_h: f64,
    /// q inductance. [H]
    pub l_q_h: f64,
    /// Magnet flux linkage. [Wb]
    pub psi_f_wb: f64,
}

/// The voltages' lines at one order less what the stator equations make of the current and
/// speed lines: the back-EMF lines (Y_d, Y_q) the model lacks and the variance the
/// stator's tolerances leave on each; `None` without the voltages. [V, V²]
fn voltage_residuals(
    w: &WindowLines,
    o: &OrderLines,
    rig: &Rig,
    s: &Stator,
) -> Option<([Complex64; 2], [f64; 2])> {
    let [u_d, u_q] = o.voltages?;
    let pp = rig.motor.pole_pairs as f64;
    let speed = w.window.speed_rad_s;
    let jw = Complex64::new(0.0, o.order as f64 * speed);
    let w_e = pp * speed;
    let [tr, tl, tpsi] = STATOR_TOLERANCE;
    let rate = jw * o.theta * pp;
    let q_terms = [
        (s.r_s_ohm * o.iq, tr),
        (jw * s.l_q_h * o.iq, tl),
        (w_e * s.l_d_h * o.id, tl),
        (rate * s.l_d_h * w.id_mean_a, tl),
        (rate * s.psi_f_wb, tpsi),
    ];
    let d_terms = [
        (s.r_s_ohm * o.id, tr),
        (jw * s.l_d_h * o.id, tl),
        (-w_e * s.l_q_h * o.iq, tl),
        (-rate * s.l_q_h * w.iq_mean_a, tl),
    ];
    let residual = |u: Complex64, terms: &[(Complex64, f64)]| {
        let y = u - terms.iter().map(|(z, _)| z).sum::<Complex64>();
        let var = terms
            .iter()
            .map(|(z, t)| 0.5 * (t * z.norm()).powi(2))
            .sum();
        (y, var)
    };
    let (yd, vd) = residual(u_d, &d_terms);
    let (yq, vq) = residual(u_q, &q_terms);
    Some(([yd, yq], [vd, vq]))
}

/// The q and d back-EMF lines of window `w` at its 6·p_n order `o` from the logged
/// voltages read with the stator constants `s` (`candidates` kept out of the noise
/// floors); `None` for a window without the voltages, a speed or a floor.
pub fn voltage_lines(
    w: &WindowLines,
    o: &OrderLines,
    rig: &Rig,
    s: &Stator,
    candidates: &[u32],
) -> Option<[LineObservation; 2]> {
    let emf_per_unit = s.psi_f_wb * rig.motor.pole_pairs as f64 * w.window.speed_rad_s;
    if emf_per_unit == 0.0 {
        return None;
    }
    let ([yd, yq], [vd, vq]) = voltage_residuals(w, o, rig, s)?;
    let floor = |axis: usize| {
        w.floor(o.order, candidates, |x| {
            voltage_residuals(w, x, rig, s).map_or(Complex64::default(), |(y, _)| y[axis])
        })
    };
    let (floor_d, floor_q) = (floor(0), floor(1));
    if !(floor_q.is_finite() && floor_d.is_finite()) {
        return None;
    }
    Some([
        LineObservation {
            line: yq,
            regressor: Complex64::new(-emf_per_unit, 0.0),
            var: floor_q + vq,
        },
        LineObservation {
            line: yd,
            regressor: Complex64::new(emf_per_unit, 0.0),
            var: floor_d + vd,
        },
    ])
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
    fn the_voltage_lines_leave_the_back_emf_the_stator_equations_lack() {
        // A shaft turning at 30 rad/s with a small oscillation at order 24, d and q currents
        // with lines of their own, and the voltages of eq. 1–2 evaluated in time plus a
        // back-EMF line E_q = −ψ_f·ω̄_e·a, E_d = ψ_f·ω̄_e·b: the residual lines are a and b.
        use crate::diagnose::steady::SteadyWindow;
        use std::f64::consts::PI;
        let rig = Rig::nominal();
        let m = &rig.motor;
        let s = Stator {
            r_s_ohm: m.r_s_ohm,
            l_d_h: m.l_d_h,
            l_q_h: m.l_q_h,
            psi_f_wb: m.psi_f_wb,
        };
        let pp = m.pole_pairs as f64;
        let (k, speed, eps) = (24u32, 30.0, 1e-3);
        let kf = k as f64;
        let (a, b) = (
            Complex64::from_polar(0.05, 0.7),
            Complex64::from_polar(0.02, -1.9),
        );
        let w_e = pp * speed;
        let (e_q, e_d) = (-s.psi_f_wb * w_e * a, s.psi_f_wb * w_e * b);
        let line = |z: Complex64, th: f64| (z * Complex64::from_polar(1.0, kf * th)).re;
        let (iq_line, id_line) = (
            Complex64::from_polar(0.2, 0.5),
            Complex64::from_polar(0.15, -1.0),
        );
        let revs = 20.0;
        let n = 200_000;
        let dt = revs * 2.0 * PI / speed / n as f64;
        let theta = |t: f64| speed * t + eps * (kf * speed * t + 0.3).sin();
        let rate = |t: f64| speed + eps * kf * speed * (kf * speed * t + 0.3).cos();
        let (iq, id) = (
            |t: f64| 3.0 + line(iq_line, theta(t)),
            |t: f64| 0.1 + line(id_line, theta(t)),
        );
        let deriv = |f: &dyn Fn(f64) -> f64, t: f64| (f(t + 1e-7) - f(t - 1e-7)) / 2e-7;
        // Lines against e^{jkθ} by projection over whole revolutions, at k and neighbours,
        // of the signals less their means (as the lock-in fits a mean beside the lines).
        let samples: Vec<(f64, [f64; 5])> = (0..n)
            .map(|i| {
                let t = i as f64 * dt;
                let th = theta(t);
                let we = pp * rate(t);
                let u_q = s.r_s_ohm * iq(t)
                    + s.l_q_h * deriv(&iq, t)
                    + we * (s.l_d_h * id(t) + s.psi_f_wb)
                    + line(e_q, th);
                let u_d = s.r_s_ohm * id(t) + s.l_d_h * deriv(&id, t) - we * s.l_q_h * iq(t)
                    + line(e_d, th);
                (th, [iq(t), id(t), th - speed * t, u_d, u_q])
            })
            .collect();
        let mut mean = [0.0; 5];
        for (_, y) in &samples {
            for (m, v) in mean.iter_mut().zip(y) {
                *m += v / n as f64;
            }
        }
        let mut acc = vec![[Complex64::default(); 5]; 9];
        for (th, y) in &samples {
            for (j, o) in (k - 4..=k + 4).enumerate() {
                let basis = Complex64::from_polar(2.0 / n as f64, -(o as f64) * th);
                for ((z, v), m) in acc[j].iter_mut().zip(y).zip(&mean) {
                    *z += basis * (v - m);
                }
            }
        }
        let orders: Vec<OrderLines> = (k - 4..=k + 4)
            .zip(&acc)
            .map(|(order, z)| OrderLines {
                order,
                iq: z[0],
                id: z[1],
                theta: z[2],
                theta_counts: 0.0,
                p: Complex64::default(),
                torque: Complex64::default(),
                voltages: Some([z[3], z[4]]),
                dead_time_voltages: Vec::new(),
            })
            .collect();
        let w = WindowLines {
            window: SteadyWindow {
                rows: 0..n,
                speed_rad_s: speed,
                revolutions: revs,
            },
            iq_mean_a: 3.0,
            id_mean_a: 0.1,
            dp_mean_pa: 0.0,
            orders: orders.clone(),
        };
        let [q, d] = voltage_lines(&w, &orders[4], &rig, &s, &[k]).unwrap();
        // The shaft's oscillation alone makes a q-voltage line p_n·ψ_f·jw·Θ this large:
        let swing = pp * s.psi_f_wb * kf * speed * eps;
        assert!(
            swing > 0.3 * (q.regressor * a).norm(),
            "the oscillation matters: {swing}"
        );
        let fitted_a = q.line / q.regressor;
        let fitted_b = d.line / d.regressor;
        assert!((fitted_a - a).norm() < 0.02 * a.norm(), "{fitted_a} vs {a}");
        assert!((fitted_b - b).norm() < 0.02 * b.norm(), "{fitted_b} vs {b}");
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

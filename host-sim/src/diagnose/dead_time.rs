//! Inverter dead time from the current lines, for logs without stator voltages.
//!
//! The dead time's voltage error (the plant's [`Inverter`]: each leg loses a voltage
//! against its current's sign, faded within a current band) has, in d-q, a constant part the
//! current PIs integrate away and a sixth-harmonic part (order 6·p_n of the shaft) they
//! only partly reject: a voltage U_6 on an axis of inductance L and resistance R under a PI
//! of gains K_p, K_i leaves the current line
//!
//! ```text
//!   I_6 = U_6 · s / (L·s² + (R + K_p)·s + K_i),   s = j·6·ω_e
//! ```
//!
//! (the loop's disturbance sensitivity, Table 1's gains from the rig). Along q the current
//! vector makes U_6 mostly a d-axis voltage, so the d current carries the dead time's
//! line while a torque effect at the same order (flux harmonics) shows in the torque balance
//! instead ([`super::angle_locked`]).
//!
//! U_6 is read from the currents that flowed ([`crate::diagnose::lines::dead_time_voltage`]):
//! the current line the dead time causes (0.2 A on a 1 A load) moves the phase currents'
//! zero crossings and with them the voltage the dead time makes, which the mean current
//! alone would overstate by half. With the angle logged the phase currents are placed and
//! the model's lines keep their phases: per steady window the model's complex lines per
//! unit dead time, the measured ones, by weighted least squares (each line's variance its
//! noise floor plus [`LOOP_TOLERANCE`] of it: the loops are Table 1's, a bench's differ),
//! the fade band searched over a grid (it is not in the rig contract). Without the angle
//! the phases are not placed: the magnitudes at the window's mean current.

use crate::diagnose::back_emf::explained_power;
use crate::diagnose::lines::{OrderLines, WindowLines};
use crate::diagnose::loop_response::{
    current_tracking, disturbance_sensitivity, speed_reference_per_angle, LOOP_TOLERANCE,
};
use plant_model::inverter::{dq_to_abc, pole_to_dq, Inverter};
use plant_model::Rig;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

pub use crate::diagnose::lines::{DEAD_TIME_BANDS_A as BANDS_A, REFERENCE_DEAD_TIME_S};

/// Longest dead time a line is read as, as a fraction of the PWM period: gate drivers
/// insert 0.1–3 µs, a few per cent of a 20 kHz period; lines that would need more are not
/// a dead time's (at a light load, where the current stays inside the fade band, a small
/// line divided by a vanishing model line would otherwise read as seconds). [1]
pub const MAX_DEAD_TIME_PERIODS: f64 = 0.1;

/// The largest dead time a line is read as on `rig` ([`MAX_DEAD_TIME_PERIODS`] of its PWM
/// period), in units of [`REFERENCE_DEAD_TIME_S`]. [1]
pub fn max_scale(rig: &Rig) -> f64 {
    MAX_DEAD_TIME_PERIODS / rig.inverter.pwm_frequency_hz.max(1.0) / REFERENCE_DEAD_TIME_S
}

/// Standard error of a dead time `dead_time_s` read from lines with likelihood ratio
/// `lambda` (Λ is the squared scale over its variance). [s]
pub fn standard_error(dead_time_s: f64, lambda: f64) -> f64 {
    dead_time_s / lambda.max(f64::MIN_POSITIVE).sqrt()
}

/// The dead time's sixth-harmonic d-q voltage at a constant current (i_d, i_q) for `band`,
/// per [`REFERENCE_DEAD_TIME_S`]: the plant's inverter over one electrical turn. The
/// reading without the angle, where the phases' zero crossings are not placed. [V]
pub fn sixth_harmonic_voltage(rig: &Rig, i_d: f64, i_q: f64, band: f64) -> (Complex64, Complex64) {
    let mut p = rig.inverter.clone();
    p.dead_time_s = REFERENCE_DEAD_TIME_S;
    p.dead_time_current_band_a = band.max(1e-6);
    let inv = Inverter::new(&p);
    let n = 720;
    let (mut d, mut q) = (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
    for k in 0..n {
        let th = 2.0 * PI * k as f64 / n as f64;
        let (s, c) = th.sin_cos();
        let v = inv.pole_voltages(&[0.0; 3], &dq_to_abc(i_d, i_q, s, c));
        let (ud, uq) = pole_to_dq(&v, s, c);
        let e = Complex64::from_polar(2.0 / n as f64, -6.0 * th);
        d += e * ud;
        q += e * uq;
    }
    (d, q)
}

/// A dead-time fit.
#[derive(Clone, Debug)]
pub struct DeadTimeFit {
    /// Dead time. [s]
    pub dead_time_s: f64,
    /// The fade band that fits best. [A]
    pub band_a: f64,
    /// Line power explained (twice the log-likelihood gain). [1]
    pub lambda: f64,
    /// Windows used.
    pub windows: usize,
    /// Whether the lines were compared with their phases (the angle logged).
    pub coherent: bool,
}

/// One window's measured and modelled d and q lines with their noise variances (per real
/// component); without the angle, their magnitudes on the real axis.
struct Obs {
    measured: [Complex64; 2],
    model: [Complex64; 2],
    var: [f64; 2],
    /// The variances that weigh the scale's estimate and choose the fade band: the noise
    /// floors, and on q the variance of the outer loops' corrections ([`loop_lines`]).
    /// Weights from the measured lines would bias the scale; the corrections' come from the
    /// shaft's oscillation, not from the current lines. [A²]
    scale_var: [f64; 2],
}

/// The index of `band` in [`BANDS_A`].
fn band_index(band: f64) -> usize {
    BANDS_A.iter().position(|b| *b == band).unwrap_or(0)
}

fn observations(lines: &[&WindowLines], rig: &Rig, band: f64, candidates: &[u32]) -> Vec<Obs> {
    let pp = rig.motor.pole_pairs;
    let order = 6 * pp;
    let b = band_index(band);
    lines
        .iter()
        .filter_map(|w| {
            let o = w.at(order)?;
            let [y_d, y_q, model_var] = loop_lines(w, o, rig)?;
            let floor_d = w.floor(order, candidates, |x| x.id);
            let floor_q = w.floor(order, candidates, |x| x.iq);
            // The loops' model is Table 1's: its uncertainty on top of the noise floor. The
            // q line's corrections for the speed loop and the back-EMF carry theirs into the
            // scale's weights too: at holding speed the outer loops act on the q current,
            // and its model is the less certain of the two.
            let tol = |z: Complex64| 0.5 * (LOOP_TOLERANCE * z.norm()).powi(2);
            let (var_d, var_q) = (floor_d + tol(y_d), floor_q + tol(y_q) + model_var.re);
            if !(var_d.is_finite() && var_q.is_finite()) {
                return None;
            }
            let w6 = o.order as f64 * w.window.speed_rad_s;
            let (hd, hq) = disturbance_sensitivity(rig, w6);
            let (measured, model) = match o.dead_time_voltages.get(b) {
                // The voltage the logged currents make, phase and all.
                Some([ed, eq]) => ([y_d, y_q], [hd * ed, hq * eq]),
                None => {
                    let (ed, eq) = sixth_harmonic_voltage(rig, 0.0, w.iq_mean_a, band);
                    let real = |z: Complex64| Complex64::new(z.norm(), 0.0);
                    ([real(y_d), real(y_q)], [real(hd * ed), real(hq * eq)])
                }
            };
            Some(Obs {
                measured,
                model,
                var: [var_d, var_q],
                scale_var: [floor_d, floor_q + model_var.re],
            })
        })
        .collect()
}

/// The d and q current lines of window `w` at its order `o` that a disturbance voltage
/// alone explains through the current loops, and the variance (its real part) the q line's
/// corrections carry: the d line as measured; of the q line what the shaft's measured
/// oscillation Θ does not account for, the speed loop's answer to it (its reference
/// −C_ω·jw·Θ followed by the q loop, [`current_tracking`]) and the current its back-EMF
/// p_n·ψ_f·jw·Θ drives through the q loop:
///
/// ```text
///   Y_q = I_q + G_i(jw)·C_ω(jw)·jw·Θ + H_q(jw)·p_n·ψ_f·jw·Θ = H_q(jw)·U_q
/// ```
///
/// `None` for a window without a speed.
fn loop_lines(w: &WindowLines, o: &OrderLines, rig: &Rig) -> Option<[Complex64; 3]> {
    let freq = o.order as f64 * w.window.speed_rad_s;
    if freq == 0.0 {
        return None;
    }
    let jw_theta = Complex64::new(0.0, freq) * o.theta;
    let (_, hq) = disturbance_sensitivity(rig, freq);
    let speed_loop = current_tracking(rig, freq) * speed_reference_per_angle(rig, freq) * o.theta;
    let emf = hq * (rig.motor.pole_pairs as f64 * rig.motor.psi_f_wb) * jw_theta;
    let tol = |z: Complex64| 0.5 * (LOOP_TOLERANCE * z.norm()).powi(2);
    Some([
        o.id,
        o.iq + speed_loop + emf,
        Complex64::new(tol(speed_loop) + tol(emf), 0.0),
    ])
}

/// Fits the dead time to the d and q current lines at order 6·p_n of `lines`.
pub fn fit_dead_time(lines: &[&WindowLines], rig: &Rig, candidates: &[u32]) -> Option<DeadTimeFit> {
    let mut best: Option<(f64, DeadTimeFit)> = None;
    let max_scale = max_scale(rig);
    let coherent = lines
        .iter()
        .any(|w| w.orders.iter().any(|o| !o.dead_time_voltages.is_empty()));
    for band in BANDS_A {
        let obs = observations(lines, rig, band, candidates);
        if obs.is_empty() {
            return None;
        }
        let Some((scale, by_floor, lambda)) = solve(&obs, max_scale) else {
            continue;
        };
        let fit = DeadTimeFit {
            dead_time_s: scale * REFERENCE_DEAD_TIME_S,
            band_a: band,
            lambda,
            windows: obs.len(),
            coherent,
        };
        if best.as_ref().is_none_or(|(b, _)| by_floor > *b) {
            best = Some((by_floor, fit));
        }
    }
    best.map(|(_, fit)| fit)
}

/// The line power the model lines at `scale` explain in `obs`, each line weighed by
/// `weight`. [1]
fn explained(obs: &[Obs], scale: f64, weight: fn(&Obs, usize) -> f64) -> f64 {
    obs.iter()
        .flat_map(|o| {
            (0..2).map(move |a| explained_power(o.measured[a], o.model[a] * scale, weight(o, a)))
        })
        .sum::<f64>()
}

/// The weighted least-squares scale of the model lines onto the measured ones, and the
/// line power it explains weighed by the scale's variances (which choose the fade band)
/// and with the loops' uncertainty (the reported Λ); `None` when no model line is there or
/// the scale would pass `max_scale`.
fn solve(obs: &[Obs], max_scale: f64) -> Option<(f64, f64, f64)> {
    let (mut num, mut den) = (0.0, 0.0);
    for o in obs {
        for a in 0..2 {
            num += (o.model[a].conj() * o.measured[a]).re / o.scale_var[a];
            den += o.model[a].norm_sqr() / o.scale_var[a];
        }
    }
    if den <= 0.0 {
        return None;
    }
    let scale = (num / den).max(0.0);
    if scale > max_scale {
        return None;
    }
    Some((
        scale,
        explained(obs, scale, |o, a| o.scale_var[a]).max(0.0),
        explained(obs, scale, |o, a| o.var[a]).max(0.0),
    ))
}

/// The line power `fit` explains in the windows `lines`. [1]
pub fn dead_time_gain(
    fit: &DeadTimeFit,
    lines: &[&WindowLines],
    rig: &Rig,
    candidates: &[u32],
) -> Option<f64> {
    let obs = observations(lines, rig, fit.band_a, candidates);
    if obs.is_empty() {
        return None;
    }
    Some(explained(
        &obs,
        fit.dead_time_s / REFERENCE_DEAD_TIME_S,
        |o, a| o.var[a],
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_loops_reject_a_slow_disturbance_and_pass_a_fast_one_through_the_winding() {
        // Far below the loop bandwidth the sensitivity is s/K_i; far above, 1/(L·s).
        let rig = Rig::nominal();
        let c = closed_loop::controller_config(&rig).current;
        let (hd, _) = disturbance_sensitivity(&rig, 1.0);
        assert!((hd.norm() - 1.0 / c.ki_d as f64).abs() < 0.01 / c.ki_d as f64);
        let (hd, _) = disturbance_sensitivity(&rig, 1e6);
        assert!((hd.norm() * rig.motor.l_d_h * 1e6 - 1.0).abs() < 0.01);
    }

    #[test]
    fn lines_are_scaled_onto_the_model_and_refused_beyond_the_plausible_dead_time() {
        // Two windows whose d and q lines are 3× the model's: a scale of 3, and all of the
        // line power (9 + 9 + 36 + 36 noise units over unit variances) explained.
        let c = |x: f64| Complex64::new(x, 0.0);
        let obs = [
            Obs {
                measured: [c(3.0), c(3.0)],
                model: [c(1.0), c(1.0)],
                var: [1.0, 1.0],
                scale_var: [1.0, 1.0],
            },
            Obs {
                measured: [c(6.0), c(6.0)],
                model: [c(2.0), c(2.0)],
                var: [1.0, 1.0],
                scale_var: [1.0, 1.0],
            },
        ];
        let (scale, lambda, _) = solve(&obs, 10.0).unwrap();
        assert!((scale - 3.0).abs() < 1e-12 && (lambda - 90.0).abs() < 1e-9);
        // The same lines where the model has almost none: the scale would be 3·10⁶.
        let faint = obs.map(|o| Obs {
            model: [o.model[0] * 1e-6, o.model[1] * 1e-6],
            ..o
        });
        assert!(solve(&faint, 10.0).is_none());
        // At 20 kHz a tenth of the period is 5 µs: 5 references of 1 µs.
        let rig = Rig::nominal();
        let bound = MAX_DEAD_TIME_PERIODS / rig.inverter.pwm_frequency_hz / REFERENCE_DEAD_TIME_S;
        assert!((bound - 5.0).abs() < 1e-9);
    }

    #[test]
    fn a_square_wave_dead_time_error_has_the_textbook_sixth_harmonic() {
        // Far above the fade band each phase loses V·sign(i), a square wave with harmonics
        // (4/π)·V/h; in d-q along q its 5th and 7th become the sixth, adding on the d axis,
        // (4/π)·V·(1/5 + 1/7), and subtracting on q, (4/π)·V·(1/5 − 1/7).
        let rig = Rig::nominal();
        let (d, q) = sixth_harmonic_voltage(&rig, 0.0, 100.0, 0.01);
        let mut p = rig.inverter.clone();
        p.dead_time_s = REFERENCE_DEAD_TIME_S;
        let leg = Inverter::new(&p).pole_voltages(&[0.0; 3], &[100.0, -50.0, -50.0])[0].abs();
        let expected = 4.0 / PI * leg * 12.0 / 35.0;
        assert!(
            (d.norm() / expected - 1.0).abs() < 0.02,
            "{} vs {expected}",
            d.norm()
        );
        let expected_q = 4.0 / PI * leg * 2.0 / 35.0;
        assert!(
            (q.norm() / expected_q - 1.0).abs() < 0.05,
            "{} vs {expected_q}",
            q.norm()
        );
    }
}

//! The lines at order 6·p_n in the logged voltages read two ways: as the flux harmonics'
//! back-EMF, or as an inverter dead time's voltage error.
//!
//! The back-EMF at 6·θ_e is ψ_f·ω_e times a fixed complex ratio on each axis
//! ([`super::back_emf`]): its lines grow with the speed, one free complex amplitude per
//! axis (four real parameters). A dead time's lines are the voltage its legs lose against
//! their currents' signs, −t_d·f_pwm·U_dc·sat(i/band) per phase, turned into d-q: computed
//! per window from the currents that flowed ([`crate::diagnose::lines::dead_time_voltage`],
//! per unit of [`REFERENCE_DEAD_TIME_S`]), so their size follows the current vector and
//! the fade band, not ω_e, and one real scale (the dead time) fixes both axes. With the
//! voltages logged the stator equations leave Y = U_cmd − (R·I + L·dI/dt + e) = −U_dt:
//! the regressor of the dead time's law is minus the computed voltage.
//!
//! Both laws are fitted by weighted least squares to the same lines with the same
//! variances, so their generalised likelihood ratios
//!
//! ```text
//!   Λ = |Σ_k x̄_k·y_k/σ_k²|² / Σ_k |x_k|²/σ_k²        (a complex amplitude, per axis)
//!   Λ = (Σ_k Re(x̄_k·y_k)/σ_k²)² / Σ_k |x_k|²/σ_k²     (a real scale, both axes)
//! ```
//!
//! are of the same residuals; each is compared with its own χ² quantile (4 and 1 degrees
//! of freedom) in [`super::decision::apply_vetoes`].

use crate::diagnose::back_emf::{explained_power, weighted_amplitude, LineObservation};
use crate::diagnose::lines::{DEAD_TIME_BANDS_A, REFERENCE_DEAD_TIME_S};
use rustfft::num_complex::Complex64;

/// A back-EMF voltage line of one window with the dead time's regressors on its axis.
#[derive(Clone, Copy, Debug)]
pub struct EmfLine {
    /// The line and its regressor under the back-EMF's law (∝ ω_e).
    pub of: LineObservation,
    /// The d axis (its own amplitude) rather than the q axis.
    pub d_axis: bool,
    /// The line one [`REFERENCE_DEAD_TIME_S`] of dead time makes on this axis, per fade band
    /// of [`DEAD_TIME_BANDS_A`]. [V]
    pub dead_time: [Complex64; DEAD_TIME_BANDS_A.len()],
}

/// The two laws' likelihood ratios on the same voltage lines.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmfLaw {
    /// Λ of the back-EMF's law (4 degrees of freedom). [1]
    pub emf_lambda: f64,
    /// Λ of the dead time's law at its best fade band (1 degree of freedom). [1]
    pub dead_time_lambda: f64,
    /// The dead time that law fits. [s]
    pub dead_time_s: f64,
    /// Its fade band, as an index into [`DEAD_TIME_BANDS_A`].
    pub band: usize,
}

/// Λ of one complex amplitude per axis of the back-EMF's law.
fn emf_lambda(lines: &[EmfLine]) -> f64 {
    [false, true]
        .iter()
        .filter_map(|&d| {
            let axis = lines.iter().filter(move |l| l.d_axis == d).map(|l| &l.of);
            weighted_amplitude(axis).map(|(a, info)| a.norm_sqr() * info)
        })
        .sum()
}

/// The dead time's scale (in units of the reference) and Λ at fade band `b`: the scale
/// kept non-negative (a dead time only takes voltage away), and no reading (Λ = 0) where
/// it would pass `max_scale` (a light load's vanishing model line).
fn dead_time_fit(lines: &[EmfLine], b: usize, max_scale: f64) -> (f64, f64) {
    let (mut info, mut score) = (0.0, 0.0);
    for l in lines {
        let x = -l.dead_time[b];
        info += x.norm_sqr() / l.of.var;
        score += (x.conj() * l.of.line).re / l.of.var;
    }
    if info > 0.0 && score > 0.0 && score / info <= max_scale {
        (score / info, score * score / info)
    } else {
        (0.0, 0.0)
    }
}

/// Both laws on `lines`, the dead time read up to `max_scale` references
/// ([`crate::diagnose::dead_time::max_scale`]); `None` without a line of finite positive
/// variance.
pub fn emf_law(lines: &[EmfLine], max_scale: f64) -> Option<EmfLaw> {
    let usable: Vec<EmfLine> = lines.iter().filter(|l| usable(l)).copied().collect();
    if usable.is_empty() {
        return None;
    }
    let (band, (scale, lambda)) = (0..DEAD_TIME_BANDS_A.len())
        .map(|b| (b, dead_time_fit(&usable, b, max_scale)))
        .max_by(|x, y| x.1 .1.total_cmp(&y.1 .1))?;
    Some(EmfLaw {
        emf_lambda: emf_lambda(&usable),
        dead_time_lambda: lambda,
        dead_time_s: scale * REFERENCE_DEAD_TIME_S,
        band,
    })
}

/// A line with a finite positive variance.
fn usable(l: &EmfLine) -> bool {
    l.of.var > 0.0 && l.of.var.is_finite()
}

impl EmfLaw {
    /// The fade band of the dead time's law. [A]
    pub fn band_a(&self) -> f64 {
        DEAD_TIME_BANDS_A[self.band]
    }

    /// How much of the line power of `lines` (another segment's) this law's dead time
    /// predicts: Σ (|y|² − |y − ŷ|²)/σ², positive when its lines are there; `None` without
    /// a line. [1]
    pub fn gain(&self, lines: &[EmfLine]) -> Option<f64> {
        let scale = self.dead_time_s / REFERENCE_DEAD_TIME_S;
        let (n, gain) = lines
            .iter()
            .filter(|l| usable(l))
            .map(|l| explained_power(l.of.line, -l.dead_time[self.band] * scale, l.of.var))
            .fold((0, 0.0), |(n, sum), g| (n + 1, sum + g));
        (n > 0).then_some(gain)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plant_model::inverter::{dq_to_abc, pole_to_dq, Inverter};
    use plant_model::Rig;
    use std::f64::consts::PI;

    /// The dead time's d and q voltage lines at 6·θ_e for a constant current (i_d, i_q), per
    /// microsecond, from the plant's inverter over one electrical turn (fade band 0.1 A).
    fn dead_time_lines(i_d: f64, i_q: f64) -> [Complex64; 2] {
        let mut p = Rig::nominal().inverter;
        p.dead_time_s = 1e-6;
        p.dead_time_current_band_a = 0.1;
        let inv = Inverter::new(&p);
        let n = 720;
        let mut out = [Complex64::default(); 2];
        for k in 0..n {
            let th = 2.0 * PI * k as f64 / n as f64;
            let (s, c) = th.sin_cos();
            let (ud, uq) = pole_to_dq(
                &inv.pole_voltages(&[0.0; 3], &dq_to_abc(i_d, i_q, s, c)),
                s,
                c,
            );
            let e = Complex64::from_polar(2.0 / n as f64, -6.0 * th);
            out[0] += e * ud;
            out[1] += e * uq;
        }
        out
    }

    /// Windows at `speeds` (rad/s) and q currents `currents` (A) whose voltage lines are
    /// `truth(dead-time lines, speed)`, read with a back-EMF regressor of 0.72 V per rad/s
    /// (ψ_f·p_n) and a noise variance of 1e-4 V².
    fn lines(
        speeds: &[f64],
        currents: &[f64],
        truth: impl Fn([Complex64; 2], f64) -> [Complex64; 2],
    ) -> Vec<EmfLine> {
        let band = DEAD_TIME_BANDS_A.iter().position(|b| *b == 0.1).unwrap();
        speeds
            .iter()
            .zip(currents)
            .flat_map(|(&w, &iq)| {
                let dt = dead_time_lines(0.0, iq);
                let y = truth(dt, w);
                [(true, 0), (false, 1)].map(|(d_axis, a)| {
                    let mut per_band = [Complex64::default(); DEAD_TIME_BANDS_A.len()];
                    per_band[band] = dt[a];
                    EmfLine {
                        of: LineObservation {
                            line: y[a],
                            regressor: Complex64::new(if d_axis { 0.72 } else { -0.72 } * w, 0.0),
                            var: 1e-4,
                        },
                        d_axis,
                        dead_time: per_band,
                    }
                })
            })
            .collect()
    }

    #[test]
    fn a_dead_times_lines_fit_its_own_law_and_are_read_back_at_its_size() {
        // 1.5 µs of dead time: Y = −1.5·U_dt(1 µs), whatever the speed.
        let lines = lines(&[6.0, 7.5, 40.0], &[1.0, 1.2, 0.6], |dt, _| {
            dt.map(|z| -1.5 * z)
        });
        let law = emf_law(&lines, 5.0).unwrap();
        assert!((law.dead_time_s - 1.5e-6).abs() < 1e-12, "{law:?}");
        assert_eq!(law.band_a(), 0.1);
        assert!(law.dead_time_lambda > law.emf_lambda + 10.0, "{law:?}");
        // Its prediction is the lines themselves: the gain on them is their whole power.
        let power: f64 = lines.iter().map(|l| l.of.line.norm_sqr() / l.of.var).sum();
        let gain = law.gain(&lines).unwrap();
        assert!((gain - power).abs() < 1e-9 * power, "{gain} vs {power}");
        // A dead time beyond the plausible bound is no reading.
        assert_eq!(emf_law(&lines, 1.0).unwrap().dead_time_lambda, 0.0);
    }

    #[test]
    fn a_back_emf_growing_with_speed_fits_the_emf_law_better() {
        // E_q = −0.72·ω·a, E_d = 0.72·ω·b with fixed a, b, at speeds 6 to 40 rad/s.
        let (a, b) = (
            Complex64::from_polar(0.01, 0.4),
            Complex64::from_polar(0.006, -1.2),
        );
        let law = emf_law(
            &lines(&[6.0, 7.5, 40.0], &[1.0, 1.2, 0.6], |_, w| {
                [0.72 * w * b, -0.72 * w * a]
            }),
            5.0,
        )
        .unwrap();
        let power = [6.0f64, 7.5, 40.0]
            .iter()
            .map(|w| (0.72 * w).powi(2) * (a.norm_sqr() + b.norm_sqr()) / 1e-4)
            .sum::<f64>();
        assert!(
            (law.emf_lambda - power).abs() < 1e-9 * power,
            "{law:?} {power}"
        );
        assert!(law.dead_time_lambda < 0.5 * law.emf_lambda, "{law:?}");
    }
}

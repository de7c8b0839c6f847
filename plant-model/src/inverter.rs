//! Two-level voltage-source inverter, average model over one PWM period, with the optional
//! dead-time voltage error of Section 4.1 (2).
//!
//! Each leg's average pole voltage is d_x·U_dc. During the dead time both switches of a leg
//! are off and the phase current free-wheels through a diode: a positive (motor-bound)
//! current through the lower diode, a negative one through the upper. Each PWM period has
//! two such intervals, but only one of them departs from the command: for a positive
//! current the rising edge comes t_d late (the lower diode holds the pole low) while the
//! falling edge does not (the diode takes over exactly when the upper switch opens). The
//! average pole voltage therefore loses t_d·f_pwm·U_dc·sign(i_x), the textbook
//! (t_d/T_pwm)·U_dc. The
//! sign fades linearly within a small current band: there the ripple current reverses within
//! the period and the error shrinks. The motor sees the pole voltages less their mean (the
//! star point floats), transformed to d-q with the amplitude-invariant Clarke and Park
//! transforms.

use crate::rig::InverterParams;

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// Inverter equations with precomputed constants.
#[derive(Clone, Debug)]
pub struct Inverter {
    /// U_dc. [V]
    pub u_dc_v: f64,
    /// Dead-time voltage error at full current over U_dc, t_d·f_pwm. [1]
    dead_time_fraction: f64,
    /// Dead-time voltage error at full current, t_d·f_pwm·U_dc. [V]
    dead_time_error_v: f64,
    /// Current band of the dead-time sign. [A]
    band_a: f64,
}

impl Inverter {
    /// From validated parameters.
    pub fn new(p: &InverterParams) -> Inverter {
        Inverter {
            u_dc_v: p.u_dc_v,
            dead_time_fraction: p.dead_time_s * p.pwm_frequency_hz,
            dead_time_error_v: p.dead_time_s * p.pwm_frequency_hz * p.u_dc_v,
            band_a: p.dead_time_current_band_a,
        }
    }

    /// Takes a new DC-link voltage (a supply fault's bus voltage), scaling the dead-time
    /// error with it. [V]
    #[inline]
    pub fn set_u_dc(&mut self, u_dc_v: f64) {
        if u_dc_v != self.u_dc_v {
            self.u_dc_v = u_dc_v;
            self.dead_time_error_v = self.dead_time_fraction * u_dc_v;
        }
    }

    /// Whether the dead-time error is modelled (then the pole voltages depend on the currents).
    #[inline]
    pub fn has_dead_time(&self) -> bool {
        self.dead_time_fraction > 0.0
    }

    /// Average pole voltages without dead time, d_x·U_dc. [V]
    #[inline]
    pub fn pole_voltages_ideal(&self, duties: &[f64; 3]) -> [f64; 3] {
        duties.map(|d| d * self.u_dc_v)
    }

    /// Average pole voltages (against the negative rail) for `duties` and phase currents
    /// `i_abc` (positive into the motor). [V]
    #[inline]
    pub fn pole_voltages(&self, duties: &[f64; 3], i_abc: &[f64; 3]) -> [f64; 3] {
        let drop = self.dead_time_drop(i_abc);
        [
            duties[0] * self.u_dc_v - drop[0],
            duties[1] * self.u_dc_v - drop[1],
            duties[2] * self.u_dc_v - drop[2],
        ]
    }

    /// The dead time's drop split at phase currents `i_abc`: each pole's constant part
    /// (±t_d·f_pwm·U_dc outside the current band, 0 inside) and the band's slope
    /// t_d·f_pwm·U_dc/band, the resistance a phase inside it sees. [V], [Ω]
    #[inline]
    pub fn dead_time_parts(&self, i_abc: &[f64; 3]) -> ([f64; 3], f64) {
        let e = self.dead_time_error_v;
        let out = |i: f64| {
            if i >= self.band_a {
                e
            } else if i <= -self.band_a {
                -e
            } else {
                0.0
            }
        };
        (i_abc.map(out), e / self.band_a)
    }

    /// The dead time's current band. [A]
    #[inline]
    pub fn band(&self) -> f64 {
        self.band_a
    }

    /// What the dead time takes off each pole's average voltage at phase currents `i_abc`
    /// (positive into the motor): t_d·f_pwm·U_dc·sign(i), fading linearly within the current
    /// band. [V]
    #[inline]
    pub fn dead_time_drop(&self, i_abc: &[f64; 3]) -> [f64; 3] {
        if self.dead_time_error_v > 0.0 {
            i_abc.map(|i| self.dead_time_error_v * (i / self.band_a).clamp(-1.0, 1.0))
        } else {
            [0.0; 3]
        }
    }
}

/// Phase (star) voltages from pole voltages, to d-q at the given sin/cos of θ_e. [V]
#[inline]
pub fn pole_to_dq(v_pole: &[f64; 3], sin_e: f64, cos_e: f64) -> (f64, f64) {
    let mean = (v_pole[0] + v_pole[1] + v_pole[2]) / 3.0;
    let va = v_pole[0] - mean;
    let (vb, vc) = (v_pole[1] - mean, v_pole[2] - mean);
    let alpha = va;
    let beta = (vb - vc) / SQRT3;
    (alpha * cos_e + beta * sin_e, -alpha * sin_e + beta * cos_e)
}

/// Phase currents from d-q currents at the given sin/cos of θ_e. [A]
#[inline]
pub fn dq_to_abc(i_d: f64, i_q: f64, sin_e: f64, cos_e: f64) -> [f64; 3] {
    let alpha = i_d * cos_e - i_q * sin_e;
    let beta = i_d * sin_e + i_q * cos_e;
    [
        alpha,
        -0.5 * alpha + 0.5 * SQRT3 * beta,
        -0.5 * alpha - 0.5 * SQRT3 * beta,
    ]
}

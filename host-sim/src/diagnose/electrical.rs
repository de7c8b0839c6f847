//! Electrical replay: the d-q voltages the controller must have commanded, predicted from the
//! logged currents and shaft motion with the stator equations (eq. 1–2) and the inverter's
//! dead-time error (Section 4.1 (2)), for comparison with the logged `ud_v`/`uq_v`.
//!
//! u_d = R_s·i_d + L_d·di_d/dt − ω_e·L_q·i_q,   u_q = R_s·i_q + L_q·di_q/dt + ω_e·(L_d·i_d + ψ_f)
//!
//! are the voltages the motor needs; the inverter loses, per leg, 2·t_d·f_pwm·U_dc·sign(i_x)
//! (faded linearly within the rig's current band), whose common mode the floating star point
//! removes. The controller regulates the currents, so its command is the motor's need plus
//! that loss: a dead time the model lacks shows in the residual as a voltage vector along the
//! current with a sixth-harmonic ripple, while a current-sensor offset or a torque ripple
//! barely moves it. The derivative is the central difference of the logged currents.
//!
//! This replay is algebraic (no state), so it costs one pass over the log.

use crate::bench_log::BenchLog;
use plant_model::Rig;

/// Predicted commanded voltages, row for row. [V]
#[derive(Clone, Debug, PartialEq)]
pub struct ElectricalReplay {
    /// d-axis voltage. [V]
    pub ud_v: Vec<f64>,
    /// q-axis voltage. [V]
    pub uq_v: Vec<f64>,
}

/// Predicts `ud_v`, `uq_v` for the first `rows` rows of `log` on `rig`; `None` when the log
/// has no shaft angle (the dead-time pattern needs the electrical angle).
pub fn replay_electrical(log: &BenchLog, rig: &Rig, rows: usize) -> Option<ElectricalReplay> {
    let theta = log.theta_m_rad.as_deref()?;
    let n = rows.min(log.len());
    let m = &rig.motor;
    let pp = m.pole_pairs as f64;
    let u_dc = log.udc_v.as_deref().map_or(rig.inverter.u_dc_v, |u| {
        u.iter().sum::<f64>() / u.len() as f64
    });
    let loss_v = 2.0 * rig.inverter.dead_time_s * rig.inverter.pwm_frequency_hz * u_dc;
    let band = rig.inverter.dead_time_current_band_a.max(1e-9);
    let t = &log.t_s;
    let deriv = |y: &[f64], k: usize| {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(log.len() - 1));
        if b > a {
            (y[b] - y[a]) / (t[b] - t[a])
        } else {
            0.0
        }
    };
    let mut out = ElectricalReplay {
        ud_v: Vec::with_capacity(n),
        uq_v: Vec::with_capacity(n),
    };
    for (k, &theta_k) in theta.iter().enumerate().take(n) {
        let (i_d, i_q) = (log.id_a[k], log.iq_a[k]);
        let w_e = pp * log.speed_rad_s[k];
        let mut u_d = m.r_s_ohm * i_d + m.l_d_h * deriv(&log.id_a, k) - w_e * m.l_q_h * i_q;
        let mut u_q =
            m.r_s_ohm * i_q + m.l_q_h * deriv(&log.iq_a, k) + w_e * (m.l_d_h * i_d + m.psi_f_wb);
        if loss_v > 0.0 {
            let th = pp * theta_k;
            let (s, c) = th.sin_cos();
            // Phase currents (inverse Park, amplitude-invariant).
            let i_alpha = c * i_d - s * i_q;
            let i_beta = s * i_d + c * i_q;
            let i_abc = [
                i_alpha,
                -0.5 * i_alpha + 0.5 * 3f64.sqrt() * i_beta,
                -0.5 * i_alpha - 0.5 * 3f64.sqrt() * i_beta,
            ];
            let e = i_abc.map(|i| loss_v * (i / band).clamp(-1.0, 1.0));
            // Clarke removes the common mode; the loss is added back to the command.
            let e_alpha = (2.0 * e[0] - e[1] - e[2]) / 3.0;
            let e_beta = (e[1] - e[2]) / 3f64.sqrt();
            u_d += c * e_alpha + s * e_beta;
            u_q += -s * e_alpha + c * e_beta;
        }
        out.ud_v.push(u_d);
        out.uq_v.push(u_q);
    }
    Some(out)
}
